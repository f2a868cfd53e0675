// In-process runs of Kawamoto's compression scene (see compression_run.h).
#include "tests/scenes/compression/compression_run.h"

#include "dem/dem_run.h"
#include "dem/force_terms/magnetic_force_term.h"
#include "dem/measurements/measurement_registry.h"

#include "coupling/applied_magnetic_field.h"
#include "coupling/case_parser.h"

#include <omp.h>

#include <cmath>
#include <cstdio>
#include <map>
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
    o.push_back("dem.duration=7.7ms");
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
  const double t0 = omp_get_wtime();
  run.run();
  RunResult r;
  r.wall_s = omp_get_wtime() - t0;
  r.rows = plate->rows();
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
