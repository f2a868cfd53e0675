// `magbrush sweep` beyond one process, on the small box scene of test_sweep.cpp (two points,
// DEM only): `mpirun -np 2 magbrush sweep` deals the points to two ranks, and a Slurm job
// array's steps (--emit slurm, each --point, --merge) run here one after the other. Either way
// the table must equal the serial sweep's bit for bit in every column but the run time, and
// each point's DEM time series (energies, contacts, wall forces at full precision) must be the
// same file: the points ran the same simulation wherever they ran.
#include "common/child_process.h"

#include "tests/app/sweep_box_case.h"
#include "tests/csv_columns.h"
#include "tests/test_temp_dir.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace {

namespace fs = std::filesystem;

const std::string magbrush = std::string(MAGBRUSH_BINARY_DIR) + "/bin/magbrush";

struct Result
{
  int status;
  std::string output;
};

std::string text_of(const fs::path &file)
{
  std::ifstream in(file);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

Result run(const fs::path &log, const std::vector<std::string> &command)
{
  magbrush::ChildOutput output;
  output.stdout_path = log.string();
  output.stderr_to_stdout = true;
  const int status = magbrush::run_program(command, output);
  return {status, text_of(log)};
}

// The sweep's words after `magbrush`, into `out`.
std::vector<std::string> sweep_words(const fs::path &dir, const fs::path &out)
{
  return {"sweep", (dir / "box.yaml").string(), "--vary", "populations.carrier.diameter=100um,120um",
          "--skip", "mesh,field,report", "--set", "output.directory=" + out.string()};
}

std::vector<std::string> with(std::vector<std::string> words, const std::vector<std::string> &more)
{
  words.insert(words.end(), more.begin(), more.end());
  return words;
}

const char *const point_folders[] = {"p0_diameter-100um", "p1_diameter-120um"};

// Every cell but run_time_s equal, as text (bit for bit); the run times present and numeric.
void expect_same_table_but_run_time(const fs::path &serial, const fs::path &other)
{
  const auto a = magbrush::testing::read_csv_rows(serial / "sweep_diameter" / "sweep_summary.csv");
  const auto b = magbrush::testing::read_csv_rows(other / "sweep_diameter" / "sweep_summary.csv");
  ASSERT_EQ(a.size(), 3u);
  ASSERT_EQ(b.size(), a.size());
  ASSERT_EQ(b[0], a[0]) << "the headers differ";
  std::size_t run_time = a[0].size();
  for (std::size_t k = 0; k < a[0].size(); ++k)
    if (a[0][k] == "run_time_s")
      run_time = k;
  ASSERT_LT(run_time, a[0].size()) << "no run_time_s column";
  for (std::size_t r = 1; r < a.size(); ++r)
  {
    ASSERT_EQ(b[r].size(), a[r].size()) << "row " << r;
    for (std::size_t k = 0; k < a[r].size(); ++k)
    {
      if (k == run_time)
        continue;
      EXPECT_EQ(b[r][k], a[r][k]) << "row " << r << ", column " << a[0][k];
    }
    EXPECT_GE(std::stod(b[r][run_time]), 0.0);
  }
  EXPECT_EQ(a[1].back(), "ok");
  EXPECT_EQ(a[2].back(), "ok");
  EXPECT_EQ(text_of(other / "sweep_diameter" / "sweep_profiles.csv"),
            text_of(serial / "sweep_diameter" / "sweep_profiles.csv"));
  for (const char *point : point_folders)
  {
    const std::string series = text_of(serial / "sweep_diameter" / point / "dem" / "time_series.csv");
    EXPECT_GT(series.size(), 100u) << point;
    EXPECT_EQ(text_of(other / "sweep_diameter" / point / "dem" / "time_series.csv"), series) << point;
  }
}

class DistributedSweep : public ::testing::Test
{
protected:
  static void SetUpTestSuite()
  {
    dir_ = magbrush::testing::test_temp_dir("app_sweep_distributed");
    std::ofstream(dir_ / "box.yaml") << magbrush::testing::sweep_box_case;
    serial_ = run(dir_ / "serial.log", with({magbrush}, sweep_words(dir_, dir_ / "serial")));
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  static fs::path dir_;
  static Result serial_;
};
fs::path DistributedSweep::dir_;
Result DistributedSweep::serial_;

TEST_F(DistributedSweep, TwoMpiRanksGiveTheSerialTableBitForBit)
{
  ASSERT_EQ(serial_.status, 0) << serial_.output;
  if (!magbrush::program_exists("mpirun"))
    GTEST_SKIP() << "mpirun is not on the PATH (OpenMPI not installed): the MPI sweep is not tested";
  // OpenMPI refuses root (containers, CI) unless told so; oversubscribe: two ranks on any machine.
  setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
  setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
  const Result mpi = run(dir_ / "mpi.log", with({"mpirun", "-np", "2", "--oversubscribe", magbrush},
                                                sweep_words(dir_, dir_ / "mpi")));
  ASSERT_EQ(mpi.status, 0) << mpi.output;
  // Each rank ran its own point (the first round of the deal: point i on rank i), and the table
  // was written once.
  EXPECT_NE(mpi.output.find("rank 0 of 2 runs points 0 with"), std::string::npos) << mpi.output;
  EXPECT_NE(mpi.output.find("rank 1 of 2 runs points 1 with"), std::string::npos) << mpi.output;
  std::size_t tables = 0;
  for (auto at = mpi.output.find("sweep_summary.csv\n"); at != std::string::npos;
       at = mpi.output.find("sweep_summary.csv\n", at + 1))
    ++tables;
  EXPECT_EQ(tables, 1u) << mpi.output;
  // The point folders record the rank that ran them: point i on rank i.
  for (int i = 0; i < 2; ++i)
    EXPECT_EQ(magbrush::testing::read_csv_rows(dir_ / "mpi" / "sweep_diameter" / point_folders[i] / "sweep_point.csv").at(1).at(2),
              std::to_string(i))
      << point_folders[i];
  expect_same_table_but_run_time(dir_ / "serial", dir_ / "mpi");
}

TEST_F(DistributedSweep, SlurmArrayStepsRunOneByOneGiveTheSerialTable)
{
  ASSERT_EQ(serial_.status, 0) << serial_.output;
  const fs::path out = dir_ / "slurm";
  const Result emitted = run(dir_ / "emit.log", with({magbrush}, with(sweep_words(dir_, out), {"--emit", "slurm"})));
  ASSERT_EQ(emitted.status, 0) << emitted.output;
  const fs::path array = out / "sweep_diameter" / "sweep_diameter.slurm";
  const fs::path merge = out / "sweep_diameter" / "sweep_diameter_merge.slurm";
  ASSERT_TRUE(fs::exists(array)) << emitted.output;
  ASSERT_TRUE(fs::exists(merge)) << emitted.output;
  // Nothing ran: no point folder yet.
  EXPECT_FALSE(fs::exists(out / "sweep_diameter" / point_folders[0]));
  const std::string script = text_of(array), merge_script = text_of(merge);
  EXPECT_EQ(script.rfind("#!/bin/bash\n", 0), 0u);
  EXPECT_NE(script.find("\n#SBATCH --array=0-1\n"), std::string::npos) << script;
  EXPECT_NE(script.find("\n#SBATCH --cpus-per-task="), std::string::npos) << script;
  EXPECT_NE(script.find("exec " + magbrush + " sweep " + (dir_ / "box.yaml").string() + " --vary "),
            std::string::npos)
    << script;
  EXPECT_NE(script.find("--point \"$SLURM_ARRAY_TASK_ID\""), std::string::npos) << script;
  EXPECT_EQ(script.substr(script.find("\nexec ")).find("--emit"), std::string::npos) << script;
  EXPECT_NE(script.find("--dependency=afterok:$jid"), std::string::npos) << script;
  EXPECT_EQ(merge_script.find("--array"), std::string::npos) << merge_script;
  EXPECT_NE(merge_script.find(" --merge\n"), std::string::npos) << merge_script;
  // Valid bash (sbatch reads the #SBATCH lines, bash the rest).
  for (const auto &s : {array, merge})
  {
    const Result syntax = run(dir_ / "syntax.log", {"bash", "-n", s.string()});
    EXPECT_EQ(syntax.status, 0) << s << ": " << syntax.output;
  }

  // A merge before any point ran says which points are missing and fails.
  const Result early = run(dir_ / "early.log", {"bash", merge.string()});
  EXPECT_NE(early.status, 0);
  EXPECT_NE(early.output.find("2 of 2 points have not run"), std::string::npos) << early.output;

  // Slurm's stand-in: each array task as Slurm would start it (the script, SLURM_ARRAY_TASK_ID
  // set), one after the other, then the merge step.
  for (const char *task : {"0", "1"})
  {
    setenv("SLURM_ARRAY_TASK_ID", task, 1);
    setenv("SLURM_CPUS_PER_TASK", "1", 1);
    const Result point = run(dir_ / "task.log", {"bash", array.string()});
    ASSERT_EQ(point.status, 0) << "task " << task << ": " << point.output;
    EXPECT_EQ(point.output.find("sweep_summary.csv"), std::string::npos) << "a task wrote the table";
  }
  unsetenv("SLURM_ARRAY_TASK_ID");
  unsetenv("SLURM_CPUS_PER_TASK");
  const Result merged = run(dir_ / "merge.log", {"bash", merge.string()});
  ASSERT_EQ(merged.status, 0) << merged.output;
  expect_same_table_but_run_time(dir_ / "serial", out);

  // A point outside the sweep is refused, naming the range.
  const Result outside = run(dir_ / "outside.log", with({magbrush}, with(sweep_words(dir_, out), {"--point", "2"})));
  EXPECT_NE(outside.status, 0);
  EXPECT_NE(outside.output.find("--point expects a point of this sweep, 0 to 1 (2 points), found '2'"),
            std::string::npos)
    << outside.output;
}

// A point stopped before its end continues with --resume from its own checkpoint, in its own
// folder, to the serial sweep's result bit for bit; its run time adds the time it had spent.
// The stop is the state a killed point leaves: its DEM ended at a checkpoint (here: a shorter
// duration, which is run control: 150 steps, a row of the time series, so that its end adds no
// row the uninterrupted run lacks), its sweep_point.csv still says "running", and its DEM log
// was last written some time after the point started (100 s here, set on the files' clocks).
TEST_F(DistributedSweep, AStoppedPointResumesFromItsCheckpointToTheSerialResult)
{
  ASSERT_EQ(serial_.status, 0) << serial_.output;
  const fs::path out = dir_ / "resume";
  const fs::path point = out / "sweep_diameter" / point_folders[0];
  const Result first = run(dir_ / "first.log", with({magbrush}, with(sweep_words(dir_, out),
                                                                      {"--point", "0", "--set", "dem.duration=9.934us"})));
  ASSERT_EQ(first.status, 0) << first.output;
  ASSERT_TRUE(fs::exists(point / "dem" / "checkpoint.bin")) << first.output;
  std::ofstream(point / "sweep_point.csv") << "# stopped\nrun_time_s,status,rank\n5.0,running,0\n";
  const auto started = fs::last_write_time(point / "sweep_point.csv");
  fs::last_write_time(point / "dem" / "dem.log", started + std::chrono::seconds(100));

  // The merge of a stopped point says so and fails.
  const Result early = run(dir_ / "early_merge.log", with({magbrush}, with(sweep_words(dir_, out), {"--merge"})));
  EXPECT_NE(early.status, 0);
  EXPECT_NE(early.output.find("have not finished (running, or stopped before their end): 0 (p0_diameter-100um)"),
            std::string::npos)
    << early.output;

  const Result resumed = run(dir_ / "resumed.log", with({magbrush}, with(sweep_words(dir_, out), {"--point", "0", "--resume"})));
  ASSERT_EQ(resumed.status, 0) << resumed.output;
  EXPECT_NE(resumed.output.find("resume: continuing from this folder's checkpoint"), std::string::npos)
    << resumed.output;
  const double run_time = std::stod(magbrush::testing::read_csv_rows(point / "sweep_point.csv").at(1).at(0));
  EXPECT_GE(run_time, 105.0);
  EXPECT_LT(run_time, 105.0 + 120.0);
  // The DEM log keeps the first run's lines above the resumed run's.
  const std::string log = text_of(point / "dem" / "dem.log");
  EXPECT_LT(log.find("restarted from"), std::string::npos);
  EXPECT_LT(log.find("magbrush-dem"), log.find("restarted from")) << log;

  // A point without a checkpoint starts afresh under --resume.
  const Result fresh = run(dir_ / "fresh.log", with({magbrush}, with(sweep_words(dir_, out), {"--point", "1", "--resume"})));
  ASSERT_EQ(fresh.status, 0) << fresh.output;
  EXPECT_NE(fresh.output.find("resume: no checkpoint in"), std::string::npos) << fresh.output;
  const Result merged = run(dir_ / "merge_resumed.log", with({magbrush}, with(sweep_words(dir_, out), {"--merge"})));
  ASSERT_EQ(merged.status, 0) << merged.output;
  expect_same_table_but_run_time(dir_ / "serial", out);

  // A finished point resumed only rewrites its files: the same time series.
  const std::string series = text_of(point / "dem" / "time_series.csv");
  const Result again = run(dir_ / "again.log", with({magbrush}, with(sweep_words(dir_, out), {"--point", "0", "--resume"})));
  ASSERT_EQ(again.status, 0) << again.output;
  EXPECT_EQ(text_of(point / "dem" / "time_series.csv"), series);
}

} // namespace
