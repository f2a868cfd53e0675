// Nothing lost, nothing silently wrong: the checkpoint's checksum (a flipped bit anywhere is
// refused before anything is read, with the file named and the checkpoint before it offered),
// its format version, its case identity, the checkpoint kept before the last one, a
// checkpoint that leaves the run which writes it bit for bit alone, and the snapshots'
// Fletcher-32 checksums.
#include "case/case_hash.h"
#include "dem/checkpoint_file.h"
#include "dem/dem_system.h"
#include "dem/force_terms/gravity.h"
#include "dem/restart_check.h"
#include "dem/snapshot_writer.h"
#include "tests/dem/dem_test_scenes.h"
#include "tests/test_temp_dir.h"

#include <gtest/gtest.h>
#include <hdf5.h>
#include <omp.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

using namespace magbrush;
using namespace magbrush::dem;
using namespace magbrush::dem::testing;
namespace fs = std::filesystem;

namespace {

// 300 falling spheres (dem_test_scenes.h): contacts, wall contacts, list rebuilds and
// re-sorting within a few hundred steps.
Case falling_case()
{
  Case c = falling_spheres_case(300, 1.5e-3, 0.4e-3, 5);
  c.materials[0].polygon_angles = Material{}.polygon_angles; // smooth spheres: no rolling resistance
  return c;
}

std::unique_ptr<DemSystem> make_falling(const Case &c)
{
  auto sys = std::make_unique<DemSystem>(c);
  sys->add_force_term(std::make_unique<Gravity>(c.dem.gravity));
  sys->insert_particles();
  give_random_velocities(sys->particles(), 11);
  sys->initialize();
  return sys;
}

std::string read_bytes(const fs::path &p)
{
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void write_bytes(const fs::path &p, const std::string &bytes)
{
  std::ofstream(p, std::ios::binary | std::ios::trunc) << bytes;
}

// The message of what `f` throws (empty, and a test failure, when it throws nothing).
template <typename F>
std::string error_of(F &&f)
{
  try
  {
    f();
  }
  catch (const std::exception &e)
  {
    return e.what();
  }
  ADD_FAILURE() << "expected an exception";
  return {};
}

bool contains(const std::string &text, const std::string &fragment) { return text.find(fragment) != std::string::npos; }

CheckpointIdentity some_identity()
{
  return {"0123456789abcdef", {{"populations.carrier.count", "300"}, {"dem.duration", "0.001"}}};
}

} // namespace

// One flipped bit anywhere — in the identity, the particle arrays, the last byte of the
// state, the stored checksum — is refused before a single value is handed out; the intact
// file reads. Without a kept checkpoint the message says to rerun; with one, it names it.
TEST(CheckpointFile, FlippedBitAnywhereIsRefusedBeforeAnythingIsRead)
{
  omp_set_num_threads(1);
  const Case c = falling_case();
  auto sys = make_falling(c);
  for (int k = 0; k < 50; ++k)
    sys->step();
  const fs::path dir = magbrush::testing::test_temp_dir("checkpoint_flip");
  const fs::path path = dir / "checkpoint.bin";
  sys->write_checkpoint(path.string(), some_identity());
  const std::string good = read_bytes(path);
  ASSERT_GT(good.size(), 100000u);
  EXPECT_EQ(CheckpointReader(path.string()).identity().inputs, some_identity().inputs);
  for (const std::size_t at : {std::size_t{20}, good.size() / 3, good.size() / 2, good.size() - 13, good.size() - 1})
  {
    std::string bad = good;
    bad[at] = static_cast<char>(bad[at] ^ 0x10);
    write_bytes(path, bad);
    const std::string m = error_of([&] { CheckpointReader in(path.string()); });
    EXPECT_TRUE(contains(m, "checkpoint '" + path.string() + "' is damaged")) << "byte " << at << ": " << m;
    EXPECT_TRUE(contains(m, "nothing was read from it")) << m;
    EXPECT_TRUE(contains(m, "rerun the case from the start (no earlier checkpoint is kept beside it)")) << m;
    DemSystem other(c);
    other.add_force_term(std::make_unique<Gravity>(c.dem.gravity));
    EXPECT_THROW(other.read_checkpoint(path.string()), std::runtime_error);
  }
  // With the checkpoint before it kept, the message offers it.
  write_bytes(previous_checkpoint_path(path.string()), good);
  std::string bad = good;
  bad[good.size() / 2] = static_cast<char>(bad[good.size() / 2] ^ 0x01);
  write_bytes(path, bad);
  const std::string m = error_of([&] { CheckpointReader in(path.string()); });
  EXPECT_TRUE(contains(m, "restart from the checkpoint kept before it, '" + (dir / "checkpoint.previous.bin").string())) << m;
  // Cut short (a copy that stopped): refused as well.
  write_bytes(path, good.substr(0, good.size() - 1000));
  EXPECT_TRUE(contains(error_of([&] { CheckpointReader in(path.string()); }), "is damaged or truncated"));
  // Intact: reads, and the state is the one written.
  write_bytes(path, good);
  DemSystem restored(c);
  restored.add_force_term(std::make_unique<Gravity>(c.dem.gravity));
  restored.read_checkpoint(path.string());
  EXPECT_EQ(restored.step_count(), 50);
  EXPECT_EQ(state_by_id(restored), state_by_id(*sys));
}

TEST(CheckpointFile, OlderFormatIsRefusedWithWhatToDo)
{
  const fs::path path = magbrush::testing::test_temp_dir("checkpoint_old") / "old.bin";
  write_bytes(path, std::string("MBDEMCK3") + std::string(64, '\0'));
  const std::string m = error_of([&] { CheckpointReader in(path.string()); });
  EXPECT_TRUE(contains(m, "has format MBDEMCK3")) << m;
  EXPECT_TRUE(contains(m, "rerun the case from the start")) << m;
  write_bytes(path, "not a checkpoint at all");
  EXPECT_TRUE(contains(error_of([&] { CheckpointReader in(path.string()); }), "is not a magbrush DEM checkpoint"));
}

// Writing a checkpoint changes nothing in the run that writes it (a wall-clock checkpoint may
// come at any step), and the run restarted from it continues bit for bit.
TEST(CheckpointFile, WritingOneLeavesTheRunAloneAndTheRestartContinuesIt)
{
  omp_set_num_threads(1);
  const Case c = falling_case();
  const fs::path path = magbrush::testing::test_temp_dir("checkpoint_alone") / "checkpoint.bin";
  auto with = make_falling(c);
  auto without = make_falling(c);
  for (int k = 0; k < 1333; ++k)
  {
    with->step();
    without->step();
  }
  with->write_checkpoint(path.string());
  for (int k = 0; k < 1500; ++k)
  {
    with->step();
    without->step();
  }
  DemSystem restarted(c);
  restarted.add_force_term(std::make_unique<Gravity>(c.dem.gravity));
  restarted.read_checkpoint(path.string());
  for (int k = 0; k < 1500; ++k)
    restarted.step();
  std::printf("2833 steps, checkpoint after 1333: %ld contacts, %ld list rebuilds at the end\n",
              without->particle_contacts(), without->neighbour_rebuilds());
  EXPECT_GT(without->neighbour_rebuilds(), 2);
  EXPECT_GT(without->particle_contacts(), 5); // (touching pairs carry contact history)
  EXPECT_EQ(state_by_id(*with), state_by_id(*without));
  EXPECT_EQ(state_by_id(restarted), state_by_id(*without));
  EXPECT_EQ(restarted.neighbour_rebuilds(), without->neighbour_rebuilds());
}

// keep_previous_checkpoint: the checkpoint before the last one survives, byte for byte.
TEST(CheckpointFile, TheOneBeforeIsKept)
{
  omp_set_num_threads(1);
  const Case c = falling_case();
  auto sys = make_falling(c);
  const fs::path dir = magbrush::testing::test_temp_dir("checkpoint_previous");
  const std::string path = (dir / "checkpoint.bin").string();
  EXPECT_EQ(previous_checkpoint_path(path), (dir / "checkpoint.previous.bin").string());
  keep_previous_checkpoint(path); // nothing to keep yet
  EXPECT_FALSE(fs::exists(previous_checkpoint_path(path)));
  sys->write_checkpoint(path);
  const std::string first = read_bytes(path);
  for (int k = 0; k < 20; ++k)
    sys->step();
  keep_previous_checkpoint(path);
  sys->write_checkpoint(path);
  EXPECT_EQ(read_bytes(previous_checkpoint_path(path)), first);
  EXPECT_NE(read_bytes(path), first);
  EXPECT_EQ(CheckpointReader(path).get<long>(), 20); // the step, first after the identity
}

TEST(RestartCheck, RunControlMayDifferTheSceneMayNot)
{
  CheckpointIdentity written{"a", {{"name", "nip"},
                                   {"populations.carrier.count", "2000"},
                                   {"dem.duration", "0.001"},
                                   {"dem.threads", "0"},
                                   {"output.directory", "results"},
                                   {"dem.time_step", "4e-08"}}};
  CheckpointIdentity now{"b", {{"name", "nip"},
                               {"populations.carrier.count", "3000"},
                               {"dem.duration", "0.002"},
                               {"dem.threads", "0"},
                               {"output.directory", "elsewhere"},
                               {"materials.toner.density", "1000"}}};
  const auto d = case_differences(written, now);
  ASSERT_EQ(d.size(), 5u);
  EXPECT_EQ(d[0].key, "populations.carrier.count");
  EXPECT_FALSE(d[0].run_control);
  EXPECT_EQ(d[1].key, "dem.duration");
  EXPECT_TRUE(d[1].run_control);
  EXPECT_EQ(d[2].key, "output.directory");
  EXPECT_TRUE(d[2].run_control);
  EXPECT_EQ(d[3].key, "dem.time_step");
  EXPECT_EQ(d[3].in_case, "(absent)");
  EXPECT_FALSE(d[3].run_control);
  EXPECT_EQ(d[4].key, "materials.toner.density");
  EXPECT_EQ(d[4].in_checkpoint, "(absent)");
  EXPECT_TRUE(contains(describe(d), "  populations.carrier.count: 2000 (checkpoint) -> 3000 (this case)\n"));
  EXPECT_TRUE(case_differences(written, written).empty());
  EXPECT_FALSE(d[4].added_at_default); // a default case has no toner material
  // What is measured, and over which window, is not the state: a continued run may average anew.
  for (const char *key : {"dma.average_from", "nip.half_width", "development.measure_to", "flow_report.flux_angle",
                          "statistics.blocks"})
    EXPECT_TRUE(is_run_control_key(key)) << key;
  for (const char *key : {"drum.gap", "inflow.areal_mass", "electric.bias", "dem.magnetic_staleness"})
    EXPECT_FALSE(is_run_control_key(key)) << key;
  // Where the stored fields are is not what they hold (their provenance is checked on reading):
  // a run moved into a sweep's folder, whose fields live per digest, continues.
  EXPECT_TRUE(is_run_control_key("field.output_dir"));
  // A first leg (dem.leg) is continued without it.
  EXPECT_TRUE(is_run_control_key("dem.leg"));

  // A key the schema gained after the checkpoint was written: at its default it is flagged
  // (the restart goes on), at another value it is a difference of the scene.
  std::string sump_default;
  for (const auto &[key, value] : case_inputs(Case{}))
    if (key == "inflow.sump_mass")
      sump_default = value;
  ASSERT_FALSE(sump_default.empty());
  CheckpointIdentity newer = written;
  newer.inputs.emplace_back("inflow.sump_mass", sump_default);
  const auto at_default = case_differences(written, newer);
  ASSERT_EQ(at_default.size(), 1u);
  EXPECT_TRUE(at_default[0].added_at_default);
  newer.inputs.back().second = "0.5";
  const auto changed = case_differences(written, newer);
  ASSERT_EQ(changed.size(), 1u);
  EXPECT_FALSE(changed[0].added_at_default);
}

// A snapshot value damaged on disk (its lowest mantissa byte) fails HDF5's read through the
// Fletcher-32 filter — what ParaView, h5py and the report then refuse — and reads intact.
TEST(SnapshotFile, DamagedValueFailsItsChecksum)
{
  omp_set_num_threads(1);
  const Case c = falling_case();
  auto sys = make_falling(c);
  for (int k = 0; k < 30; ++k)
    sys->step();
  const fs::path dir = magbrush::testing::test_temp_dir("snapshot_flip") / "out";
  SnapshotWriter w(dir.string());
  w.write(*sys);
  const fs::path h5 = dir / w.snapshots().at(0).second;
  const auto &p = sys->particles();
  std::size_t k = 0;
  while (p.id[k] != 7)
    ++k;
  const double value = p.x[k]; // stored at position[7][0]
  std::string bytes = read_bytes(h5);
  const std::string pattern(reinterpret_cast<const char *>(&value), sizeof value);
  const std::size_t at = bytes.find(pattern);
  ASSERT_NE(at, std::string::npos);
  auto read_position = [&] {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    const hid_t f = H5Fopen(h5.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0)
      return false;
    std::vector<double> pos(3 * p.size());
    const hid_t d = H5Dopen2(f, "position", H5P_DEFAULT);
    const bool ok = d >= 0 && H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, pos.data()) >= 0 &&
                    pos[3 * 7] == value;
    if (d >= 0)
      H5Dclose(d);
    H5Fclose(f);
    return ok;
  };
  EXPECT_TRUE(read_position());
  bytes[at] = static_cast<char>(bytes[at] ^ 0x01);
  write_bytes(h5, bytes);
  EXPECT_FALSE(read_position()) << "a damaged value was read back";
  bytes[at] = static_cast<char>(bytes[at] ^ 0x01);
  write_bytes(h5, bytes);
  EXPECT_TRUE(read_position());
}
