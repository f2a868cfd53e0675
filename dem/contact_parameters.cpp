// Mixing rules, damping forms and the polygon rule (see contact_parameters.h).
#include "dem/contact_parameters.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace magbrush::dem {

double rolling_friction_from_polygon(int corners)
{
  if (corners < 3)
    throw std::invalid_argument("polygon rule for rolling friction: expected at least 3 corners, got " +
                                std::to_string(corners));
  return std::sin(M_PI / corners);
}

namespace {
double beta_of(double e)
{
  if (!(e > 0.0 && e <= 1.0))
    throw std::invalid_argument("restitution coefficient must lie in (0, 1], got " + std::to_string(e));
  const double l = std::log(e);
  return std::abs(l) / std::sqrt(l * l + M_PI * M_PI);
}
} // namespace

double ln_e_alpha_normal(double e) { return std::sqrt(5.0) * beta_of(e); }
double ln_e_alpha_tangential(double e) { return 2.0 * std::sqrt(5.0 / 6.0) * beta_of(e); }

double hertz_restitution(double alpha)
{
  // RK4 on y = (ξ, ξ'), with a step refined near the end so that the exit time is resolved.
  auto accel = [alpha](double xi, double v) {
    const double s = xi > 0.0 ? xi : 0.0;
    return -(s * std::sqrt(s) + alpha * std::sqrt(std::sqrt(s)) * v);
  };
  auto force = [alpha](double xi, double v) {
    const double s = xi > 0.0 ? xi : 0.0;
    return s * std::sqrt(s) + alpha * std::sqrt(std::sqrt(s)) * v;
  };
  double xi = 0.0, v = 1.0, h = 1e-3;
  for (long step = 0; step < 100000000; ++step)
  {
    const double k1x = v, k1v = accel(xi, v);
    const double k2x = v + 0.5 * h * k1v, k2v = accel(xi + 0.5 * h * k1x, v + 0.5 * h * k1v);
    const double k3x = v + 0.5 * h * k2v, k3v = accel(xi + 0.5 * h * k2x, v + 0.5 * h * k2v);
    const double k4x = v + h * k3v, k4v = accel(xi + h * k3x, v + h * k3v);
    const double xn = xi + h / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x);
    const double vn = v + h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v);
    // Separation: the overlap closes or the repulsive force vanishes while receding.
    if (step > 10 && vn < 0.0 && (xn <= 0.0 || force(xn, vn) <= 0.0))
    {
      if (h < 1e-9)
        return -vn;
      h *= 0.5; // retry this step with a finer one
      continue;
    }
    xi = xn;
    v = vn;
  }
  throw std::runtime_error("hertz_restitution: the contact ODE did not separate (alpha = " +
                           std::to_string(alpha) + ")");
}

double hertz_alpha_for_restitution(double e)
{
  if (!(e > 0.0 && e <= 1.0))
    throw std::invalid_argument("restitution coefficient must lie in (0, 1], got " + std::to_string(e));
  if (e == 1.0)
    return 0.0;
  double lo = 0.0, hi = 1.0;
  while (hertz_restitution(hi) > e)
    hi *= 2.0;
  for (int it = 0; it < 40; ++it)
  {
    const double mid = 0.5 * (lo + hi);
    (hertz_restitution(mid) > e ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

namespace {
double shear_modulus(const Material &m) { return m.youngs_modulus / (2.0 * (1.0 + m.poisson_ratio)); }

void check_elastic(const Material &m)
{
  if (!(m.youngs_modulus > 0.0))
    throw std::invalid_argument("material '" + m.name + "': Young's modulus must be > 0 for contacts, got " +
                                std::to_string(m.youngs_modulus) + " Pa");
  if (!(m.poisson_ratio > -1.0 && m.poisson_ratio < 0.5))
    throw std::invalid_argument("material '" + m.name + "': Poisson's ratio must lie in (-1, 0.5), got " +
                                std::to_string(m.poisson_ratio));
}

double rolling_of(const Material &m)
{
  return m.polygon_angles > 0 ? rolling_friction_from_polygon(m.polygon_angles) : m.rolling_friction;
}

struct Damping
{
  double normal = 0.0, tangential = 0.0;
};

Damping damping_of(const Material &m, const std::string &model)
{
  if (m.restitution >= 0.0)
  {
    if (model == "ln_e")
      return {ln_e_alpha_normal(m.restitution), ln_e_alpha_tangential(m.restitution)};
    if (model == "hertz_exact")
    {
      const double a = hertz_alpha_for_restitution(m.restitution);
      // Keep LIGGGHTS's tangential/normal ratio 2√(5/6)/√5 = √(2/3).
      return {a, a * std::sqrt(2.0 / 3.0)};
    }
    throw std::invalid_argument("dem.restitution_model: expected 'ln_e' or 'hertz_exact', got '" + model + "'");
  }
  return {m.damping, m.damping}; // Kawamoto A3/A5: one α for both
}
} // namespace

ContactCoefficients mix_materials(const Material &a, const Material &b, bool b_is_wall,
                                  const std::string &restitution_model)
{
  check_elastic(a);
  check_elastic(b);
  ContactCoefficients c;
  c.effective_modulus = 1.0 / ((1.0 - a.poisson_ratio * a.poisson_ratio) / a.youngs_modulus +
                               (1.0 - b.poisson_ratio * b.poisson_ratio) / b.youngs_modulus);
  c.effective_shear = 1.0 / ((2.0 - a.poisson_ratio) / shear_modulus(a) +
                             (2.0 - b.poisson_ratio) / shear_modulus(b));
  const Damping da = damping_of(a, restitution_model);
  if (b_is_wall)
  {
    c.friction = b.friction;
    c.rolling_friction = rolling_of(a);
    const Damping d = b.restitution >= 0.0 ? damping_of(b, restitution_model) : da;
    c.damping_normal = d.normal;
    c.damping_tangential = d.tangential;
  }
  else
  {
    const Damping db = damping_of(b, restitution_model);
    c.friction = 0.5 * (a.friction + b.friction);
    c.rolling_friction = 0.5 * (rolling_of(a) + rolling_of(b));
    c.damping_normal = 0.5 * (da.normal + db.normal);
    c.damping_tangential = 0.5 * (da.tangential + db.tangential);
  }
  return c;
}

double hamaker_of_pair(const Case &c, const Material &a, const Material &b)
{
  for (const AdhesionPair &p : c.adhesion_pairs)
    if ((p.material_a == a.name && p.material_b == b.name) || (p.material_a == b.name && p.material_b == a.name))
      return p.hamaker;
  if ((a.hamaker > 0.0 && !b.hamaker_given) || (b.hamaker > 0.0 && !a.hamaker_given))
  {
    const Material &has = a.hamaker > 0.0 ? a : b, &lacks = a.hamaker > 0.0 ? b : a;
    throw std::invalid_argument("adhesion between '" + a.name + "' and '" + b.name + "': material '" +
                                has.name + "' has a Hamaker constant but '" + lacks.name +
                                "' has none: give materials." + lacks.name +
                                ".hamaker (0 J for no adhesion) or an adhesion_pairs entry "
                                "{material_a: " + a.name + ", material_b: " + b.name + ", hamaker: ...}");
  }
  return std::sqrt(a.hamaker * b.hamaker);
}

Material contact_material(const Case &c, std::size_t population)
{
  const Population &p = c.populations.at(population);
  Material m = c.material(p.material);
  if (p.kind == ParticleKind::toner)
    m.youngs_modulus *= c.dem.toner_stiffness_factor;
  return m;
}

namespace {
double asperity_of(const Material &m)
{
  return m.adhesion_radius > 0.0 ? m.adhesion_radius : std::numeric_limits<double>::infinity();
}

void check_adhesion_pairs(const Case &c)
{
  for (std::size_t k = 0; k < c.adhesion_pairs.size(); ++k)
  {
    const AdhesionPair &p = c.adhesion_pairs[k];
    for (const std::string *name : {&p.material_a, &p.material_b})
    {
      bool known = false;
      for (const Material &m : c.materials)
        known = known || m.name == *name;
      if (!known)
        throw std::invalid_argument("adhesion_pairs[" + std::to_string(k) + "]: no material '" + *name + "'");
    }
    for (std::size_t l = 0; l < k; ++l)
    {
      const AdhesionPair &q = c.adhesion_pairs[l];
      if ((q.material_a == p.material_a && q.material_b == p.material_b) ||
          (q.material_a == p.material_b && q.material_b == p.material_a))
        throw std::invalid_argument("adhesion_pairs[" + std::to_string(k) + "]: the pair '" + p.material_a +
                                    "'–'" + p.material_b + "' is already given in adhesion_pairs[" +
                                    std::to_string(l) + "]");
    }
  }
}
} // namespace

void ContactTable::build(const Case &c, const std::vector<std::string> &species_materials,
                         const std::vector<std::string> &wall_materials)
{
  n_species_ = species_materials.size();
  columns_ = n_species_ + wall_materials.size();
  table_.assign(n_species_ * columns_, {});
  adhesion_.assign(n_species_ * columns_, {});
  names_.assign(n_species_ * columns_, {});
  check_adhesion_pairs(c);
  adhesive_ = particles_adhesive_ = false;
  const std::string &model = c.dem.restitution_model;
  // Species s is population s when the table is built for the case's populations (the
  // engine); the toner stiffness factor then applies to toner populations.
  const auto material_of = [&](std::size_t s) {
    return s < c.populations.size() && c.populations[s].material == species_materials[s]
               ? contact_material(c, s)
               : c.material(species_materials[s]);
  };
  for (std::size_t s = 0; s < n_species_; ++s)
  {
    const Material ms = material_of(s);
    for (std::size_t t = 0; t < n_species_; ++t)
    {
      const Material mt = material_of(t);
      table_[s * columns_ + t] = mix_materials(ms, mt, false, model);
      adhesion_[s * columns_ + t] = {hamaker_of_pair(c, ms, mt), asperity_of(ms), asperity_of(mt)};
      particles_adhesive_ = particles_adhesive_ || adhesion_[s * columns_ + t].hamaker > 0.0;
      names_[s * columns_ + t] = species_materials[s] + "–" + species_materials[t];
    }
    for (std::size_t w = 0; w < wall_materials.size(); ++w)
    {
      const Material &mw = c.material(wall_materials[w]);
      table_[s * columns_ + n_species_ + w] = mix_materials(ms, mw, true, model);
      adhesion_[s * columns_ + n_species_ + w] = {hamaker_of_pair(c, ms, mw), asperity_of(ms), asperity_of(mw)};
      adhesive_ = adhesive_ || adhesion_[s * columns_ + n_species_ + w].hamaker > 0.0;
      names_[s * columns_ + n_species_ + w] = species_materials[s] + "–wall:" + wall_materials[w];
    }
  }
  adhesive_ = adhesive_ || particles_adhesive_;
  cutoff_ = c.dem.adhesion_cutoff;
  if (adhesive_ && !(cutoff_ > 0.0 && c.dem.adhesion_range_fraction > 0.0 && c.dem.adhesion_range_fraction < 1.0))
    throw std::invalid_argument("adhesion: dem.adhesion_cutoff must be > 0 and dem.adhesion_range_fraction in (0, 1)");
  range_ = adhesive_ ? HamakerAdhesion::range(cutoff_, c.dem.adhesion_range_fraction) : 0.0;
}

std::string ContactTable::describe() const
{
  std::string out;
  char line[256];
  for (std::size_t k = 0; k < table_.size(); ++k)
  {
    const auto &c = table_[k];
    std::snprintf(line, sizeof line,
                  "  %-28s E* %.3g Pa, G* %.3g Pa, mu %.3g, mu_r %.3g, alpha_n %.3g (e_Hertz %.3f), alpha_t %.3g\n",
                  names_[k].c_str(), c.effective_modulus, c.effective_shear, c.friction,
                  c.rolling_friction, c.damping_normal,
                  c.damping_normal > 0 ? hertz_restitution(c.damping_normal) : 1.0, c.damping_tangential);
    out += line;
    const auto &a = adhesion_[k];
    if (a.hamaker > 0.0)
    {
      std::snprintf(line, sizeof line, "  %-28s Hamaker %.3g J, asperity radii %.3g / %.3g m\n", "", a.hamaker,
                    a.asperity_i, a.asperity_j);
      out += line;
    }
  }
  if (adhesive_)
  {
    std::snprintf(line, sizeof line, "  adhesion: cut-off gap z0 %.3g m, range %.3g m%s\n", cutoff_, range_,
                  particles_adhesive_ ? "" : "; off between particles (no particle pair has a Hamaker constant)");
    out += line;
  }
  else
    out += "  adhesion: off (no pair of materials has a Hamaker constant): the contact kernels run without it\n";
  return out;
}

} // namespace magbrush::dem
