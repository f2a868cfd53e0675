// The HDF5 field-grid format: bit-exact round trip, the reader's checks (each with the
// message a user will see), provenance comparison and the atomic write.
#include "tests/fields/exact_multipole.h"
#include "fields/field_grid.h"

#include <gtest/gtest.h>
#include "tests/test_temp_dir.h"
#include <hdf5.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>

using namespace magbrush;
namespace fs = std::filesystem;

namespace {

// A scratch directory per test, removed when the test program ends.
fs::path scratch_dir()
{
  const auto *info = ::testing::UnitTest::GetInstance()->current_test_info();
  return magbrush::testing::test_temp_dir(std::string("fieldgrid_") + info->name());
}

PolarGrid some_polar_grid()
{
  // Values with all bits in play (irrational-looking), to make "bit-exact" meaningful.
  return sample_polar_grid(12.5e-3, 15.5e-3, 7, 24, [](double x, double y) {
    return 1e-4 * std::sin(3 * std::atan2(y, x) + 0.1) / std::pow(std::hypot(x, y) * 80, 3) +
           1e-7 * x / (y + 1.0);
  });
}

CartesianGrid some_cartesian_grid()
{
  return sample_cartesian_grid(-2e-4, 3e-4, 6, 1e-5, 4.1e-4, 5,
                               [](double x, double y) { return 1e6 * x * y - 600.0 + std::exp(x * 1e3); });
}

// A nip potential: the bias grid plus K image phases (distinct values in every sample).
NipPotentialGrid some_nip_grid(const CartesianGrid &bias, int K = 3, double period = 250e-6)
{
  NipPotentialGrid g;
  g.bias = bias;
  g.image_period = K == 1 ? 0.0 : period;
  for (int k = 0; k < K; ++k)
  {
    std::vector<double> v(bias.phi.size());
    for (size_t n = 0; n < v.size(); ++n)
      v[n] = 37.0 * std::sin(0.7 * n + 1.3 * k + 0.2);
    g.image.push_back(v);
  }
  return g;
}

GridProvenance some_provenance()
{
  GridProvenance p;
  p.case_hash = "fnv1a64:0123456789abcdef";
  p.case_inputs = {{"roller.magnet_radius", "0.0093"},
                   {"roller.poles.N1.angle", "1.2566370614359172"},
                   {"field.grid_radial_spacing", "5.0000000000000002e-05"},
                   {"sleeve.radius", "0.0125"}};
  p.mesh_sizes = {{"far", 2e-3}, {"sleeve", 1e-4}, {"gap", 2e-5}};
  p.element_degree = 2;
  p.error_estimate = 3.25e-4;
  return p;
}

// Runs `f` and returns the FieldGridError message (fails the test when nothing is thrown).
template <typename F>
std::string error_of(F f)
{
  try
  {
    f();
  }
  catch (const FieldGridError &e)
  {
    return e.what();
  }
  ADD_FAILURE() << "expected a FieldGridError";
  return {};
}

// Tampering with a written file through the HDF5 C API, as a damaged or foreign file would be.
struct H5File
{
  hid_t id;
  explicit H5File(const fs::path &p) : id(H5Fopen(p.c_str(), H5F_ACC_RDWR, H5P_DEFAULT)) {}
  ~H5File() { H5Fclose(id); }
};

void set_string_attribute(hid_t obj, const char *name, const std::string &value)
{
  if (H5Aexists(obj, name) > 0)
    H5Adelete(obj, name);
  hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, value.size());
  hid_t space = H5Screate(H5S_SCALAR);
  hid_t attr = H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(attr, type, value.data());
  H5Aclose(attr);
  H5Sclose(space);
  H5Tclose(type);
}

void set_int_attribute(hid_t obj, const char *name, int value)
{
  H5Adelete(obj, name);
  hid_t space = H5Screate(H5S_SCALAR);
  hid_t attr = H5Acreate2(obj, name, H5T_STD_I32LE, space, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(attr, H5T_NATIVE_INT, &value);
  H5Aclose(attr);
  H5Sclose(space);
}

void replace_dataset(hid_t file, const char *name, const std::vector<double> &data,
                     const std::vector<hsize_t> &dims, const char *units, bool checksum = true)
{
  H5Ldelete(file, name, H5P_DEFAULT);
  hid_t space = H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr);
  // With the checksum filter every dataset of the format has (or the reader stops there).
  hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
  if (checksum)
  {
    H5Pset_chunk(dcpl, static_cast<int>(dims.size()), dims.data());
    H5Pset_fletcher32(dcpl);
  }
  hid_t set = H5Dcreate2(file, name, H5T_IEEE_F64LE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
  H5Dwrite(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data());
  if (units)
    set_string_attribute(set, "units", units);
  H5Dclose(set);
  H5Pclose(dcpl);
  H5Sclose(space);
}

bool contains(const std::string &text, const std::string &fragment)
{
  return text.find(fragment) != std::string::npos;
}

} // namespace

TEST(FieldGridFile, MagneticRoundTripIsBitExact)
{
  const fs::path path = scratch_dir() / "roller_field.h5";
  const PolarGrid g = some_polar_grid();
  const GridProvenance p = some_provenance();
  write_magnetic_grid(path, g, p);
  EXPECT_FALSE(fs::exists(path.string() + ".tmp"));

  const MagneticGridFile in = read_magnetic_grid(path);
  EXPECT_EQ(in.grid.r_min, g.r_min);
  EXPECT_EQ(in.grid.r_max, g.r_max);
  EXPECT_EQ(in.grid.n_r, g.n_r);
  EXPECT_EQ(in.grid.n_theta, g.n_theta);
  ASSERT_EQ(in.grid.A_z.size(), g.A_z.size());
  EXPECT_EQ(std::memcmp(in.grid.A_z.data(), g.A_z.data(), g.A_z.size() * sizeof(double)), 0);

  const GridFileInfo &info = in.info;
  EXPECT_EQ(info.path, path.string());
  EXPECT_EQ(info.kind, "magnetic");
  EXPECT_EQ(info.format_version, field_grid_format_version);
  EXPECT_EQ(info.code_version, MAGBRUSH_VERSION);
  EXPECT_TRUE(std::regex_match(info.created, std::regex(R"(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ)")))
      << info.created;
  ASSERT_EQ(info.grid_spacing.size(), 2u);
  EXPECT_EQ(info.grid_spacing[0], g.dr());
  EXPECT_EQ(info.grid_spacing[1], g.dtheta());
  EXPECT_EQ(info.provenance.case_hash, p.case_hash);
  EXPECT_EQ(info.provenance.case_inputs, p.case_inputs);
  EXPECT_EQ(info.provenance.mesh_sizes, p.mesh_sizes);
  EXPECT_EQ(info.provenance.element_degree, 2);
  EXPECT_EQ(info.provenance.error_estimate, p.error_estimate);

  // The header alone, without the data.
  const GridFileInfo header = read_grid_info(path);
  EXPECT_EQ(header.provenance.case_inputs, p.case_inputs);
  EXPECT_EQ(header.kind, "magnetic");
}

TEST(FieldGridFile, ElectricRoundTripIsBitExactAndUnknownErrorIsNaN)
{
  const fs::path path = scratch_dir() / "nip_field.h5";
  const CartesianGrid g = some_cartesian_grid();
  GridProvenance p = some_provenance();
  p.error_estimate = std::nan("");
  p.mesh_sizes.clear();
  const NipPotentialGrid nip = some_nip_grid(g);
  write_electric_grid(path, nip, p);
  const ElectricGridFile in = read_electric_grid(path);
  EXPECT_EQ(in.info.kind, "electric");
  EXPECT_EQ(in.info.format_version, field_grid_format_version);
  EXPECT_EQ(in.grid.bias.x_min, g.x_min);
  EXPECT_EQ(in.grid.bias.x_max, g.x_max);
  EXPECT_EQ(in.grid.bias.y_min, g.y_min);
  EXPECT_EQ(in.grid.bias.y_max, g.y_max);
  EXPECT_EQ(in.grid.bias.n_x, g.n_x);
  EXPECT_EQ(in.grid.bias.n_y, g.n_y);
  EXPECT_EQ(std::memcmp(in.grid.bias.phi.data(), g.phi.data(), g.phi.size() * sizeof(double)), 0);
  EXPECT_EQ(in.grid.image_period, nip.image_period);
  ASSERT_EQ(in.grid.phase_samples(), 3);
  for (int k = 0; k < 3; ++k)
    EXPECT_EQ(in.grid.image[k], nip.image[k]) << "phase sample " << k;
  EXPECT_TRUE(std::isnan(in.info.provenance.error_estimate));
  EXPECT_TRUE(in.info.provenance.mesh_sizes.empty());
  EXPECT_EQ(in.info.grid_spacing, (std::vector<double>{g.dx(), g.dy()}));
}

TEST(FieldGridFile, ReaderRejectsWrongFormatVersionAndKind)
{
  const fs::path dir = scratch_dir();
  const fs::path path = dir / "f.h5";
  write_magnetic_grid(path, some_polar_grid(), some_provenance());
  {
    H5File f(path);
    set_string_attribute(f.id, "format", "someone-elses-grid");
  }
  EXPECT_TRUE(contains(error_of([&] { read_magnetic_grid(path); }),
                       "format is 'someone-elses-grid' but 'magbrush-field-grid' was expected"));

  write_magnetic_grid(path, some_polar_grid(), some_provenance());
  {
    H5File f(path);
    set_int_attribute(f.id, "format_version", 99);
  }
  const std::string version = error_of([&] { read_magnetic_grid(path); });
  EXPECT_TRUE(contains(version, "format_version is 99")) << version;
  EXPECT_TRUE(contains(version, "regenerate")) << version;

  write_magnetic_grid(path, some_polar_grid(), some_provenance());
  const std::string kind = error_of([&] { read_electric_grid(path); });
  EXPECT_TRUE(contains(kind, "kind is 'magnetic' but a 'electric' field grid was expected")) << kind;
  EXPECT_TRUE(contains(kind, path.string())) << kind;

  // Older versions (no checksums; version 1 also one Φ without the image's phases) are
  // refused, magnetic or electric, with the advice to regenerate.
  for (int old_version : {1, 2})
  {
    write_magnetic_grid(path, some_polar_grid(), some_provenance());
    {
      H5File f(path);
      set_int_attribute(f.id, "format_version", old_version);
    }
    const std::string old_magnetic = error_of([&] { read_magnetic_grid(path); });
    EXPECT_TRUE(contains(old_magnetic, "regenerate")) << old_magnetic;
    write_electric_grid(path, some_nip_grid(some_cartesian_grid()), some_provenance());
    {
      H5File f(path);
      set_int_attribute(f.id, "format_version", old_version);
    }
    const std::string old_electric = error_of([&] { read_electric_grid(path); });
    EXPECT_TRUE(contains(old_electric, "format_version is " + std::to_string(old_version))) << old_electric;
  }
}

TEST(FieldGridFile, ReaderRejectsMissingDatasetAndAttribute)
{
  const fs::path path = scratch_dir() / "f.h5";
  write_magnetic_grid(path, some_polar_grid(), some_provenance());
  {
    H5File f(path);
    H5Ldelete(f.id, "/polar/A_z", H5P_DEFAULT);
  }
  EXPECT_TRUE(contains(error_of([&] { read_magnetic_grid(path); }), "dataset /polar/A_z is missing"));

  write_magnetic_grid(path, some_polar_grid(), some_provenance());
  {
    H5File f(path);
    H5Adelete(f.id, "case_hash");
  }
  const std::string m = error_of([&] { read_grid_info(path); });
  EXPECT_TRUE(contains(m, "attribute 'case_hash'")) << m;
  EXPECT_TRUE(contains(m, "missing")) << m;
}

TEST(FieldGridFile, ReaderRejectsMismatchedUnits)
{
  const fs::path path = scratch_dir() / "f.h5";
  const PolarGrid g = some_polar_grid();
  write_magnetic_grid(path, g, some_provenance());
  {
    H5File f(path);
    hid_t set = H5Dopen2(f.id, "/polar/A_z", H5P_DEFAULT);
    set_string_attribute(set, "units", "T");
    H5Dclose(set);
  }
  const std::string m = error_of([&] { read_magnetic_grid(path); });
  EXPECT_TRUE(contains(m, "file " + path.string() +
                              ": dataset /polar/A_z has units 'T' but 'T*m' was expected"))
      << m;

  write_magnetic_grid(path, g, some_provenance());
  {
    H5File f(path);
    hid_t set = H5Dopen2(f.id, "/polar/r", H5P_DEFAULT);
    H5Adelete(set, "units");
    H5Dclose(set);
  }
  EXPECT_TRUE(contains(error_of([&] { read_magnetic_grid(path); }),
                       "dataset /polar/r has no 'units' attribute ('m' was expected)"));
}

TEST(FieldGridFile, ReaderRejectsWrongShapes)
{
  const fs::path path = scratch_dir() / "f.h5";
  const PolarGrid g = some_polar_grid();
  write_magnetic_grid(path, g, some_provenance());
  {
    H5File f(path);
    std::vector<double> transposed(g.A_z.size(), 0.0);
    replace_dataset(f.id, "/polar/A_z", transposed,
                    {static_cast<hsize_t>(g.n_theta), static_cast<hsize_t>(g.n_r)}, "T*m");
  }
  const std::string m = error_of([&] { read_magnetic_grid(path); });
  EXPECT_TRUE(contains(m, "dataset /polar/A_z has shape (24, 7) but (7, 24) was expected")) << m;

  // Attributes that disagree with the axis datasets.
  write_magnetic_grid(path, g, some_provenance());
  {
    H5File f(path);
    hid_t group = H5Gopen2(f.id, "/polar", H5P_DEFAULT);
    set_int_attribute(group, "n_r", 8);
    H5Gclose(group);
  }
  EXPECT_TRUE(contains(error_of([&] { read_magnetic_grid(path); }),
                       "dataset /polar/r has shape (7) but (8) was expected"));
}

TEST(FieldGridFile, ReaderRejectsNonFiniteValuesAndNonMonotoneAxes)
{
  const fs::path path = scratch_dir() / "f.h5";
  const CartesianGrid g = some_cartesian_grid();
  write_electric_grid(path, some_nip_grid(g), some_provenance());
  {
    H5File f(path);
    std::vector<double> phi = g.phi;
    phi[7] = std::nan("");
    replace_dataset(f.id, "/cartesian/phi_bias", phi,
                    {static_cast<hsize_t>(g.n_x), static_cast<hsize_t>(g.n_y)}, "V");
  }
  const std::string m = error_of([&] { read_electric_grid(path); });
  EXPECT_TRUE(contains(m, "/cartesian/phi has a non-finite value (nan) at node [1][2]")) << m;

  write_electric_grid(path, some_nip_grid(g), some_provenance());
  {
    H5File f(path);
    std::vector<double> x(g.n_x);
    for (int i = 0; i < g.n_x; ++i)
      x[i] = g.x(i);
    std::swap(x[2], x[3]);
    replace_dataset(f.id, "/cartesian/x", x, {static_cast<hsize_t>(g.n_x)}, "m");
  }
  const std::string axis = error_of([&] { read_electric_grid(path); });
  EXPECT_TRUE(contains(axis, "dataset /cartesian/x is not strictly increasing at index 3")) << axis;
}

// Damage on disk: one byte of one stored value flipped (its lowest mantissa byte: a change
// of 1 ulp-ish that no range check could see). HDF5's Fletcher-32 filter fails the read, and
// the reader turns that into a message naming the file, the dataset and the remedy. A dataset
// without the filter (a file from before the checksums) is refused as well.
TEST(FieldGridFile, DamagedValueIsRefusedByItsChecksum)
{
  const fs::path path = scratch_dir() / "roller_field.h5";
  const PolarGrid g = some_polar_grid();
  write_magnetic_grid(path, g, some_provenance());
  std::string bytes;
  {
    std::ifstream in(path, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  // The stored bytes of A_z[1][5] (little-endian IEEE doubles, uncompressed chunks).
  const double value = g.A_z[1 * static_cast<size_t>(g.n_theta) + 5];
  const std::string pattern(reinterpret_cast<const char *>(&value), sizeof value);
  const size_t at = bytes.find(pattern);
  ASSERT_NE(at, std::string::npos);
  ASSERT_EQ(bytes.find(pattern, at + 1), std::string::npos) << "the value should be stored once";
  bytes[at] = static_cast<char>(bytes[at] ^ 0x01); // the lowest mantissa byte
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  const std::string m = error_of([&] { read_magnetic_grid(path); });
  EXPECT_TRUE(contains(m, path.string())) << m;
  EXPECT_TRUE(contains(m, "dataset /polar/A_z is damaged: its Fletcher-32 checksum does not match")) << m;
  EXPECT_TRUE(contains(m, "regenerate it with `magbrush field CASE`")) << m;
  // Flipped back, the file reads again (so the refusal came from that byte alone).
  bytes[at] = static_cast<char>(bytes[at] ^ 0x01);
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  EXPECT_EQ(read_magnetic_grid(path).grid.A_z, g.A_z);

  // The same values without the filter: not a file of this format version.
  {
    H5File f(path);
    replace_dataset(f.id, "/polar/A_z", g.A_z, {static_cast<hsize_t>(g.n_r), static_cast<hsize_t>(g.n_theta)},
                    "T*m", /*checksum=*/false);
  }
  const std::string old = error_of([&] { read_magnetic_grid(path); });
  EXPECT_TRUE(contains(old, "/polar/A_z carries no Fletcher-32 checksum")) << old;
  EXPECT_TRUE(contains(old, "regenerate")) << old;
}

TEST(FieldGridFile, ReaderRejectsMissingAndForeignFiles)
{
  const fs::path dir = scratch_dir();
  const std::string missing = error_of([&] { read_magnetic_grid(dir / "nope.h5"); });
  EXPECT_TRUE(contains(missing, "cannot open it")) << missing;
  EXPECT_TRUE(contains(missing, "magbrush field")) << missing;
  std::ofstream(dir / "text.h5") << "not hdf5\n";
  EXPECT_TRUE(contains(error_of([&] { read_magnetic_grid(dir / "text.h5"); }), "not an HDF5 file"));
  // An HDF5 file that is not ours.
  {
    hid_t f = H5Fcreate((dir / "other.h5").c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    H5Fclose(f);
  }
  EXPECT_TRUE(contains(error_of([&] { read_grid_info(dir / "other.h5"); }),
                       "no 'format' attribute: not a magbrush-field-grid file"));
}

TEST(FieldGridFile, ProvenanceMismatchNamesTheDifferingKey)
{
  const fs::path path = scratch_dir() / "f.h5";
  const GridProvenance p = some_provenance();
  write_magnetic_grid(path, some_polar_grid(), p);
  const GridFileInfo info = read_grid_info(path);

  EXPECT_EQ(provenance_difference(info, p.case_inputs), "");
  EXPECT_NO_THROW(check_provenance(info, p.case_inputs));

  auto changed = p.case_inputs;
  changed[1].second = "1.3"; // the N1 pole moved
  try
  {
    check_provenance(info, changed);
    FAIL() << "expected ProvenanceMismatch";
  }
  catch (const ProvenanceMismatch &e)
  {
    EXPECT_EQ(e.differing_key, "roller.poles.N1.angle");
    const std::string m = e.what();
    EXPECT_TRUE(contains(m, "was computed for roller.poles.N1.angle = 1.2566370614359172 but the "
                            "case has roller.poles.N1.angle = 1.3"))
        << m;
    EXPECT_TRUE(contains(m, path.string())) << m;
    EXPECT_TRUE(contains(m, "regenerate")) << m;
  }

  auto extra = p.case_inputs;
  extra.emplace_back("blade.mu_r", "200");
  EXPECT_TRUE(contains(provenance_difference(info, extra), "does not record input 'blade.mu_r'"));
  try
  {
    check_provenance(info, extra);
    FAIL();
  }
  catch (const ProvenanceMismatch &e)
  {
    EXPECT_EQ(e.differing_key, "blade.mu_r");
  }

  auto fewer = p.case_inputs;
  fewer.pop_back();
  EXPECT_TRUE(contains(provenance_difference(info, fewer),
                       "was computed with input sleeve.radius = 0.0125, which the case does not have"));
}

TEST(FieldGridFile, WriteIsAtomic)
{
  const fs::path dir = scratch_dir();
  // Unwritable place (a directory that does not exist): an error, and no file at all.
  const fs::path nowhere = dir / "no_such_dir" / "f.h5";
  const std::string m = error_of([&] { write_magnetic_grid(nowhere, some_polar_grid(), some_provenance()); });
  EXPECT_TRUE(contains(m, "cannot create")) << m;
  EXPECT_FALSE(fs::exists(nowhere));
  EXPECT_FALSE(fs::exists(nowhere.string() + ".tmp"));

  // Failure after the data is written (the target is a directory, the rename fails):
  // the temporary file is removed too.
  const fs::path occupied = dir / "occupied.h5";
  fs::create_directories(occupied / "inside");
  const std::string r = error_of([&] { write_magnetic_grid(occupied, some_polar_grid(), some_provenance()); });
  EXPECT_TRUE(contains(r, "cannot rename")) << r;
  EXPECT_FALSE(fs::exists(occupied.string() + ".tmp"));
  EXPECT_TRUE(fs::is_directory(occupied / "inside"));

  // A failed overwrite leaves the previous file as it was; a good one replaces it.
  const fs::path path = dir / "f.h5";
  write_magnetic_grid(path, some_polar_grid(), some_provenance());
  const auto before = fs::file_size(path);
  PolarGrid bad = some_polar_grid();
  bad.A_z[3] = std::nan("");
  EXPECT_TRUE(contains(error_of([&] { write_magnetic_grid(path, bad, some_provenance()); }),
                       "non-finite value"));
  EXPECT_EQ(fs::file_size(path), before);
  EXPECT_NO_THROW(read_magnetic_grid(path));
  GridProvenance bad_key = some_provenance();
  bad_key.case_inputs.emplace_back("a=b", "1");
  EXPECT_TRUE(contains(error_of([&] { write_magnetic_grid(path, some_polar_grid(), bad_key); }),
                       "cannot be stored"));
  EXPECT_FALSE(fs::exists(path.string() + ".tmp"));
  EXPECT_NO_THROW(read_magnetic_grid(path));
  fs::remove_all(dir);
}

TEST(FieldGridFile, WriterRejectsMalformedGrids)
{
  const fs::path path = scratch_dir() / "f.h5";
  PolarGrid g = some_polar_grid();
  g.A_z.pop_back();
  EXPECT_TRUE(contains(error_of([&] { write_magnetic_grid(path, g, {}); }),
                       "A_z has 167 values but n_r × n_theta = 168"));
  g = some_polar_grid();
  g.r_min = 0.0;
  EXPECT_TRUE(contains(error_of([&] { write_magnetic_grid(path, g, {}); }), "0 < r_min < r_max"));
  CartesianGrid c = some_cartesian_grid();
  c.n_y = 3;
  EXPECT_TRUE(contains(error_of([&] { write_electric_grid(path, some_nip_grid(c), {}); }), "n_y ≥ 4"));
  NipPotentialGrid nip = some_nip_grid(some_cartesian_grid());
  nip.image[1].pop_back();
  EXPECT_TRUE(contains(error_of([&] { write_electric_grid(path, nip, {}); }),
                       "image phase sample 1 has 29 values but n_x × n_y = 30"));
  nip = some_nip_grid(some_cartesian_grid());
  nip.image_period = 0.0;
  EXPECT_TRUE(contains(error_of([&] { write_electric_grid(path, nip, {}); }),
                       "a uniform image (period 0) has exactly one phase sample, found 3"));
  EXPECT_FALSE(fs::exists(path));
}

TEST(FieldGridLayout, PolarGridFromTheCaseSettings)
{
  Case c;
  c.source_file = "test.yaml";
  EXPECT_THROW(polar_grid_layout(c), FieldGridError);
  c.sleeve = Sleeve{};
  c.sleeve->radius = 12.5e-3;
  const PolarGridLayout l = polar_grid_layout(c); // defaults: 50 µm, 0.25°, sleeve + 3 mm
  EXPECT_EQ(l.r_min, 12.5e-3);
  EXPECT_DOUBLE_EQ(l.r_max, 15.5e-3);
  EXPECT_EQ(l.n_r, 61);
  EXPECT_EQ(l.n_theta, 1440);
  c.field.grid_outer_radius = 12.0e-3;
  EXPECT_THROW(polar_grid_layout(c), FieldGridError);
}

namespace {
std::vector<double> read_dataset(const fs::path &path, const char *name, std::string &units)
{
  H5File f(path);
  hid_t set = H5Dopen2(f.id, name, H5P_DEFAULT);
  EXPECT_GE(set, 0) << name;
  hid_t space = H5Dget_space(set);
  std::vector<double> v(static_cast<size_t>(H5Sget_simple_extent_npoints(space)));
  H5Dread(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
  hid_t attr = H5Aopen(set, "units", H5P_DEFAULT);
  hid_t type = H5Aget_type(attr);
  units.assign(H5Tget_size(type), '\0');
  H5Aread(attr, type, units.data());
  units = units.substr(0, units.find('\0'));
  H5Tclose(type);
  H5Aclose(attr);
  H5Sclose(space);
  H5Dclose(set);
  return v;
}
} // namespace

// B_r, B_θ (and E_x, E_y) at the nodes, stored for inspection: the field at the nodes.
TEST(FieldGridFile, InspectionDatasetsHoldTheFieldAtTheNodes)
{
  const fs::path dir = scratch_dir();
  const magbrush::testing::MultipoleField f(4e-3, 11.5e-3, {{3, 150e3, 0.2}, {5, -90e3, 1.0}});
  const PolarGrid g = sample_polar_grid(12.5e-3, 16e-3, 36, 360,
                                        [&](double x, double y) { return f.A(x, y); });
  write_magnetic_grid(dir / "m.h5", g, {});
  std::string units_r, units_t;
  const auto B_r = read_dataset(dir / "m.h5", "/polar/B_r", units_r);
  const auto B_t = read_dataset(dir / "m.h5", "/polar/B_theta", units_t);
  EXPECT_EQ(units_r, "T");
  EXPECT_EQ(units_t, "T");
  double err = 0, scale = 0;
  for (int i = 0; i < g.n_r; ++i)
    for (int j = 0; j < g.n_theta; ++j)
    {
      const double c = std::cos(g.theta(j)), s = std::sin(g.theta(j));
      const auto e = f.B(g.r(i) * c, g.r(i) * s);
      const double er = e.B[0] * c + e.B[1] * s, et = -e.B[0] * s + e.B[1] * c;
      const size_t k = static_cast<size_t>(i) * g.n_theta + j;
      err = std::max({err, std::abs(B_r[k] - er), std::abs(B_t[k] - et)});
      scale = std::max(scale, std::hypot(er, et));
    }
  EXPECT_LT(err, 1e-4 * scale);
  EXPECT_NO_THROW(read_magnetic_grid(dir / "m.h5"));

  // Φ = x y + x²: a quadratic, reproduced exactly by the not-a-knot spline; E = −(y + 2x, x).
  const CartesianGrid c = sample_cartesian_grid(-1e-3, 1e-3, 9, 0.0, 5e-4, 6,
                                                [](double x, double y) { return 1e6 * (x * y + x * x); });
  NipPotentialGrid nip = some_nip_grid(c, 1);
  for (auto &v : nip.image[0])
    v = 0.0;
  write_electric_grid(dir / "e.h5", nip, {});
  std::string ux, uy;
  const auto E_x = read_dataset(dir / "e.h5", "/cartesian/E_x", ux);
  const auto E_y = read_dataset(dir / "e.h5", "/cartesian/E_y", uy);
  EXPECT_EQ(ux, "V/m");
  EXPECT_EQ(uy, "V/m");
  for (int i = 0; i < c.n_x; ++i)
    for (int j = 0; j < c.n_y; ++j)
    {
      const size_t k = static_cast<size_t>(i) * c.n_y + j;
      EXPECT_NEAR(E_x[k], -1e6 * (c.y(j) + 2 * c.x(i)), 1e-6);
      EXPECT_NEAR(E_y[k], -1e6 * c.x(i), 1e-6);
    }
}

// The provenance of a case: its hash and inputs (case_hash.h), mesh sizes, degree; moving a
// pole makes the stored magnetic field stale and the mismatch names the pole's key.
TEST(FieldGridFile, CaseProvenanceDetectsAMovedPole)
{
  Case c;
  c.name = "t";
  c.source_file = "t.yaml";
  c.sleeve = Sleeve{};
  c.sleeve->radius = 12.5e-3;
  c.sleeve->thickness = 0.5e-3;
  c.roller = Roller{};
  c.roller->shaft_radius = 3e-3;
  c.roller->magnet_radius = 11e-3;
  c.roller->poles = {{"N1", 0.5, 150e3, 10.0}, {"S1", 2.0, -150e3, 10.0}};
  const GridProvenance p = case_provenance(c, FieldKind::magnetic);
  EXPECT_EQ(p.case_hash, field_hash(c, FieldKind::magnetic));
  EXPECT_EQ(p.case_inputs, field_inputs(c, FieldKind::magnetic));
  ASSERT_FALSE(p.case_inputs.empty());
  EXPECT_EQ(p.element_degree, c.field.element_degree);
  ASSERT_EQ(p.mesh_sizes.size(), 3u);
  EXPECT_EQ(p.mesh_sizes[1].second, c.field.mesh_size_sleeve);

  const fs::path path = scratch_dir() / "t_magnetic.h5";
  write_magnetic_grid(path, some_polar_grid(), p);
  const GridFileInfo info = read_grid_info(path);
  EXPECT_NO_THROW(check_provenance(info, case_provenance(c, FieldKind::magnetic).case_inputs));
  c.dem.time_step = 1e-8; // not a field input
  EXPECT_NO_THROW(check_provenance(info, case_provenance(c, FieldKind::magnetic).case_inputs));
  c.roller->poles[0].angle = 0.6;
  try
  {
    check_provenance(info, case_provenance(c, FieldKind::magnetic).case_inputs);
    FAIL() << "expected ProvenanceMismatch";
  }
  catch (const ProvenanceMismatch &e)
  {
    EXPECT_TRUE(contains(e.differing_key, "N1")) << e.differing_key;
    EXPECT_TRUE(contains(e.differing_key, "angle")) << e.differing_key;
  }
}

// Files touched by Python tools carry variable-length strings (h5py's default): accepted.
TEST(FieldGridFile, ReaderAcceptsVariableLengthStrings)
{
  const fs::path path = scratch_dir() / "f.h5";
  write_magnetic_grid(path, some_polar_grid(), some_provenance());
  {
    H5File f(path);
    const auto set_vl = [](hid_t obj, const char *name, const char *value) {
      H5Adelete(obj, name);
      hid_t type = H5Tcopy(H5T_C_S1);
      H5Tset_size(type, H5T_VARIABLE);
      H5Tset_cset(type, H5T_CSET_UTF8);
      hid_t space = H5Screate(H5S_SCALAR);
      hid_t attr = H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
      H5Awrite(attr, type, &value);
      H5Aclose(attr);
      H5Sclose(space);
      H5Tclose(type);
    };
    set_vl(f.id, "kind", "magnetic");
    set_vl(f.id, "case_hash", "from-python");
    hid_t set = H5Dopen2(f.id, "/polar/A_z", H5P_DEFAULT);
    set_vl(set, "units", "T*m");
    H5Dclose(set);
  }
  const MagneticGridFile in = read_magnetic_grid(path);
  EXPECT_EQ(in.info.provenance.case_hash, "from-python");
  EXPECT_EQ(in.grid.A_z, some_polar_grid().A_z);
}
