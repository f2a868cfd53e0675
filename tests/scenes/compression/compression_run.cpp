// In-process runs of Kawamoto's compression scene (see compression_run.h).
#include "tests/scenes/compression/compression_run.h"

#include "dem/dem_run.h"
#include "dem/force_terms/magnetic_force_term.h"
#include "dem/measurements/measurement_registry.h"

#include "fields/applied_magnetic_field.h"
#include "case/case_parser.h"

#include <omp.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace magbrush::compression_test {

namespace {
const std::map<int, long> paper_counts{{42, 13700}, {50, 7870}, {60, 4420}};

std::string fmt(const char *f, double v)
{
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}
// Samples the plate's contacts over slide_steady for PlateSliding (the bead velocities at the
// contact point against the plate's own velocity, from its path in the case).
class PlateSlidingSampler : public dem::Measurement
{
public:
  PlateSlidingSampler(const Case &c, double interval, PlateSliding *out) : interval_(interval), out_(out)
  {
    for (const auto &p : c.planes)
      if (p.name == c.compression.plate)
        plate_ = p;
  }
  const char *name() const override { return "plate sliding (test)"; }
  double interval() const override { return interval_; }
  void write(const std::string &) const override {}
  // The test's runs are never restarted: a restart would be a misuse of the sampler.
  void write_state(StateOut &) const override {}
  void read_state(StateIn &) override { throw std::logic_error("the plate sliding sampler is not restartable"); }
  void sample(const dem::DemSystem &system) override
  {
    const double t = system.time();
    if (t < slide_steady.t0 || t > slide_steady.t1)
      return;
    std::size_t wall = system.walls().size();
    for (std::size_t w = 0; w < system.walls().size(); ++w)
      if (system.walls().name(w) == plate_.name)
        wall = w;
    if (wall == system.walls().size())
      throw std::logic_error("compression test: no plate wall");
    system.wall_contacts(wall, records_);
    const dem::Vector3 n{plate_.normal[0], plate_.normal[1], plate_.normal[2]}; // into the brush
    const Vec3 d = displacement(t);
    const dem::Vector3 point{plate_.point[0] + d[0], plate_.point[1] + d[1], plate_.point[2] + d[2]};
    const dem::Vector3 v_plate = velocity(t);
    const auto &s = system.particles();
    for (const auto &r : records_)
    {
      const std::size_t i = r.particle;
      const dem::Vector3 centre = s.position(i);
      const double h = dem::dot(centre - point, n);             // centre to plate, along n (lever arm)
      const dem::Vector3 contact_offset = -h * n;                  // towards the plate
      const dem::Vector3 v = s.velocity(i) + dem::cross(s.angular_velocity(i), contact_offset) - v_plate;
      const dem::Vector3 v_t = v - dem::dot(v, n) * n;
      const double slip = std::sqrt(dem::dot(v_t, v_t));
      const double fn = -dem::dot(r.force_on_wall, n); // the bead pushes the plate against n
      out_->fn += fn;
      if (slip > PlateSliding::sliding_speed)
      {
        out_->fn_sliding += fn;
        out_->fn_sliding_along += fn * (-v_t.x / slip);
      }
    }
    ++out_->samples;
  }

private:
  // The plate's path, piecewise linear between its samples (as the case defines it).
  Vec3 displacement(double t) const
  {
    const auto &p = plate_.path;
    if (p.empty())
      return {0, 0, 0};
    if (t <= p.front().first)
      return p.front().second;
    for (std::size_t k = 1; k < p.size(); ++k)
      if (t <= p[k].first)
      {
        const double w = (t - p[k - 1].first) / (p[k].first - p[k - 1].first);
        Vec3 out;
        for (int a = 0; a < 3; ++a)
          out[a] = (1 - w) * p[k - 1].second[a] + w * p[k].second[a];
        return out;
      }
    return p.back().second;
  }
  dem::Vector3 velocity(double t) const
  {
    const double h = 1e-9;
    const Vec3 a = displacement(t - h), b = displacement(t + h);
    return {(b[0] - a[0]) / (2 * h), (b[1] - a[1]) / (2 * h), (b[2] - a[2]) / (2 * h)};
  }

  double interval_;
  PlateSliding *out_;
  PlaneWall plate_;
  std::vector<dem::WallContactRecord> records_;
};

} // namespace

long bead_count(int diameter_um, double box_mm)
{
  const auto it = paper_counts.find(diameter_um);
  if (it == paper_counts.end())
    throw std::invalid_argument("compression test: Kawamoto's carrier sizes are 42, 50 and 60 um, not " +
                                std::to_string(diameter_um));
  return std::lround(static_cast<double>(it->second) * (box_mm / 2.0) * (box_mm / 2.0));
}

const std::vector<FieldHold> &field_holds()
{
  // The second half of each hold, ending 20 us before the next change (rows are 10 us means).
  static const std::vector<FieldHold> holds{{130, {2.5e-3, 2.68e-3}},
                                            {80, {2.88e-3, 2.98e-3}},
                                            {50, {3.18e-3, 3.28e-3}},
                                            {30, {3.48e-3, 3.58e-3}},
                                            {20, {3.78e-3, 3.88e-3}}};
  return holds;
}

Case reduced_case(const ReducedScene &s, const std::string &output_dir)
{
  const std::string box = fmt("%gmm", s.box_mm);
  std::vector<std::string> o{"populations.carrier.diameter=" + std::to_string(s.diameter_um) + "um",
                             "populations.carrier.diameter_std=" + fmt("%gum", s.diameter_um / 10.0),
                             "populations.carrier.count=" + std::to_string(bead_count(s.diameter_um, s.box_mm)),
                             "dem.periodic_length_x=" + box,
                             "dem.periodic_length_y=" + box,
                             "populations.carrier.insert_box=[[0mm, 0mm, 0.03mm], [" + box + ", " + box + ", 0.9mm]]",
                             "dem.seed=" + std::to_string(s.seed),
                             "dem.time_step=" + fmt("%gs", s.time_step),
                             "dem.output_interval=0s",
                             "output.directory=" + output_dir,
                             "output.vtu=false",
                             "output.xdmf=false",
                             "compression.average_window=10us",
                             "compression.map_interval=0s",
                             "planes.plate.point=[0mm, 0mm, 1.0mm]"};
  if (s.paper_magnetics)
  {
    o.push_back("dem.magnetic_far_field=none");
    o.push_back("dem.magnetic_cutoff=4");
  }
  if (s.saturation_magnetisation > 0.0)
    o.push_back("materials.carrier.saturation_magnetisation=" + fmt("%.17gA/m", s.saturation_magnetisation));
  if (s.sweep_and_slide)
  {
    o.push_back("planes.plate.path=[{time: 0ms, displacement: [0,0,0]}, {time: 0.4ms, displacement: [0,0,0]},"
                " {time: 2.4ms, displacement: [0mm,0mm,-0.4mm]}, {time: 4.5ms, displacement: [0mm,0mm,-0.4mm]},"
                " {time: 7.7ms, displacement: [0.8mm,0mm,-0.4mm]}]");
    o.push_back("applied_field.schedule=[{time: 0ms, magnitude: 0mT}, {time: 0.3ms, magnitude: 130mT},"
                " {time: 2.7ms, magnitude: 130mT}, {time: 2.75ms, magnitude: 80mT}, {time: 3.0ms, magnitude: 80mT},"
                " {time: 3.05ms, magnitude: 50mT}, {time: 3.3ms, magnitude: 50mT}, {time: 3.35ms, magnitude: 30mT},"
                " {time: 3.6ms, magnitude: 30mT}, {time: 3.65ms, magnitude: 20mT}, {time: 3.9ms, magnitude: 20mT},"
                " {time: 4.0ms, magnitude: 130mT}]");
    o.push_back(s.slide ? "dem.duration=7.7ms" : "dem.duration=3.9ms");
  }
  else
  {
    o.push_back("planes.plate.path=[{time: 0ms, displacement: [0,0,0]}, {time: 0.4ms, displacement: [0,0,0]},"
                " {time: 2.4ms, displacement: [0mm,0mm,-0.4mm]}]");
    o.push_back("applied_field.schedule=[{time: 0ms, magnitude: 0mT}, {time: 0.3ms, magnitude: 130mT}]");
    o.push_back("dem.duration=2.7ms");
  }
  return load_case(std::string(MAGBRUSH_SOURCE_DIR) + "/cases/kawamoto_brush_compression.yaml", o);
}

RunResult run_case(const Case &c, const std::string &output_dir, int threads)
{
  std::ostringstream log;
  dem::RunOptions options;
  options.output_dir = output_dir;
  options.threads = threads;
  options.progress_interval = 1e9;
  // As magbrush-dem: the scene's force terms (the induced dipoles in the scheduled uniform
  // field among them) and measurements.
  dem::DemRun run(c, options, log);
  auto &system = run.system();
  dem::add_case_measurements(run, c);
  const dem::PlateCompression *plate = nullptr;
  for (const auto &m : run.measurements())
    if (auto *p = dynamic_cast<const dem::PlateCompression *>(m.get()))
      plate = p;
  if (!plate)
    throw std::logic_error("compression test: the plate measurement was not added to the Kawamoto case");
  auto sliding = std::make_unique<PlateSliding>();
  run.add_measurement(std::make_unique<PlateSlidingSampler>(c, plate->interval(), sliding.get()));
  const double t0 = omp_get_wtime();
  run.run();
  RunResult r;
  r.wall_s = omp_get_wtime() - t0;
  r.rows = plate->rows();
  r.sliding = *sliding;
  r.area = plate->area();
  r.beads = static_cast<long>(system.particles().size());
  for (std::size_t k = 0; k < system.force_terms().size(); ++k)
    if (std::string(system.force_terms()[k]->name()) == "magnetic dipoles")
      r.magnetic_s = system.phase_times().terms[k];
  r.log = log.str();
  return r;
}

WindowMean mean_over(const std::vector<dem::PlateCompressionRow> &rows, Window w)
{
  WindowMean m;
  for (const auto &r : rows)
    if (r.time >= w.t0 && r.time <= w.t1)
    {
      m.fn += r.fn;
      m.ft += r.ft;
      m.touching += r.touching;
      m.field += r.field;
      m.gap += r.gap;
      ++m.rows;
    }
  if (m.rows > 0)
  {
    const double n = static_cast<double>(m.rows);
    m.fn /= n;
    m.ft /= n;
    m.touching /= n;
    m.field /= n;
    m.gap /= n;
  }
  return m;
}

WindowMean mean_at_length(const std::vector<dem::PlateCompressionRow> &rows, double lo, double hi)
{
  std::vector<dem::PlateCompressionRow> in;
  for (const auto &r : rows)
    if (r.time >= descent.t0 && r.time <= descent.t1 && r.gap >= lo && r.gap <= hi)
      in.push_back(r);
  return mean_over(in, {0.0, 1.0});
}

double power_law_exponent(const std::vector<double> &x, const std::vector<double> &y)
{
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = static_cast<double>(x.size());
  for (std::size_t i = 0; i < x.size(); ++i)
  {
    const double lx = std::log(x[i]), ly = std::log(y[i]);
    sx += lx;
    sy += ly;
    sxx += lx * lx;
    sxy += lx * ly;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

} // namespace magbrush::compression_test
