#include "dem/vtu_snapshot_writer.h"

#include "common/atomic_file.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <regex>
#include <sstream>

namespace magbrush::dem {

namespace fs = std::filesystem;

VtuSnapshotWriter::VtuSnapshotWriter(const std::string &directory) : directory_(directory)
{
  fs::create_directories(fs::path(directory_) / "snapshots");
}

void VtuSnapshotWriter::write(const DemSystem &system)
{
  const ParticleState &s = system.particles();
  const ForceBuffers &f = system.forces();
  const std::vector<std::int32_t> &contacts = system.contact_count();
  const std::size_t n = s.size();
  std::vector<std::size_t> order(n); // particles in id order
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return s.id[a] < s.id[b]; });

  std::ostringstream o;
  o.precision(9);
  auto vectors = [&](const char *name, const std::vector<double> &a, const std::vector<double> &b,
                     const std::vector<double> &c) {
    o << "<DataArray type=\"Float64\" Name=\"" << name << "\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    for (std::size_t i : order)
      o << a[i] << ' ' << b[i] << ' ' << c[i] << '\n';
    o << "</DataArray>\n";
  };
  auto scalars = [&](const char *name, const char *type, const auto &a) {
    o << "<DataArray type=\"" << type << "\" Name=\"" << name << "\" format=\"ascii\">\n";
    for (std::size_t i : order)
      o << a[i] << '\n';
    o << "</DataArray>\n";
  };
  o << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\">\n"
    << "<UnstructuredGrid>\n<FieldData><DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" "
       "format=\"ascii\">"
    << system.time() << "</DataArray></FieldData>\n"
    << "<Piece NumberOfPoints=\"" << n << "\" NumberOfCells=\"" << n << "\">\n<Points>\n";
  vectors("position", s.x, s.y, s.z);
  o << "</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (std::size_t k = 0; k < n; ++k)
    o << k << '\n';
  o << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (std::size_t k = 0; k < n; ++k)
    o << k + 1 << '\n';
  o << "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n"; // 1 = VTK_VERTEX
  for (std::size_t k = 0; k < n; ++k)
    o << "1\n";
  o << "</DataArray>\n</Cells>\n<PointData Scalars=\"radius\" Vectors=\"velocity\">\n";
  vectors("velocity", s.vx, s.vy, s.vz);
  vectors("angular_velocity", s.wx, s.wy, s.wz);
  vectors("force", f.fx, f.fy, f.fz);
  scalars("radius", "Float64", s.radius);
  scalars("charge", "Float64", s.charge);
  scalars("species", "Int32", s.species);
  scalars("id", "Int32", s.id);
  scalars("contact_count", "Int32", contacts);
  o << "</PointData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";

  char name[64];
  std::snprintf(name, sizeof name, "snapshots/particles_%08ld.vtu", system.step_count());
  write_text_atomically((fs::path(directory_) / name).string(), o.str());
  snapshots_.emplace_back(system.time(), name);
  write_collection();
}

void VtuSnapshotWriter::resume(double up_to_time)
{
  snapshots_.clear();
  std::ifstream in(fs::path(directory_) / "particles.pvd");
  const std::regex entry(R"re(<DataSet timestep="([^"]+)"[^>]*file="([^"]+)")re");
  std::string line;
  while (std::getline(in, line))
  {
    std::smatch m;
    if (std::regex_search(line, m, entry))
    {
      const double t = std::stod(m[1]);
      if (t <= up_to_time * (1.0 + 1e-12) && fs::exists(fs::path(directory_) / m[2].str()))
        snapshots_.emplace_back(t, m[2]);
    }
  }
}

void VtuSnapshotWriter::write_collection() const
{
  std::ostringstream x;
  x << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"1.0\">\n<Collection>\n";
  for (const auto &[t, file] : snapshots_)
  {
    char tbuf[32];
    std::snprintf(tbuf, sizeof tbuf, "%.9g", t);
    x << "<DataSet timestep=\"" << tbuf << "\" part=\"0\" file=\"" << file << "\"/>\n";
  }
  x << "</Collection>\n</VTKFile>\n";
  write_text_atomically((fs::path(directory_) / "particles.pvd").string(), x.str());
}

} // namespace magbrush::dem
