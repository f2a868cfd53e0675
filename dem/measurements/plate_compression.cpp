// Kawamoto's compression test measured at the plate (see plate_compression.h).
#include "dem/measurements/plate_compression.h"

#include "dem/measurements/measurement_registry.h"
#include "dem/snapshot_writer.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace magbrush::dem {

namespace {

const PlaneWall *find_plane(const Case &c, const std::string &name)
{
  for (const auto &p : c.planes)
    if (p.name == name)
      return &p;
  return nullptr;
}

PlaneWallPrimitive primitive_of(const PlaneWall &p)
{
  PlaneWallPrimitive w;
  w.name = p.name;
  w.point = p.point;
  w.normal = p.normal;
  w.material = p.material;
  w.path = p.path;
  return w;
}

const char *axis_name(int a)
{
  return a == 0 ? "x" : a == 1 ? "y" : "z";
}

// Registered at start-up: every box scene with a plate and a stage gets this measurement.
const bool registered = register_measurement({"plate compression", [](const Case &c) -> std::unique_ptr<Measurement> {
                                                if (!PlateCompression::applies(c))
                                                  return nullptr;
                                                return std::make_unique<PlateCompression>(c);
                                              }});

} // namespace

bool PlateCompression::applies(const Case &c)
{
  return c.scene == "box" && find_plane(c, c.compression.plate) && find_plane(c, c.compression.stage);
}

PlateCompression::PlateCompression(const Case &c) : settings_(c.compression)
{
  const PlaneWall *plate = find_plane(c, settings_.plate);
  const PlaneWall *stage = find_plane(c, settings_.stage);
  if (!plate || !stage)
    throw std::invalid_argument("plate compression: the case needs plane walls named '" + settings_.plate +
                                "' (the moving plate) and '" + settings_.stage +
                                "' (the stage); set compression.plate and compression.stage to the names used in "
                                "'planes'");
  plate_ = primitive_of(*plate);
  stage_ = primitive_of(*stage);
  // The plate normal must lie along a coordinate axis, and the box must be periodic along the
  // other two: the pressure is the force over that periodic area.
  normal_axis_ = -1;
  for (int a = 0; a < 3; ++a)
    if (std::abs(plate_.normal[a]) > 1.0 - 1e-12)
      normal_axis_ = a;
  if (normal_axis_ < 0)
    throw std::invalid_argument("plate compression: the plate '" + settings_.plate +
                                "' must be normal to a coordinate axis (e.g. normal: [0, 0, -1]) so that the "
                                "periodic box defines the pressure area");
  in_plane_ = {(normal_axis_ + 1) % 3, (normal_axis_ + 2) % 3};
  if (in_plane_[0] > in_plane_[1])
    std::swap(in_plane_[0], in_plane_[1]);
  const std::array<double, 3> box{c.dem.periodic_length_x, c.dem.periodic_length_y, c.dem.periodic_length};
  for (int a : in_plane_)
    if (!(box[a] > 0.0))
      throw std::invalid_argument(std::string("plate compression: the box must be periodic along ") + axis_name(a) +
                                  " (in the plate plane) to define the pressure area; set dem.periodic_length" +
                                  (a == 0   ? "_x"
                                   : a == 1 ? "_y"
                                            : "") +
                                  " (Kawamoto: 2 mm)");
  area_ = box[in_plane_[0]] * box[in_plane_[1]];
  if (!(settings_.average_window >= settings_.sample_interval))
    throw std::invalid_argument(
        "plate compression: compression.average_window (" + std::to_string(settings_.average_window) +
        " s) must be at least one compression.sample_interval (" + std::to_string(settings_.sample_interval) + " s)");
  samples_per_window_ = std::max(1L, std::lround(settings_.average_window / settings_.sample_interval));
  field_ = AppliedMagneticField::from_settings(c.applied_field);
  next_map_ = settings_.map_interval;
}

double PlateCompression::gap(double t) const
{
  const Vec3 dp = plate_.displacement(t), ds = stage_.displacement(t);
  double g = 0.0;
  for (int a = 0; a < 3; ++a)
    g += (plate_.point[a] + dp[a] - stage_.point[a] - ds[a]) * stage_.normal[a];
  return g;
}

std::size_t PlateCompression::find_plate_wall(const DemSystem &system) const
{
  for (std::size_t w = 0; w < system.walls().size(); ++w)
    if (system.walls().name(w) == settings_.plate)
      return w;
  throw std::invalid_argument("plate compression: the engine has no wall named '" + settings_.plate + "'");
}

PlateContactMap PlateCompression::contact_map(const DemSystem &system)
{
  if (!wall_found_)
  {
    plate_wall_ = find_plate_wall(system);
    wall_found_ = true;
  }
  system.wall_contacts(plate_wall_, records_);
  const ParticleState &s = system.particles();
  const double t = system.time();
  PlateContactMap map;
  map.time = t;
  map.gap = gap(t);
  const Vec3 origin{stage_.point[0], stage_.point[1], stage_.point[2]};
  const Vec3 B = field_.field(origin, t);
  map.field = std::sqrt(B[0] * B[0] + B[1] * B[1] + B[2] * B[2]);
  map.beads.reserve(records_.size());
  const double sign = plate_.normal[normal_axis_] > 0 ? 1.0 : -1.0; // n̂ = sign ê_axis
  for (const auto &r : records_)
  {
    const std::size_t i = r.particle;
    const double f[3] = {r.force_on_wall.x, r.force_on_wall.y, r.force_on_wall.z};
    const double pos[3] = {s.x[i], s.y[i], s.z[i]};
    PlateContactBead b;
    b.id = s.id[i];
    b.u = pos[in_plane_[0]];
    b.v = pos[in_plane_[1]];
    b.radius = s.radius[i];
    b.fn = -sign * f[normal_axis_]; // −F·n̂: the brush pushes the plate against its normal
    b.ft_u = f[in_plane_[0]];
    b.ft_v = f[in_plane_[1]];
    map.beads.push_back(b);
  }
  return map;
}

void PlateCompression::sample(const DemSystem &system)
{
  PlateContactMap map = contact_map(system);
  if (sum_.samples == 0)
    sum_ = PlateCompressionRow{};
  sum_.time += map.time;
  sum_.gap += map.gap;
  sum_.field += map.field;
  for (const auto &b : map.beads)
  {
    sum_.fn += b.fn;
    sum_.ft_u += b.ft_u;
    sum_.ft_v += b.ft_v;
  }
  sum_.touching += static_cast<double>(map.beads.size());
  ++sum_.samples;
  if (sum_.samples >= samples_per_window_)
    close_window();
  if (settings_.map_interval > 0.0 && map.time >= next_map_ - 0.5 * settings_.sample_interval)
  {
    maps_.push_back(map);
    while (next_map_ <= map.time + 0.5 * settings_.sample_interval)
      next_map_ += settings_.map_interval;
  }
  last_map_ = std::move(map);
}

PlateCompressionRow PlateCompression::window_mean(const PlateCompressionRow &sum) const
{
  PlateCompressionRow r;
  const double n = static_cast<double>(sum.samples);
  r.samples = sum.samples;
  r.time = sum.time / n;
  r.gap = sum.gap / n;
  r.field = sum.field / n;
  r.fn = sum.fn / n;
  r.ft_u = sum.ft_u / n;
  r.ft_v = sum.ft_v / n;
  r.ft = std::hypot(r.ft_u, r.ft_v);
  r.touching = sum.touching / n;
  return r;
}

void PlateCompression::close_window()
{
  rows_.push_back(window_mean(sum_));
  sum_ = PlateCompressionRow{};
}

void PlateCompression::write_map(const std::string &path, const PlateContactMap &map, const std::array<int, 2> &axes)
{
  std::string text;
  char line[320];
  std::snprintf(line, sizeof line, "# plate contact map: t = %.9g s, brush length = %.9g m, B = %.9g T, %zu beads\n",
                map.time, map.gap, map.field, map.beads.size());
  text += line;
  std::snprintf(line, sizeof line, "id,%s_m,%s_m,radius_m,Fn_N,Ft_%s_N,Ft_%s_N,Ft_N\n", axis_name(axes[0]),
                axis_name(axes[1]), axis_name(axes[0]), axis_name(axes[1]));
  text += line;
  for (const auto &b : map.beads)
  {
    std::snprintf(line, sizeof line, "%d,%.9g,%.9g,%.6g,%.9g,%.9g,%.9g,%.9g\n", b.id, b.u, b.v, b.radius, b.fn, b.ft_u,
                  b.ft_v, std::hypot(b.ft_u, b.ft_v));
    text += line;
  }
  write_file_atomically(path, text);
}

void PlateCompression::write(const std::string &directory) const
{
  namespace fs = std::filesystem;
  std::vector<PlateCompressionRow> rows = rows_;
  if (sum_.samples > 0)
    rows.push_back(window_mean(sum_)); // the unfinished last window
  const double mm2 = 1e-6;
  std::string text;
  char line[640];
  std::snprintf(line, sizeof line,
                "# plate compression: plate '%s', stage '%s', periodic area %.9g m^2, rows = means over %ld samples "
                "every %.6g s\n",
                settings_.plate.c_str(), settings_.stage.c_str(), area_, samples_per_window_,
                settings_.sample_interval);
  text += line;
  std::snprintf(line, sizeof line,
                "time_s,brush_length_m,B_T,Fn_N,Ft_%s_N,Ft_%s_N,Ft_N,pn_Pa,pt_Pa,touching,density_per_mm2,"
                "force_per_bead_N,chain_spacing_m,ft_over_fn,samples\n",
                axis_name(in_plane_[0]), axis_name(in_plane_[1]));
  text += line;
  for (const auto &r : rows)
  {
    const double per_bead = r.touching > 0 ? r.fn / r.touching : 0.0;
    const double spacing = r.touching > 0 ? std::sqrt(area_ / r.touching) : 0.0;
    const double ratio = r.fn > 0 ? r.ft / r.fn : 0.0;
    std::snprintf(line, sizeof line, "%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.6g,%.9g,%.9g,%.9g,%.6g,%ld\n",
                  r.time, r.gap, r.field, r.fn, r.ft_u, r.ft_v, r.ft, r.fn / area_, r.ft / area_, r.touching,
                  r.touching / (area_ / mm2), per_bead, spacing, ratio, r.samples);
    text += line;
  }
  write_file_atomically((fs::path(directory) / "plate_compression.csv").string(), text);

  std::vector<const PlateContactMap *> maps;
  for (const auto &m : maps_)
    maps.push_back(&m);
  if (last_map_.time > 0.0 && (maps.empty() || last_map_.time > maps.back()->time))
    maps.push_back(&last_map_);
  std::string index = "file,time_s,brush_length_m,B_T,beads\n";
  for (std::size_t k = 0; k < maps.size(); ++k)
  {
    char name[64];
    std::snprintf(name, sizeof name, "contact_map_%03zu.csv", k);
    write_map((fs::path(directory) / name).string(), *maps[k], in_plane_);
    std::snprintf(line, sizeof line, "%s,%.9g,%.9g,%.9g,%zu\n", name, maps[k]->time, maps[k]->gap, maps[k]->field,
                  maps[k]->beads.size());
    index += line;
  }
  write_file_atomically((fs::path(directory) / "contact_maps.csv").string(), index);
}


// The open window's sums, the closed windows, the contact maps and when the next is due
// (Measurement::write_state). A map's beads are written field by field (no padding bytes).
namespace {
void write_map_state(StateOut &out, const PlateContactMap &map)
{
  out.put(map.time);
  out.put(map.gap);
  out.put(map.field);
  std::vector<std::int32_t> ids;
  std::vector<double> values;
  for (const PlateContactBead &b : map.beads)
  {
    ids.push_back(b.id);
    values.insert(values.end(), {b.u, b.v, b.radius, b.fn, b.ft_u, b.ft_v});
  }
  out.put_array(ids);
  out.put_array(values);
}

PlateContactMap read_map_state(StateIn &in)
{
  PlateContactMap map;
  map.time = in.get<double>();
  map.gap = in.get<double>();
  map.field = in.get<double>();
  std::vector<std::int32_t> ids;
  std::vector<double> values;
  in.get_array(ids);
  in.get_array(values);
  if (values.size() != 6 * ids.size())
    in.fail("is corrupt (a plate contact map)");
  for (std::size_t k = 0; k < ids.size(); ++k)
  {
    const double *v = &values[6 * k];
    map.beads.push_back({ids[k], v[0], v[1], v[2], v[3], v[4], v[5]});
  }
  return map;
}

void write_rows(StateOut &out, const std::vector<PlateCompressionRow> &rows)
{
  std::vector<double> values;
  std::vector<long> samples;
  for (const PlateCompressionRow &r : rows)
  {
    values.insert(values.end(), {r.time, r.gap, r.field, r.fn, r.ft_u, r.ft_v, r.ft, r.touching});
    samples.push_back(r.samples);
  }
  out.put_array(values);
  out.put_array(samples);
}

std::vector<PlateCompressionRow> read_rows(StateIn &in)
{
  std::vector<double> values;
  std::vector<long> samples;
  in.get_array(values);
  in.get_array(samples);
  if (values.size() != 8 * samples.size())
    in.fail("is corrupt (the plate compression's rows)");
  std::vector<PlateCompressionRow> rows;
  for (std::size_t k = 0; k < samples.size(); ++k)
  {
    const double *v = &values[8 * k];
    rows.push_back({v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], samples[k]});
  }
  return rows;
}
} // namespace

void PlateCompression::write_state(StateOut &out) const
{
  write_rows(out, {sum_});
  write_rows(out, rows_);
  out.put(next_map_);
  out.put<std::uint64_t>(maps_.size());
  for (const PlateContactMap &m : maps_)
    write_map_state(out, m);
  write_map_state(out, last_map_);
}

void PlateCompression::read_state(StateIn &in)
{
  const auto sum = read_rows(in);
  if (sum.size() != 1)
    in.fail("is corrupt (the plate compression's open window)");
  sum_ = sum.front();
  rows_ = read_rows(in);
  next_map_ = in.get<double>();
  const auto n_maps = in.get<std::uint64_t>();
  if (n_maps > in.remaining())
    in.fail("is corrupt (more contact maps than the file holds)");
  maps_.clear();
  for (std::uint64_t k = 0; k < n_maps; ++k)
    maps_.push_back(read_map_state(in));
  last_map_ = read_map_state(in);
}

} // namespace magbrush::dem
