// HDF5/XDMF snapshots and the CSV time series (see snapshot_writer.h).
#include "dem/snapshot_writer.h"

#include "common/atomic_file.h"

#include <hdf5.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace magbrush::dem {

namespace fs = std::filesystem;

void write_file_atomically(const std::string &path, const std::string &text)
{
  write_text_atomically(path, text);
}

namespace {
// Minimal RAII around an HDF5 file being written.
class H5File
{
public:
  explicit H5File(const std::string &path)
  {
    // The 1.8 object-header format checksums the metadata (time, step) as the filter below
    // does the data.
    const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    H5Pset_libver_bounds(fapl, H5F_LIBVER_V18, H5F_LIBVER_LATEST);
    id_ = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
    H5Pclose(fapl);
    if (id_ < 0)
      throw std::runtime_error("HDF5: cannot create '" + path + "'");
  }
  ~H5File() { H5Fclose(id_); }
  H5File(const H5File &) = delete;
  H5File &operator=(const H5File &) = delete;

  // Chunked (whole rows, at most about 1 MiB a chunk) with HDF5's Fletcher-32 checksum filter:
  // a value damaged on disk fails the read (ParaView, h5py, the report) instead of showing.
  template <typename T>
  void dataset(const char *name, const std::vector<T> &data, hsize_t rows, hsize_t cols)
  {
    const hsize_t dims[2] = {rows, cols};
    const int rank = cols > 1 ? 2 : 1;
    const hid_t space = H5Screate_simple(rank, dims, nullptr);
    const hid_t type = std::is_same<T, double>::value ? H5T_NATIVE_DOUBLE : H5T_NATIVE_INT32;
    const hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
    if (rows > 0)
    {
      const hsize_t chunk[2] = {std::max<hsize_t>(1, std::min<hsize_t>(rows, (hsize_t{1} << 20) / (8 * cols))), cols};
      H5Pset_chunk(dcpl, rank, chunk);
      H5Pset_fletcher32(dcpl);
    }
    const hid_t set = H5Dcreate2(id_, name, type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    H5Pclose(dcpl);
    if (set < 0 || H5Dwrite(set, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()) < 0)
      throw std::runtime_error(std::string("HDF5: cannot write dataset ") + name);
    H5Dclose(set);
    H5Sclose(space);
  }
  void attribute(const char *name, double value)
  {
    const hid_t space = H5Screate(H5S_SCALAR);
    const hid_t a = H5Acreate2(id_, name, H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(a, H5T_NATIVE_DOUBLE, &value);
    H5Aclose(a);
    H5Sclose(space);
  }

private:
  hid_t id_;
};
} // namespace

SnapshotWriter::SnapshotWriter(const std::string &directory) : directory_(directory)
{
  fs::create_directories(fs::path(directory_) / "snapshots");
}

void SnapshotWriter::write(const DemSystem &system)
{
  const ParticleState &s = system.particles();
  const ForceBuffers &f = system.forces();
  const std::size_t n = s.size();
  particles_ = n;
  // The particles in ascending id (ids are unique, not dense once particles enter and leave).
  std::vector<std::size_t> where(n);
  for (std::size_t i = 0; i < n; ++i)
    where[i] = i;
  std::sort(where.begin(), where.end(), [&s](std::size_t a, std::size_t b) { return s.id[a] < s.id[b]; });
  auto vec3 = [&](const std::vector<double> &a, const std::vector<double> &b, const std::vector<double> &c) {
    std::vector<double> out(3 * n);
    for (std::size_t k = 0; k < n; ++k)
    {
      const std::size_t i = where[k];
      out[3 * k] = a[i];
      out[3 * k + 1] = b[i];
      out[3 * k + 2] = c[i];
    }
    return out;
  };
  auto scalar = [&](const auto &a) {
    std::vector<typename std::decay_t<decltype(a)>::value_type> out(n);
    for (std::size_t k = 0; k < n; ++k)
      out[k] = a[where[k]];
    return out;
  };
  char name[64];
  std::snprintf(name, sizeof name, "snapshots/particles_%08ld.h5", system.step_count());
  const std::string path = (fs::path(directory_) / name).string();
  AtomicFile file(path);
  {
    H5File h5(file.temp_path());
    h5.attribute("time", system.time());
    h5.attribute("step", static_cast<double>(system.step_count()));
    h5.dataset("position", vec3(s.x, s.y, s.z), n, 3);
    h5.dataset("velocity", vec3(s.vx, s.vy, s.vz), n, 3);
    h5.dataset("angular_velocity", vec3(s.wx, s.wy, s.wz), n, 3);
    h5.dataset("force", vec3(f.fx, f.fy, f.fz), n, 3);
    h5.dataset("radius", scalar(s.radius), n, 1);
    h5.dataset("charge", scalar(s.charge), n, 1);
    h5.dataset("species", scalar(s.species), n, 1);
    h5.dataset("id", scalar(s.id), n, 1);
    h5.dataset("contact_count", scalar(system.contact_count()), n, 1);
  }
  file.commit();
  snapshots_.emplace_back(system.time(), name);
  counts_.push_back(n); // particles may enter and leave: each snapshot has its own count
  write_index();
}

void SnapshotWriter::resume(double up_to_time)
{
  // Rebuild the list from the files present, keeping those not later than the restart time.
  snapshots_.clear();
  counts_.clear();
  const fs::path dir = fs::path(directory_) / "snapshots";
  std::vector<std::string> files;
  for (const auto &e : fs::directory_iterator(dir))
    if (e.path().extension() == ".h5")
      files.push_back(e.path().filename().string());
  std::sort(files.begin(), files.end());
  for (const auto &f : files)
  {
    const std::string path = (dir / f).string();
    const hid_t id = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    if (id < 0)
      continue;
    double t = 0.0;
    const hid_t a = H5Aopen(id, "time", H5P_DEFAULT);
    if (a >= 0)
    {
      H5Aread(a, H5T_NATIVE_DOUBLE, &t);
      H5Aclose(a);
    }
    hsize_t dims[2] = {0, 0};
    const hid_t set = H5Dopen2(id, "radius", H5P_DEFAULT);
    if (set >= 0)
    {
      const hid_t space = H5Dget_space(set);
      H5Sget_simple_extent_dims(space, dims, nullptr);
      H5Sclose(space);
      H5Dclose(set);
    }
    H5Fclose(id);
    if (t <= up_to_time * (1.0 + 1e-12))
    {
      snapshots_.emplace_back(t, "snapshots/" + f);
      particles_ = static_cast<std::size_t>(dims[0]);
      counts_.push_back(particles_);
    }
  }
}

void SnapshotWriter::write_index() const
{
  std::ostringstream x;
  x << "<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n<Xdmf Version=\"3.0\">\n<Domain>\n"
    << "<Grid Name=\"particles\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (std::size_t k = 0; k < snapshots_.size(); ++k)
  {
    const auto &[t, file] = snapshots_[k];
    const std::size_t n = counts_[k];
    char tbuf[32];
    std::snprintf(tbuf, sizeof tbuf, "%.9g", t);
    x << "  <Grid Name=\"t=" << tbuf << "\" GridType=\"Uniform\">\n"
      << "    <Time Value=\"" << tbuf << "\"/>\n"
      << "    <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"" << n << "\" NodesPerElement=\"1\"/>\n"
      << "    <Geometry GeometryType=\"XYZ\"><DataItem Dimensions=\"" << n
      << " 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << file << ":/position</DataItem></Geometry>\n";
    auto attr = [&](const char *name, const char *type, int cols, const char *number, int precision) {
      x << "    <Attribute Name=\"" << name << "\" AttributeType=\"" << type << "\" Center=\"Node\"><DataItem Dimensions=\""
        << n << (cols > 1 ? " 3" : "") << "\" NumberType=\"" << number << "\" Precision=\"" << precision
        << "\" Format=\"HDF\">" << file << ":/" << name << "</DataItem></Attribute>\n";
    };
    attr("velocity", "Vector", 3, "Float", 8);
    attr("angular_velocity", "Vector", 3, "Float", 8);
    attr("force", "Vector", 3, "Float", 8);
    attr("radius", "Scalar", 1, "Float", 8);
    attr("charge", "Scalar", 1, "Float", 8);
    attr("species", "Scalar", 1, "Int", 4);
    attr("id", "Scalar", 1, "Int", 4);
    attr("contact_count", "Scalar", 1, "Int", 4);
    x << "  </Grid>\n";
  }
  x << "</Grid>\n</Domain>\n</Xdmf>\n";
  write_file_atomically((fs::path(directory_) / "particles.xdmf").string(), x.str());
}

TimeSeriesWriter::TimeSeriesWriter(const std::string &path, const DemSystem &system) : path_(path)
{
  header_ = "step,time,kinetic_energy,rotational_energy,particle_contacts,wall_contacts";
  for (std::size_t w = 0; w < system.walls().size(); ++w)
  {
    const std::string &n = system.walls().name(w);
    header_ += "," + n + "_Fx," + n + "_Fy," + n + "_Fz," + n + "_Tz";
  }
}

void TimeSeriesWriter::record(const DemSystem &system)
{
  const auto loads = system.wall_loads();
  long wall_contacts = 0;
  for (const auto &l : loads)
    wall_contacts += l.contacts;
  char buf[256];
  std::snprintf(buf, sizeof buf, "%ld,%.9g,%.9g,%.9g,%ld,%ld", system.step_count(), system.time(),
                system.kinetic_energy(), system.rotational_energy(), system.particle_contacts(), wall_contacts);
  std::string row = buf;
  for (const auto &l : loads)
  {
    std::snprintf(buf, sizeof buf, ",%.9g,%.9g,%.9g,%.9g", l.force[0], l.force[1], l.force[2], l.torque[2]);
    row += buf;
  }
  rows_.emplace_back(system.step_count(), row);
  flush();
}

void TimeSeriesWriter::resume(long step)
{
  rows_.clear();
  std::ifstream in(path_);
  std::string line;
  std::getline(in, line); // header
  while (std::getline(in, line))
  {
    const long s = std::stol(line.substr(0, line.find(',')));
    if (s <= step)
      rows_.emplace_back(s, line);
  }
}

void TimeSeriesWriter::flush() const
{
  std::string text = header_ + "\n";
  for (const auto &r : rows_)
    text += r.second + "\n";
  write_file_atomically(path_, text);
}

} // namespace magbrush::dem
