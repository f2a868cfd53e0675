// Profiles of the beads touching the drum along the nip (see nip_profile.h).
#include "dem/measurements/nip_profile.h"

#include "dem/measurements/measurement_registry.h"
#include "dem/snapshot_writer.h" // write_file_atomically

#include "fields/applied_magnetic_field.h"
#include "fields/field_files.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace magbrush::dem {

namespace {

constexpr double nan = std::numeric_limits<double>::quiet_NaN();
constexpr double mu0 = 4e-7 * M_PI;

// |B| of the case's applied field at the gap centre, when its grid can be read (the stored
// field must belong to this case); NaN otherwise — the summary then leaves it out.
double field_at_gap_centre(const Case &c, const NipFrame &f)
{
  try
  {
    AppliedMagneticField field;
    if (c.applied_field.kind == AppliedField::Kind::roller)
    {
      const std::string path = field::magnetic_grid_path(c);
      if (!std::filesystem::exists(path))
        return nan;
      field = AppliedMagneticField::for_case(c, path);
    }
    else if (c.applied_field.kind == AppliedField::Kind::uniform)
      field = AppliedMagneticField::from_settings(c.applied_field);
    else
      return nan;
    const double h = f.sleeve_radius + 0.5 * f.gap;
    Vec3 B;
    std::array<Vec3, 3> grad;
    field.evaluate({f.sx + h * f.nx, f.sy + h * f.ny, 0.0}, 1e30, B, grad);
    return std::sqrt(B[0] * B[0] + B[1] * B[1] + B[2] * B[2]);
  }
  catch (const std::exception &)
  {
    return nan;
  }
}

} // namespace

DrumContactInFrame resolve_drum_contact(const NipFrame &f, const DrumContact &c)
{
  // Outward drum normal at the bead, overlap and the contact point on the drum surface. The
  // lever arm from the bead centre to the contact point is r − δ, as in the engine's wall
  // contact (dem/contact_law.h), so the contact-point velocity is the one the contact law saw.
  const double rx = c.position.x - f.cx, ry = c.position.y - f.cy;
  const double d = std::hypot(rx, ry);
  const Vector3 n_out{rx / d, ry / d, 0.0};
  const double overlap = f.drum_radius + c.radius - d;
  const double lever = c.radius - overlap;
  const Vector3 to_contact = -lever * n_out;
  const Vector3 q = c.position + to_contact;
  const Vector3 v_bead = c.velocity + cross(c.angular_velocity, to_contact);
  const Vector3 v_drum = f.drum_surface_velocity(q.x, q.y);
  // Downstream tangent of the drum at q: the nip tangent t turned with the drum normal.
  const double sense = (f.nx * f.ty - f.ny * f.tx) >= 0.0 ? 1.0 : -1.0; // t = sense · ẑ × n
  const Vector3 t_local{sense * n_out.y, -sense * n_out.x, 0.0};     // sense · ẑ × (−n_out)
  DrumContactInFrame out;
  out.x = f.x_along(q.x, q.y);
  out.slip = dot(v_bead - v_drum, t_local);
  out.chain_speed = dot(c.velocity - v_drum, t_local);
  const Vector3 relative = v_bead - v_drum;
  const Vector3 relative_t = relative - dot(relative, n_out) * n_out;
  out.slip_speed = std::sqrt(dot(relative_t, relative_t));
  out.normal = -dot(c.force_on_wall, n_out);
  out.tangential = dot(c.force_on_wall, t_local);
  return out;
}

NipProfile::NipProfile(const Case &c) : settings_(c.nip), statistics_(c.statistics), frame_(NipFrame::from_case(c))
{
  if (settings_.bin_width <= 0.0 || settings_.half_width < 0.5 * settings_.bin_width)
    throw std::invalid_argument("nip profile: nip.half_width (" + std::to_string(settings_.half_width) +
                                " m) must be at least half of nip.bin_width (" + std::to_string(settings_.bin_width) +
                                " m)");
  bins_half_ = static_cast<int>(std::lround(settings_.half_width / settings_.bin_width));
  const std::size_t n = static_cast<std::size_t>(2 * bins_half_ + 1);
  fn_.assign(n, 0.0);
  ft_.assign(n, 0.0);
  slip_.assign(n, 0.0);
  slip2_.assign(n, 0.0);
  chain_.assign(n, 0.0);
  count_.assign(n, 0);
  bin_pressure_.assign(n, SampleSeries{});
  sample_fn_.assign(n, 0.0);
  for (int k = -bins_half_; k <= bins_half_; ++k)
  {
    const double lo = (k - 0.5) * settings_.bin_width, hi = (k + 0.5) * settings_.bin_width;
    bin_area_.push_back((frame_.drum_arc_of_x(hi) - frame_.drum_arc_of_x(lo)) * frame_.slab_depth);
  }
  gap_field_ = field_at_gap_centre(c, frame_);
}

int NipProfile::bin_of(double x) const
{
  const long k = std::lround(x / settings_.bin_width);
  if (std::abs(k) > bins_half_)
    return -1;
  return static_cast<int>(k) + bins_half_;
}

std::size_t NipProfile::find_drum_wall(const DemSystem &system) const
{
  for (std::size_t w = 0; w < system.walls().size(); ++w)
    if (system.walls().name(w) == "drum")
      return w;
  throw std::runtime_error("nip profile: the run has no wall named 'drum' (walls come from the case's drum section)");
}

void NipProfile::sample(const DemSystem &system)
{
  if (system.time() < settings_.average_from)
    return;
  system.wall_contacts(find_drum_wall(system), records_);
  const ParticleState &p = system.particles();
  contacts_.clear();
  for (const auto &r : records_)
  {
    DrumContact c;
    c.position = p.position(r.particle);
    c.velocity = p.velocity(r.particle);
    c.angular_velocity = p.angular_velocity(r.particle);
    c.radius = p.radius[r.particle];
    c.force_on_wall = r.force_on_wall;
    contacts_.push_back(c);
  }
  add_sample(system.time(), contacts_);
}

void NipProfile::add_sample(double time, const std::vector<DrumContact> &contacts)
{
  if (t_first_ < 0.0)
    t_first_ = time;
  t_last_ = time;
  ++samples_;
  double fn = 0.0, ft = 0.0, centre_slip = 0.0, centre_chain = 0.0;
  long touching = 0, centre = 0;
  asymmetry_.start_sample();
  std::fill(sample_fn_.begin(), sample_fn_.end(), 0.0);
  for (const auto &c : contacts)
  {
    const DrumContactInFrame r = resolve_drum_contact(frame_, c);
    const int b = bin_of(r.x);
    if (b < 0)
      continue;
    asymmetry_.add_contact(r.x, r.normal);
    const auto k = static_cast<std::size_t>(b);
    fn_[k] += r.normal;
    sample_fn_[k] += r.normal;
    ft_[k] += r.tangential;
    slip_[k] += r.slip;
    slip2_[k] += r.slip * r.slip;
    chain_[k] += r.chain_speed;
    ++count_[k];
    if (r.slip_speed > sliding_speed())
    {
      fn_sliding_ += r.normal;
      fn_sliding_downstream_ += r.normal * (r.slip / r.slip_speed);
    }
    fn += r.normal;
    ft += r.tangential;
    ++touching;
    if (b == bins_half_)
      centre_slip += r.slip, centre_chain += r.chain_speed, ++centre;
  }
  asymmetry_.end_sample();
  for (std::size_t k = 0; k < sample_fn_.size(); ++k)
    bin_pressure_[k].add(sample_fn_[k] / bin_area_[k]);
  centre_touching_.add(static_cast<double>(centre));
  normal_force_.add(fn / frame_.slab_depth);
  tangential_force_.add(ft / frame_.slab_depth);
  touching_.add(static_cast<double>(touching));
  if (centre > 0) // a sample without a bead in the centre bin says nothing about its slip
  {
    centre_slip_.add(centre_slip / static_cast<double>(centre));
    centre_chain_.add(centre_chain / static_cast<double>(centre));
  }
}

std::vector<NipBin> NipProfile::bins() const
{
  std::vector<NipBin> out;
  const double w = settings_.bin_width;
  const double per_sample = samples_ > 0 ? 1.0 / static_cast<double>(samples_) : nan;
  for (int k = -bins_half_; k <= bins_half_; ++k)
  {
    const auto i = static_cast<std::size_t>(k + bins_half_);
    NipBin b;
    b.x = k * w;
    b.x_lo = b.x - 0.5 * w;
    b.x_hi = b.x + 0.5 * w;
    b.area = bin_area_[i];
    b.contacts = count_[i];
    b.touching = static_cast<double>(count_[i]) * per_sample;
    b.density = b.touching / b.area;
    b.normal_pressure = fn_[i] * per_sample / b.area;
    b.tangential_pressure = ft_[i] * per_sample / b.area;
    if (count_[i] > 0)
    {
      const double m = slip_[i] / static_cast<double>(count_[i]);
      b.slip = m;
      b.slip_std = std::sqrt(std::max(0.0, slip2_[i] / static_cast<double>(count_[i]) - m * m));
      b.chain_speed = chain_[i] / static_cast<double>(count_[i]);
      b.normal_force_per_bead = fn_[i] / static_cast<double>(count_[i]);
    }
    else
      b.slip = b.slip_std = b.chain_speed = b.normal_force_per_bead = nan;
    out.push_back(b);
  }
  return out;
}

double NipProfile::slip_at_gap_centre() const
{
  const auto c = static_cast<std::size_t>(bins_half_);
  return count_[c] > 0 ? slip_[c] / static_cast<double>(count_[c]) : nan;
}

double NipProfile::chain_speed_at_gap_centre() const
{
  const auto c = static_cast<std::size_t>(bins_half_);
  return count_[c] > 0 ? chain_[c] / static_cast<double>(count_[c]) : nan;
}

double NipProfile::tangential_over_normal() const
{
  double fn = 0.0, ft = 0.0;
  for (std::size_t k = 0; k < fn_.size(); ++k)
  {
    fn += fn_[k];
    ft += ft_[k];
  }
  return fn > 0.0 ? ft / fn : nan;
}

double NipProfile::sliding_speed() const
{
  const double relative = std::abs(frame_.relative_surface_speed());
  return relative > 0.0 ? 0.1 * relative : 1e-3;
}

double NipProfile::sliding_share() const
{
  double fn = 0.0;
  for (const double f : fn_)
    fn += f;
  return fn > 0.0 ? fn_sliding_ / fn : nan;
}

double NipProfile::sliding_downstream_share() const
{
  double fn = 0.0;
  for (const double f : fn_)
    fn += f;
  return fn > 0.0 ? fn_sliding_downstream_ / fn : nan;
}

std::size_t NipProfile::peak_bin() const
{
  std::size_t peak = 0;
  for (std::size_t k = 1; k < fn_.size(); ++k)
    if (fn_[k] / bin_area_[k] > fn_[peak] / bin_area_[peak])
      peak = k;
  return peak;
}

double NipProfile::peak_normal_pressure() const
{
  if (samples_ == 0)
    return nan; // no sample in the averaging window: no peak, not 0 Pa
  const std::size_t k = peak_bin();
  return std::max(0.0, fn_[k] / bin_area_[k] / static_cast<double>(samples_));
}

std::string NipProfile::csv() const
{
  std::ostringstream o;
  char line[512];
  std::snprintf(line, sizeof line,
                "# Nip profile of the beads touching the drum (magbrush nip profile): %ld samples every %.4g s "
                "over t = %.6g .. %.6g s (averaging from nip.average_from = %.6g s)\n",
                samples_, settings_.sample_interval, t_first_, t_last_, settings_.average_from);
  o << line;
  o << "# x: distance from the gap centre along the common tangent of sleeve and drum, positive downstream "
       "(the way the sleeve surface moves); contacts binned by the x of their contact point on the drum.\n"
       "# drum_arc, drum_angle, sleeve_angle: the bin centre as arc length/angle on the drum and angle on the "
       "sleeve from the line of centres.\n"
       "# slip: bead contact-point velocity minus drum surface velocity, downstream component (relative surface "
       "speed of the walls " +
           std::to_string(frame_.relative_surface_speed()) +
           " m/s).\n"
           "# chain_speed: the same with the bead centre instead of its contact point (the chain's end moving over "
           "the drum, rolling included: one reading of Kawamoto's slip speed of the chains).\n"
           "# pressures: forces of the touching beads on the drum per drum surface of the bin (arc x slab depth "
           "= " +
           std::to_string(frame_.slab_depth * 1e3) + " mm); normal presses into the drum, tangential drags it downstream.\n";
  o << "x_mm,x_lo_mm,x_hi_mm,drum_arc_mm,drum_angle_deg,sleeve_angle_deg,touching_beads,density_per_mm2,"
       "normal_pressure_Pa,tangential_pressure_Pa,tangential_over_normal,slip_speed_m_s,slip_std_m_s,"
       "chain_speed_m_s,normal_force_per_bead_N,contact_samples\n";
  for (const auto &b : bins())
  {
    const double ratio = b.normal_pressure > 0.0 ? b.tangential_pressure / b.normal_pressure : nan;
    std::snprintf(line, sizeof line, "%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%ld\n",
                  b.x * 1e3, b.x_lo * 1e3, b.x_hi * 1e3, frame_.drum_arc_of_x(b.x) * 1e3,
                  frame_.drum_angle_of_x(b.x) * 180.0 / M_PI, frame_.sleeve_angle_of_x(b.x) * 180.0 / M_PI,
                  b.touching, b.density * 1e-6, b.normal_pressure, b.tangential_pressure, ratio, b.slip, b.slip_std,
                  b.chain_speed, b.normal_force_per_bead, b.contacts);
    o << line;
  }
  return o.str();
}

std::string NipProfile::summary_csv() const
{
  std::ostringstream o;
  char line[256];
  auto row = [&](const char *key, double value, const char *unit, const char *what) {
    std::snprintf(line, sizeof line, "%s,%.6g,%s,%s\n", key, value, unit, what);
    o << line;
  };
  const auto all = bins();
  const NipBin &centre = all[static_cast<std::size_t>(bins_half_)];
  double fn = 0.0, ft = 0.0, touching = 0.0;
  for (const auto &b : all)
  {
    fn += b.normal_pressure * b.area;
    ft += b.tangential_pressure * b.area;
    touching += b.touching;
  }
  o << "# Key numbers of the nip profile (magbrush nip profile); NaN: not available\n";
  o << "key,value,unit,meaning\n";
  row("samples", static_cast<double>(samples_), "1", "samples averaged");
  // No sample in the averaging window: no times either (the report says so instead of a window).
  row("t_from", samples_ > 0 ? t_first_ : nan, "s", "first averaged sample");
  row("t_to", samples_ > 0 ? t_last_ : nan, "s", "last averaged sample");
  row("relative_surface_speed", frame_.relative_surface_speed(), "m/s", "sleeve minus drum surface speed at the nip");
  row("slip_at_gap_centre", centre.slip, "m/s", "mean slip of the beads touching the drum in the centre bin");
  row("slip_std_at_gap_centre", centre.slip_std, "m/s", "spread of that slip over beads and samples");
  row("chain_speed_at_gap_centre", centre.chain_speed, "m/s",
      "mean speed of the touching beads' centres over the drum in the centre bin (rolling included)");
  row("beads_in_centre_bin", centre.touching, "1", "mean touching beads in the centre bin per sample");
  row("peak_normal_pressure", peak_normal_pressure(), "Pa", "largest bin normal pressure");
  row("normal_pressure_at_gap_centre", centre.normal_pressure, "Pa", "normal pressure of the centre bin");
  row("tangential_over_normal", tangential_over_normal(), "1", "sum of tangential / sum of normal forces on the drum");
  row("sliding_share", sliding_share(), "1",
      "share of the normal force on sliding contacts (slip faster than sliding_speed)");
  row("sliding_downstream_share", sliding_downstream_share(), "1",
      "the same, each contact weighted with the downstream cosine of its slip");
  row("sliding_speed", sliding_speed(), "m/s", "slip speed above which a contact counts as sliding");
  row("normal_force_per_length", fn / frame_.slab_depth, "N/m", "total normal force on the drum per slab depth");
  row("tangential_force_per_length", ft / frame_.slab_depth, "N/m", "total tangential force per slab depth");
  row("touching_beads", touching, "1", "mean beads touching the drum within the profile");
  row("density_at_gap_centre", centre.density * 1e-6, "1/mm^2", "touching beads per drum area, centre bin");
  row("gap_centre_field", gap_field_, "T", "|B| of the applied field at the gap centre");
  row("magnetic_pressure", gap_field_ * gap_field_ / (2.0 * mu0), "Pa", "B^2/2mu0 at the gap centre");
  // How symmetric about the gap centre (standard errors in summary.csv).
  for (const SummaryValue &v : asymmetry_.summary(static_cast<std::size_t>(statistics_.blocks)))
  {
    const bool length = v.unit == "m";
    std::snprintf(line, sizeof line, "%s,%.6g,%s,%s\n", (length ? v.key.substr(0, v.key.size() - 2) : v.key).c_str(),
                  length ? v.value * 1e3 : v.value, length ? "mm" : v.unit.c_str(), v.meaning.c_str());
    o << line;
  }
  return o.str();
}

std::vector<SummaryValue> NipProfile::summary() const
{
  const auto blocks = static_cast<std::size_t>(statistics_.blocks);
  auto sampled = [&](const char *key, const SampleSeries &s, const char *unit, const char *meaning) {
    return summarise(s, blocks, true, key, unit, meaning);
  };
  auto plain = [](const char *key, double value, const char *unit, const char *meaning) {
    SummaryValue v;
    v.key = key, v.value = value, v.unit = unit, v.meaning = meaning;
    return v;
  };
  const auto all = bins();
  const NipBin &centre = all[static_cast<std::size_t>(bins_half_)];
  // The slip: the mean over every contact sample of the centre bin (as in nip_summary.csv); its
  // standard error from the series of per-sample means. Not tested for drift: few beads per
  // sample make its halves noisy, and the forces and bead counts below judge the steady state.
  SummaryValue slip = sampled("slip_at_gap_centre_m_s", centre_slip_, "m/s",
                              "slip of the beads touching the drum in the centre bin");
  slip.value = slip_at_gap_centre();
  slip.drift = slip.drift_standard_error = std::numeric_limits<double>::quiet_NaN();
  SummaryValue chain = sampled("chain_speed_at_gap_centre_m_s", centre_chain_, "m/s",
                               "speed of the touching beads' centres over the drum in the centre bin");
  chain.value = chain_speed_at_gap_centre();
  chain.drift = chain.drift_standard_error = std::numeric_limits<double>::quiet_NaN();
  // T/N: the bins' sums are the per-sample series' sums (the same contacts), so its error is
  // the scatter of the blocks' ratios.
  SummaryValue t_over_n = plain("tangential_over_normal", tangential_over_normal(), "1",
                                "sum of tangential over sum of normal drum forces");
  t_over_n.standard_error = ratio_standard_error(tangential_force_, normal_force_, blocks);
  // The peak: the standard error of the peak bin's own mean (the bin is chosen by the same
  // data, so that when two bins are within their errors the peak's error is somewhat larger).
  // Not tested for drift: one bin's halves are noisy; the forces below judge the steady state.
  auto bin_value = [&](const char *key, const SampleSeries &s, double value, double scale, const char *unit,
                       const char *meaning) {
    SummaryValue v = sampled(key, s, unit, meaning);
    v.value = value;
    v.standard_error *= scale;
    v.drift = v.drift_standard_error = std::numeric_limits<double>::quiet_NaN();
    return v;
  };
  const auto centre_bin = static_cast<std::size_t>(bins_half_);
  std::vector<SummaryValue> out = {
      slip,
      chain,
      plain("relative_surface_speed_m_s", frame_.relative_surface_speed(), "m/s", "sleeve minus drum surface speed"),
      bin_value("peak_normal_pressure_Pa", bin_pressure_[peak_bin()], peak_normal_pressure(), 1.0, "Pa",
                "largest bin normal pressure"),
      bin_value("normal_pressure_at_gap_centre_Pa", bin_pressure_[centre_bin], centre.normal_pressure, 1.0, "Pa",
                "normal pressure of the centre bin"),
      t_over_n,
      bin_value("density_at_gap_centre_per_mm2", centre_touching_, centre.density * 1e-6,
                1e-6 / bin_area_[centre_bin], "1/mm^2", "touching beads per drum area, centre bin"),
      sampled("normal_force_per_length_N_m", normal_force_, "N/m", "normal force on the drum per slab depth"),
      sampled("tangential_force_per_length_N_m", tangential_force_, "N/m", "tangential force on the drum per slab depth"),
      sampled("touching_beads", touching_, "1", "beads touching the drum within the profile"),
      plain("magnetic_pressure_Pa", gap_field_ * gap_field_ / (2.0 * mu0), "Pa", "B^2/2mu0 at the gap centre"),
  };
  const auto symmetry = asymmetry_.summary(blocks);
  out.insert(out.end(), symmetry.begin(), symmetry.end());
  return out;
}

void NipProfile::write(const std::string &directory) const
{
  write_file_atomically((std::filesystem::path(directory) / "nip_profile.csv").string(), csv());
  write_file_atomically((std::filesystem::path(directory) / "nip_summary.csv").string(), summary_csv());
}

namespace {
const bool registered = register_measurement({"nip profile", [](const Case &c) -> std::unique_ptr<Measurement> {
                                                if (!NipFrame::applies(c))
                                                  return nullptr;
                                                return std::make_unique<NipProfile>(c);
                                              }});
} // namespace


// The profile's sums and the per-sample series (Measurement::write_state).
void NipProfile::write_state(StateOut &out) const
{
  for (const auto *a : {&fn_, &ft_, &slip_, &slip2_, &chain_})
    out.put_array(*a);
  out.put_array(count_);
  out.put(fn_sliding_);
  out.put(fn_sliding_downstream_);
  out.put(samples_);
  out.put(t_first_);
  out.put(t_last_);
  for (const auto *s : {&normal_force_, &tangential_force_, &touching_, &centre_slip_, &centre_chain_})
    s->write_state(out);
  asymmetry_.write_state(out);
  for (const auto &s : bin_pressure_)
    s.write_state(out);
  centre_touching_.write_state(out);
}

void NipProfile::read_state(StateIn &in)
{
  const std::size_t bins = fn_.size();
  for (auto *a : {&fn_, &ft_, &slip_, &slip2_, &chain_})
    in.get_array(*a);
  in.get_array(count_);
  for (const auto *a : {&fn_, &ft_, &slip_, &slip2_, &chain_})
    if (a->size() != bins)
      in.fail("holds a nip profile of " + std::to_string(a->size()) + " bins, this case's has " + std::to_string(bins));
  if (count_.size() != bins)
    in.fail("holds a nip profile of " + std::to_string(count_.size()) + " bins, this case's has " + std::to_string(bins));
  fn_sliding_ = in.get<double>();
  fn_sliding_downstream_ = in.get<double>();
  samples_ = in.get<long>();
  t_first_ = in.get<double>();
  t_last_ = in.get<double>();
  for (auto *s : {&normal_force_, &tangential_force_, &touching_, &centre_slip_, &centre_chain_})
    s->read_state(in);
  asymmetry_.read_state(in);
  for (auto &s : bin_pressure_)
    s.read_state(in);
  centre_touching_.read_state(in);
}

} // namespace magbrush::dem
