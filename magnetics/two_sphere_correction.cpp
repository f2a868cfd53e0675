#include "magnetics/two_sphere_correction.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace magbrush::magnetics {

void add_incident_pair_forces(const MagneticNeighbourList &list, const std::vector<double> &pair_force,
                              std::size_t b, double F[3])
{
  const auto &begin = list.incident_begin();
  const auto &end = list.incident_end();
  const auto &pair_of = list.incident_pair();
  const auto &first = list.incident_first();
  for (std::size_t q = begin[b]; q < end[b]; ++q)
  {
    const double *Fp = &pair_force[3 * pair_of[q]];
    const double sign = first[q] ? -1.0 : 1.0;
    for (int a = 0; a < 3; ++a)
      F[a] += sign * Fp[a];
  }
}

TwoSphereCorrection::TwoSphereCorrection(const MagneticSettings &settings, const std::array<double, 3> &box)
  : settings_(settings), box_(box)
{
}

void TwoSphereCorrection::prepare_tables(const std::vector<double> &beta)
{
  std::vector<double> distinct;
  for (const double b : beta)
    if (b != 0.0) // (inert holes: no correction, no table)
      distinct.push_back(b);
  std::sort(distinct.begin(), distinct.end());
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  for (std::size_t a = 0; a < distinct.size(); ++a)
    for (std::size_t b = a; b < distinct.size(); ++b)
    {
      const double pair_beta = 0.5 * (distinct[a] + distinct[b]);
      if (tables_.count(pair_beta))
        continue;
      try
      {
        tables_[pair_beta] = TwoSphereTable::shared(pair_beta, settings_.switch_end);
      }
      catch (const std::runtime_error &e)
      {
        // The series converges ever more slowly as μr grows (touching, perfectly permeable
        // spheres attract with a force that grows without bound): say which input and what to
        // do, not which internal limit was hit.
        char what[512];
        std::snprintf(what, sizeof what,
                      "magnetics: the exact two-sphere correction (dem.magnetic_model: corrected) cannot be "
                      "tabulated for carriers of mu_r = %.4g (beta = %.6f): the force between touching beads "
                      "grows without bound as mu_r -> infinity and its multipole series does not converge. Use a "
                      "lower materials.*.mu_r (measured carriers: 3-10), or dem.magnetic_model: mutual_dipole. (",
                      mu_r_from_beta(pair_beta), pair_beta);
        throw std::runtime_error(what + std::string(e.what()) + ")");
      }
    }
}

const TwoSphereTable *TwoSphereCorrection::table(double beta_i, double beta_j) const
{
  if (tables_.size() == 1)
    return tables_.begin()->second.get();
  return tables_.at(0.5 * (beta_i + beta_j)).get();
}

bool TwoSphereCorrection::add(const InducedState &s, std::uint32_t i, std::uint32_t j,
                              const double r[3], const DipoleTensor &T, double F[3]) const
{
  const double s0 = settings_.switch_begin, s1 = settings_.switch_end;
  const double a = 0.5 * (s.beads.radius[i] + s.beads.radius[j]);
  const double dist = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
  const double D = dist / a;
  // A bead that does not magnetise (β = 0: an inert hole left by a leaver) induces nothing.
  if (D >= s1 || s.beta[i] == 0.0 || s.beta[j] == 0.0)
    return false;
  const TwoSphereTable *tab = table(s.beta[i], s.beta[j]);
  // The field the pair sits in: the local field at each bead minus the partner's own
  // contribution, averaged.
  const std::vector<double> &B_local = s.local_field;
  double Bi[3] = {B_local[3 * i], B_local[3 * i + 1], B_local[3 * i + 2]};
  double Bj[3] = {B_local[3 * j], B_local[3 * j + 1], B_local[3 * j + 2]};
  const DipoleTensor minus = {-T.xx, -T.yy, -T.zz, -T.xy, -T.xz, -T.yz};
  minus.add_field(&s.p[3 * j], Bi);
  minus.add_field(&s.p[3 * i], Bj);
  double H[3], e[3];
  for (int d = 0; d < 3; ++d)
  {
    H[d] = 0.5 * (Bi[d] + Bj[d]) / mu0;
    e[d] = r[d] / dist;
  }
  const double Hr = H[0] * e[0] + H[1] * e[1] + H[2] * e[2];
  const double Ht[3] = {H[0] - Hr * e[0], H[1] - Hr * e[1], H[2] - Hr * e[2]};
  const double Ht2 = Ht[0] * Ht[0] + Ht[1] * Ht[1] + Ht[2] * Ht[2];
  const TwoSphereForce c = tab->correction(D);
  // Smooth switch-off (C¹ smoothstep) between switch_begin and switch_end.
  double w = 1.0;
  if (D > s0)
  {
    const double t = (D - s0) / (s1 - s0);
    w = 1.0 - t * t * (3.0 - 2.0 * t);
  }
  // Unequal beads: the identical-sphere table at the mean radius ā, rescaled by the dipole
  // scaling (a_i a_j)³/ā⁶ of a pair force (a ±15 % size pair: residual ~1–2 % of Δf).
  const double size_ratio = s.beads.radius[i] * s.beads.radius[j] / (a * a);
  const double scale = w * mu0 * a * a * size_ratio * size_ratio * size_ratio;
  const double radial = c.parallel * Hr * Hr + c.perpendicular * Ht2;
  // F·t̂ = f_t sinψ cosψ H² along t̂ (the direction that turns r̂ away from the field),
  // i.e. −f_t H_r H_t as a vector.
  for (int d = 0; d < 3; ++d)
    F[d] += scale * (radial * e[d] - c.transverse * Hr * Ht[d]);
  return true;
}

void TwoSphereCorrection::refresh_list(const BeadArrays &beads)
{
  double sum = 0.0, largest = 0.0;
  for (std::size_t b = 0; b < beads.n; ++b)
  {
    sum += beads.radius[b];
    largest = std::max(largest, beads.radius[b]);
  }
  const double skin = settings_.skin_fraction * 2.0 * sum / beads.n;
  const double radius = settings_.switch_end * largest + skin;
  // The list holds every pair within its reach with the build's skin, and stays good while
  // no bead moved half that skin and no bead is larger than the build's largest. (After an
  // admission the mean radius, hence `skin`, differs a little from the build's; otherwise
  // skin_ = skin and the radius is the list's.)
  const bool stale = !list_.built() || list_.particle_count() != beads.n || list_.box() != box_ ||
                     settings_.switch_end * largest + skin_ > list_.list_radius() * (1.0 + 1e-12) ||
                     list_.max_displacement(beads.n, beads.x, beads.y, beads.z) > 0.5 * skin_;
  // Each pair is listed only within its own reach, switch_end × its mean radius + skin: with
  // ±10 % beads the largest radius sets a search radius whose sphere holds ~3× the pairs
  // that can ever be corrected (the rest cost a force evaluation, a gather and a local
  // refresh's attention each, for a zero force).
  if (stale)
  {
    list_.build(beads.n, beads.x, beads.y, beads.z, box_, radius, {beads.radius, settings_.switch_end, skin});
    skin_ = skin;
  }
}

bool TwoSphereCorrection::can_admit(const BeadArrays &beads, std::size_t first) const
{
  const std::size_t n = beads.n;
  if (!list_.built() || list_.particle_count() != first || first == 0 || first >= n)
    return false;
  const double R = list_.list_radius();
  double largest = 0.0;
  for (std::size_t b = 0; b < n; ++b)
    largest = std::max(largest, beads.radius[b]);
  // (A radius beyond a period is fine: admit() visits every image within reach.)
  return !(settings_.switch_end * largest + skin_ > R * (1.0 + 1e-12));
}

bool TwoSphereCorrection::admit(const BeadArrays &beads, std::size_t first)
{
  if (!can_admit(beads, first))
    return false;
  const std::size_t n = beads.n;
  // Every image of every bead within the pair's reach of a newcomer. The positions are the
  // magnetics' unwrapped ones (a bead keeps the image nearest its last position), so two
  // beads may sit any number of periods apart, and a reach beyond a period (a quasi-2D slab
  // of three or four diameters) meets several images of the same bead, and the newcomer's
  // own: along a periodic axis the images j + s L with |Δ + s L| < reach are those with
  // s in [⌈(−reach − Δ)/L⌉, ⌊(reach − Δ)/L⌋], Δ = x_j − x_c.
  const double *x[3] = {beads.x, beads.y, beads.z};
  admitted_.clear();
  for (std::size_t c = first; c < n; ++c)
    for (std::size_t j = 0; j < n; ++j)
    {
      if (j < c && j >= first)
        continue; // (a pair of two newcomers: listed from the lower one)
      const double reach = settings_.switch_end * 0.5 * (beads.radius[c] + beads.radius[j]) + skin_;
      long lo[3], hi[3];
      for (int d = 0; d < 3; ++d)
      {
        lo[d] = hi[d] = 0;
        if (box_[d] > 0.0)
        {
          const double delta = x[d][j] - x[d][c];
          lo[d] = static_cast<long>(std::ceil((-reach - delta) / box_[d]));
          hi[d] = static_cast<long>(std::floor((reach - delta) / box_[d]));
        }
      }
      for (long sx = lo[0]; sx <= hi[0]; ++sx)
        for (long sy = lo[1]; sy <= hi[1]; ++sy)
          for (long sz = lo[2]; sz <= hi[2]; ++sz)
          {
            const long s[3] = {sx, sy, sz};
            double shift[3], r[3];
            for (int d = 0; d < 3; ++d)
            {
              shift[d] = static_cast<double>(s[d]) * box_[d];
              r[d] = x[d][j] - x[d][c] + shift[d]; // from the newcomer to j's image
            }
            const bool zero = sx == 0 && sy == 0 && sz == 0;
            const bool positive = sx > 0 || (sx == 0 && (sy > 0 || (sy == 0 && sz > 0)));
            if (j == c && (zero || !positive))
              continue; // (a bead and its own image: once per ± pair)
            if (r[0] * r[0] + r[1] * r[1] + r[2] * r[2] >= reach * reach)
              continue;
            MagneticNeighbourList::Pair p;
            if (j < first) // r = x_c − x_j − shift: the pair seen from the older bead
            {
              p.i = static_cast<std::uint32_t>(j);
              p.j = static_cast<std::uint32_t>(c);
              for (int d = 0; d < 3; ++d)
                p.shift[d] = -shift[d];
            }
            else
            {
              p.i = static_cast<std::uint32_t>(c);
              p.j = static_cast<std::uint32_t>(j);
              for (int d = 0; d < 3; ++d)
                p.shift[d] = shift[d];
            }
            admitted_.push_back(p);
          }
    }
  list_.append(n, beads.x, beads.y, beads.z, admitted_);
  force_.resize(3 * list_.pairs().size(), 0.0);
  return true;
}

bool TwoSphereCorrection::list_current(const BeadArrays &beads, double skin) const
{
  return list_.built() && list_.particle_count() == beads.n &&
         !(list_.max_displacement(beads.n, beads.x, beads.y, beads.z) > 0.5 * std::min(skin, skin_));
}

std::size_t TwoSphereCorrection::evaluate_list_forces(const InducedState &s)
{
  const std::size_t np = list_.pairs().size();
  force_.resize(3 * np);
  std::size_t corrected_pairs = 0;
#pragma omp parallel for schedule(static) reduction(+ : corrected_pairs) if (np >= bead_parallel_threshold)
  for (long k = 0; k < static_cast<long>(np); ++k)
    corrected_pairs += evaluate_list_force(s, k);
  return corrected_pairs;
}

bool TwoSphereCorrection::evaluate_list_force(const InducedState &s, std::size_t k)
{
  double *F = &force_[3 * k];
  F[0] = F[1] = F[2] = 0.0;
  const auto &pair = list_.pairs()[k];
  const double r[3] = {s.beads.x[pair.j] - s.beads.x[pair.i] + pair.shift[0],
                       s.beads.y[pair.j] - s.beads.y[pair.i] + pair.shift[1],
                       s.beads.z[pair.j] - s.beads.z[pair.i] + pair.shift[2]};
  const double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
  if (r2 == 0.0)
    return false;
  // Beyond switch_end (as add() decides it) no correction: skip the pair's dipole tensor.
  if (std::sqrt(r2) / (0.5 * (s.beads.radius[pair.i] + s.beads.radius[pair.j])) >= settings_.switch_end)
    return false;
  return add(s, pair.i, pair.j, r, DipoleTensor::at(r), F);
}

void TwoSphereCorrection::add_incident_forces(std::size_t b, double F[3]) const
{
  add_incident_pair_forces(list_, force_, b, F);
}

void TwoSphereCorrection::scale_forces(double ratio2)
{
  for (double &x : force_)
    x *= ratio2;
}

void TwoSphereCorrection::write_state(StateOut &out) const
{
  list_.write_state(out);
  out.put_array(force_);
  out.put(skin_);
}

void TwoSphereCorrection::read_state(StateIn &in)
{
  list_.read_state(in);
  in.get_array(force_);
  skin_ = in.get<double>();
}

} // namespace magbrush::magnetics
