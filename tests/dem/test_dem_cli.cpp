// End-to-end: bin/magbrush-dem on a small case file (parser → insertion → run → outputs),
// a restart from the checkpoint that reproduces the uninterrupted run's final snapshot bit for
// bit, the messages of a refused time step and an impossible insertion, a restart under
// another case (refused) or other run control (proceeds), and a killed run's checkpoints.
#include <gtest/gtest.h>
#include "tests/cli_run.h"
#include "tests/test_temp_dir.h"
#include <hdf5.h>

#include <signal.h>
#include <sys/types.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <thread>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

const char *case_text = R"(name: dem_cli_test
scene: box
planes:
  - name: stage
    point: [0 mm, 0 mm, 0 mm]
    normal: [0, 0, 1]
    material: wall
materials:
  carrier:
    youngs_modulus: 100 MPa
    poisson_ratio: 0.35
    density: 2200 kg/m^3
    friction: 0.45
    polygon_angles: 12
    damping: 0.6
  wall:
    youngs_modulus: 5e4 MPa
    poisson_ratio: 0.3
    friction: 0.35
populations:
  - name: carrier
    kind: carrier
    material: carrier
    diameter: 100 um
    diameter_std: 10 um
    count: 250
    insert_box: [[0 mm, 0 mm, 0.05 mm], [1 mm, 1 mm, 1 mm]]
dem:
  duration: 100 us
  output_interval: 20 us
  checkpoint_interval: 50 us
  periodic_length_x: 1 mm
  periodic_length_y: 1 mm
  gravity: [0, 0, -9.81 m/s^2]
)";

using magbrush::testing::CliResult;

CliResult run_dem(const std::string &args) { return magbrush::testing::run_program("magbrush-dem", args); }

std::vector<double> read_dataset(const std::string &file, const char *name)
{
  std::vector<double> v;
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0)
    return v;
  const hid_t d = H5Dopen2(f, name, H5P_DEFAULT);
  const hid_t s = H5Dget_space(d);
  v.resize(static_cast<std::size_t>(H5Sget_simple_extent_npoints(s)));
  H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
  H5Sclose(s);
  H5Dclose(d);
  H5Fclose(f);
  return v;
}

class DemCli : public ::testing::Test
{
protected:
  fs::path dir;
  std::string case_file;
  void SetUp() override
  {
    dir = magbrush::testing::test_temp_dir("dem_cli");
    case_file = (dir / "case.yaml").string();
    std::ofstream(case_file) << case_text;
  }
  void TearDown() override { fs::remove_all(dir); }
};

} // namespace

TEST_F(DemCli, RunsWritesOutputsAndRestartsBitIdentically)
{
  const std::string straight = (dir / "straight").string(), split = (dir / "split").string();
  const CliResult a = run_dem(case_file + " --threads 2 --output " + straight);
  ASSERT_EQ(a.code, 0) << a.output;
  EXPECT_NE(a.output.find("force terms on: contacts, gravity, Stokes drag"), std::string::npos) << a.output;
  EXPECT_NE(a.output.find("time per phase"), std::string::npos) << a.output;
  for (const char *f : {"particles.xdmf", "time_series.csv", "checkpoint.bin"})
    EXPECT_TRUE(fs::exists(fs::path(straight) / f)) << f;
  std::ifstream x(fs::path(straight) / "particles.xdmf");
  const std::string xdmf((std::istreambuf_iterator<char>(x)), std::istreambuf_iterator<char>());
  std::size_t grids = 0;
  for (std::size_t p = xdmf.find("<Time Value"); p != std::string::npos; p = xdmf.find("<Time Value", p + 1))
    ++grids;
  EXPECT_EQ(grids, 6u); // t = 0, 20, ..., 100 µs
  std::ifstream csv(fs::path(straight) / "time_series.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_NE(header.find("stage_Fz"), std::string::npos) << header;

  // The same run in two pieces: to 50 µs, then restarted from its checkpoint to 100 µs.
  const CliResult b1 = run_dem(case_file + " --threads 1 --set dem.duration=50us --output " + split);
  ASSERT_EQ(b1.code, 0) << b1.output;
  const CliResult b2 = run_dem(case_file + " --threads 1 --output " + split + " --restart " + split + "/checkpoint.bin");
  ASSERT_EQ(b2.code, 0) << b2.output;
  EXPECT_NE(b2.output.find("restarted from"), std::string::npos) << b2.output;
  std::vector<std::string> last;
  for (const auto &d : {straight, split})
  {
    std::vector<std::string> files;
    for (const auto &e : fs::directory_iterator(fs::path(d) / "snapshots"))
      files.push_back(e.path().string());
    std::sort(files.begin(), files.end());
    ASSERT_GE(files.size(), 6u) << d; // (the split run also has its 50 µs end snapshot)
    last.push_back(files.back());
  }
  for (const char *name : {"position", "velocity", "angular_velocity", "force"})
  {
    const auto p = read_dataset(last[0], name), q = read_dataset(last[1], name);
    ASSERT_EQ(p.size(), 750u) << name;
    EXPECT_EQ(0, std::memcmp(p.data(), q.data(), p.size() * sizeof(double))) << name << " differs after restart";
  }
}

TEST_F(DemCli, RefusesUnstableTimeStepWithTheLimit)
{
  const CliResult r = run_dem(case_file + " --set dem.time_step=1us --output " + (dir / "o").string());
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("above the stable limit"), std::string::npos) << r.output;
}

TEST_F(DemCli, ImpossibleInsertionSaysWhatToDo)
{
  const CliResult r = run_dem(case_file + " --set populations.carrier.count=5000 --output " + (dir / "o").string());
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("enlarge the insertion region"), std::string::npos) << r.output;
}

// A restart under a case that differs beyond run control is refused with the keys that
// differ (here another particle count) unless --restart-anyway is given; one that changes run
// control only (the duration) proceeds and says what changed.
TEST_F(DemCli, RestartUnderAnotherCaseIsRefusedRunControlMayChange)
{
  const std::string out = (dir / "first").string(), checkpoint = out + "/checkpoint.bin";
  const CliResult a = run_dem(case_file + " --threads 1 --set dem.duration=40us --output " + out);
  ASSERT_EQ(a.code, 0) << a.output;
  const CliResult refused = run_dem(case_file + " --threads 1 --set populations.carrier.count=300 --output " +
                                    (dir / "refused").string() + " --restart " + checkpoint);
  EXPECT_EQ(refused.code, 1) << refused.output;
  const std::size_t list = refused.output.find("beyond run control:");
  ASSERT_NE(list, std::string::npos) << refused.output;
  const std::string keys = refused.output.substr(list);
  EXPECT_NE(keys.find("populations.carrier.count: 250 (checkpoint) -> 300 (this case)"), std::string::npos) << keys;
  EXPECT_EQ(keys.find("dem.duration"), std::string::npos) << "run control is not a reason to refuse:\n" << keys;
  EXPECT_NE(keys.find("--restart-anyway"), std::string::npos) << keys;
  EXPECT_FALSE(fs::exists(dir / "refused" / "checkpoint.bin"));

  const CliResult anyway = run_dem(case_file + " --threads 1 --set populations.carrier.count=300 --output " +
                                   (dir / "anyway").string() + " --restart " + checkpoint + " --restart-anyway");
  EXPECT_EQ(anyway.code, 0) << anyway.output;
  EXPECT_NE(anyway.output.find("restart anyway (--restart-anyway)"), std::string::npos) << anyway.output;

  const CliResult longer = run_dem(case_file + " --threads 1 --set dem.duration=60us --output " +
                                   (dir / "longer").string() + " --restart " + checkpoint);
  EXPECT_EQ(longer.code, 0) << longer.output;
  EXPECT_NE(longer.output.find("run control changed since the checkpoint"), std::string::npos) << longer.output;
  EXPECT_NE(longer.output.find("  dem.duration: "), std::string::npos) << longer.output;
  EXPECT_NE(longer.output.find("restarted from"), std::string::npos) << longer.output;
}

// A run killed (SIGKILL) in the middle leaves good checkpoints by the default interval (the
// case sets none), the last and the one before it; the log says where. A byte flipped in the
// last one is refused with the file named and the one before offered; both restart.
TEST_F(DemCli, KilledRunLeavesGoodCheckpointsByDefault)
{
  std::string text = case_text;
  const std::string interval_line = "  checkpoint_interval: 50 us\n";
  text.erase(text.find(interval_line), interval_line.size());
  text.replace(text.find("duration: 100 us"), 16, "duration: 1 s");
  const std::string killed_case = (dir / "long.yaml").string();
  std::ofstream(killed_case) << text;
  const fs::path out = dir / "killed", log = dir / "killed.log";
  const std::string start = std::string(MAGBRUSH_BINARY_DIR) + "/bin/magbrush-dem " + killed_case +
                            " --threads 1 --output " + out.string() + " > " + log.string() + " 2>&1 & echo $!";
  FILE *p = popen(start.c_str(), "r");
  ASSERT_NE(p, nullptr);
  long pid = 0;
  ASSERT_EQ(fscanf(p, "%ld", &pid), 1);
  pclose(p);
  // Wait for two checkpoints (at 250 and 500 µs of simulated time), then kill the run.
  auto log_text = [&] {
    std::ifstream in(log);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  };
  auto count = [](const std::string &s, const std::string &what) {
    std::size_t n = 0;
    for (std::size_t at = s.find(what); at != std::string::npos; at = s.find(what, at + 1))
      ++n;
    return n;
  };
  for (int waited = 0; waited < 3000 && count(log_text(), "checkpoint at t = ") < 2; ++waited)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  kill(static_cast<pid_t>(pid), SIGKILL);
  for (int waited = 0; waited < 100 && kill(static_cast<pid_t>(pid), 0) == 0; ++waited)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  const std::string written = log_text();
  ASSERT_GE(count(written, "checkpoint at t = "), 2u) << written;
  // The first at 250 µs of simulated time (to the last digit of the step count's sum of steps).
  EXPECT_TRUE(std::regex_search(written, std::regex(R"(checkpoint at t = 0\.000(25|249\d+) s \(step \d+\): )" +
                                                     (out / "checkpoint.bin").string())))
    << written;
  EXPECT_EQ(written.find("done:"), std::string::npos) << "the run should have been killed";
  ASSERT_TRUE(fs::exists(out / "checkpoint.bin"));
  ASSERT_TRUE(fs::exists(out / "checkpoint.previous.bin"));

  // Flip one byte of the last checkpoint: refused, the file named, the one before offered.
  std::string bytes;
  {
    std::ifstream in(out / "checkpoint.bin", std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  bytes[bytes.size() / 2] = static_cast<char>(bytes[bytes.size() / 2] ^ 0x04);
  std::ofstream(out / "checkpoint.bin", std::ios::binary | std::ios::trunc) << bytes;
  const CliResult damaged = run_dem(killed_case + " --threads 1 --output " + (dir / "r0").string() + " --restart " +
                                    (out / "checkpoint.bin").string());
  EXPECT_EQ(damaged.code, 1) << damaged.output;
  EXPECT_NE(damaged.output.find("checkpoint '" + (out / "checkpoint.bin").string() + "' is damaged"), std::string::npos)
    << damaged.output;
  EXPECT_NE(damaged.output.find("restart from the checkpoint kept before it, '" +
                                (out / "checkpoint.previous.bin").string()),
            std::string::npos)
    << damaged.output;
  // The one before restarts, and runs on (a little past where the killed run got).
  const CliResult resumed = run_dem(killed_case + " --threads 1 --set dem.duration=0.3ms --output " +
                                    (dir / "r1").string() + " --restart " + (out / "checkpoint.previous.bin").string());
  EXPECT_EQ(resumed.code, 0) << resumed.output;
  EXPECT_NE(resumed.output.find("restarted from"), std::string::npos) << resumed.output;
  EXPECT_NE(resumed.output.find("done:"), std::string::npos) << resumed.output;
}

TEST_F(DemCli, WritesVtuSnapshotsWhenAskedAndNoXdmfWhenNot)
{
  const std::string out = (dir / "vtu").string();
  const CliResult r = run_dem(case_file + " --set output.vtu=true --set output.xdmf=false --set dem.duration=40us --output " + out);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_FALSE(fs::exists(fs::path(out) / "particles.xdmf"));
  std::ifstream pvd(fs::path(out) / "particles.pvd");
  const std::string index((std::istreambuf_iterator<char>(pvd)), std::istreambuf_iterator<char>());
  std::size_t sets = 0;
  for (std::size_t p = index.find("<DataSet"); p != std::string::npos; p = index.find("<DataSet", p + 1))
    ++sets;
  EXPECT_EQ(sets, 3u) << index; // t = 0, 20, 40 µs
  const auto file = fs::path(out) / "snapshots" / "particles_00000000.vtu";
  ASSERT_TRUE(fs::exists(file));
  std::ifstream vtu(file);
  const std::string text((std::istreambuf_iterator<char>(vtu)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("NumberOfPoints=\"250\""), std::string::npos);
  // The position array holds 250 lines of three numbers, all above the stage (z > 0).
  const auto begin = text.find('\n', text.find("Name=\"position\"")) + 1;
  std::istringstream positions(text.substr(begin, text.find("</DataArray>", begin) - begin));
  double x, y, z;
  std::size_t points = 0;
  while (positions >> x >> y >> z)
  {
    ++points;
    EXPECT_GT(z, 0.0);
  }
  EXPECT_EQ(points, 250u);
  for (const char *array : {"\"velocity\"", "\"charge\"", "\"id\"", "\"contact_count\""})
    EXPECT_NE(text.find(array), std::string::npos) << array;
}
