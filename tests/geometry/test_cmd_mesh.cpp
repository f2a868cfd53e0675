// `magbrush mesh` end to end on the repository's case files (coarse sizes through --set):
// the files are written where asked and read back (every named region and boundary has
// elements of its dimension, every element's nodes exist), the table is printed, bad input
// gives the documented codes.
#include <gtest/gtest.h>
#include "tests/test_temp_dir.h"

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

namespace fs = std::filesystem;

namespace {
struct Result
{
  int status;
  std::string output;
};

Result run(const std::string &arguments)
{
  const std::string command = std::string(MAGBRUSH_BINARY_DIR) + "/bin/magbrush mesh " + arguments + " 2>&1";
  Result r{0, ""};
  FILE *pipe = ::popen(command.c_str(), "r");
  std::array<char, 4096> buffer;
  while (std::fgets(buffer.data(), buffer.size(), pipe))
    r.output += buffer.data();
  const int status = ::pclose(pipe);
  r.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// An output directory that the command creates, inside this process's own scratch directory.
std::string scratch(const std::string &name)
{
  return (magbrush::testing::test_temp_dir("cmd_mesh_" + name) / "out").string();
}

// What a Gmsh 2.2 ASCII file holds: its physical groups by name (dimension and element count)
// and whether every element refers to existing nodes.
struct MshContent
{
  std::string version;
  std::size_t nodes = 0, elements = 0, dangling = 0;
  std::map<std::string, std::pair<int, std::size_t>> groups; // name -> (dim, elements)
};

// Dimension of a Gmsh element type (points, lines, surface elements of order 1 and 2).
int element_dimension(long type)
{
  switch (type)
  {
    case 15: return 0;
    case 1: case 8: case 26: case 27: case 28: return 1;
    default: return 2;
  }
}

MshContent read_msh(const std::string &path)
{
  MshContent m;
  std::ifstream in(path);
  std::map<std::pair<int, int>, std::string> names; // (dim, tag): tags are per dimension
  std::set<long> node_ids;
  std::string line;
  while (std::getline(in, line))
  {
    if (line == "$MeshFormat")
    {
      std::getline(in, line);
      m.version = line.substr(0, line.find(' '));
    }
    else if (line == "$PhysicalNames")
    {
      int n = 0;
      in >> n;
      for (int k = 0; k < n; ++k)
      {
        int dim = 0, tag = 0;
        std::string name;
        in >> dim >> tag >> name;
        names[{dim, tag}] = name.substr(1, name.size() - 2); // drop the quotes
        m.groups[names[{dim, tag}]] = {dim, 0};
      }
    }
    else if (line == "$Nodes")
    {
      in >> m.nodes;
      for (std::size_t k = 0; k < m.nodes; ++k)
      {
        long id = 0;
        double x, y, z;
        in >> id >> x >> y >> z;
        node_ids.insert(id);
      }
    }
    else if (line == "$Elements")
    {
      in >> m.elements;
      std::getline(in, line);
      for (std::size_t k = 0; k < m.elements && std::getline(in, line); ++k)
      {
        std::istringstream e(line);
        long id = 0, type = 0, n_tags = 0, physical = 0, tag = 0, node = 0;
        e >> id >> type >> n_tags >> physical;
        for (long t = 1; t < n_tags; ++t)
          e >> tag;
        while (e >> node)
          m.dangling += node_ids.count(node) == 0;
        const std::pair<int, int> key{element_dimension(type), static_cast<int>(physical)};
        if (names.count(key))
          ++m.groups[names[key]].second;
      }
    }
  }
  return m;
}

// The file is a mesh with elements in each named group, regions (dim 2) and boundaries (dim 1).
void expect_mesh(const std::string &path, const std::vector<std::string> &regions,
                 const std::vector<std::string> &boundaries)
{
  ASSERT_TRUE(fs::exists(path)) << path;
  const MshContent m = read_msh(path);
  EXPECT_EQ(m.version, "2.2") << path;
  EXPECT_GT(m.nodes, 100u) << path;
  EXPECT_GT(m.elements, 100u) << path;
  EXPECT_EQ(m.dangling, 0u) << path << ": elements refer to nodes that are not in the file";
  for (const auto &[names, dim] : {std::pair{regions, 2}, std::pair{boundaries, 1}})
    for (const auto &name : names)
    {
      const auto g = m.groups.find(name);
      ASSERT_NE(g, m.groups.end()) << path << " has no physical group '" << name << "'";
      EXPECT_EQ(g->second.first, dim) << path << ": " << name;
      EXPECT_GT(g->second.second, 0u) << path << ": no elements in " << name;
    }
}

const std::string cases = std::string(MAGBRUSH_SOURCE_DIR) + "/cases/";
const std::string coarse = " --set field.mesh_size_sleeve=0.5mm --set field.mesh_size_gap=60um --set field.mesh_size_far=4mm";
} // namespace

TEST(MeshCommand, WritesBothMeshesOfTheFullRoller)
{
  const std::string dir = scratch("cmd_kweon");
  const Result r = run(cases + "kweon_full_roller.yaml" + coarse + " -o " + dir);
  EXPECT_EQ(r.status, 0) << r.output;
  expect_mesh(dir + "/roller.msh", {"shaft", "magnet", "sleeve_wall", "air", "shell"}, {"outer_boundary"});
  expect_mesh(dir + "/nip.msh", {"air", "photoconductor", "shell"},
              {"outer_boundary", "sleeve_surface", "drum_substrate"});
  for (const char *name : {"shaft", "magnet", "sleeve_wall", "air", "shell", "photoconductor", "sleeve_surface",
                           "drum_substrate", "outer_boundary"})
    EXPECT_NE(r.output.find(name), std::string::npos) << name << "\n" << r.output;
  EXPECT_EQ(r.output.find("WARNING"), std::string::npos) << "Gmsh chatter leaked:\n" << r.output;
}

TEST(MeshCommand, OnlyTheNipOfKawamoto)
{
  const std::string dir = scratch("cmd_kawamoto");
  const Result r = run(cases + "kawamoto_nip.yaml" + coarse + " --only nip -o " + dir);
  EXPECT_EQ(r.status, 0) << r.output;
  expect_mesh(dir + "/nip.msh", {"air", "shell"}, {"outer_boundary", "sleeve_surface", "drum_substrate"});
  EXPECT_FALSE(fs::exists(dir + "/roller.msh"));
}

TEST(MeshCommand, ErrorsAndHelp)
{
  EXPECT_EQ(run("--help").status, 0);
  EXPECT_EQ(run("").status, 2);
  EXPECT_EQ(run(cases + "kweon_full_roller.yaml --only drum").status, 2);
  const Result box = run(cases + "kawamoto_brush_compression.yaml -o " + scratch("cmd_box"));
  EXPECT_EQ(box.status, 1);
  EXPECT_NE(box.output.find("nothing to mesh"), std::string::npos) << box.output;
  const Result bad = run(cases + "kweon_full_roller.yaml --set drum.gap=-1mm -o " + scratch("cmd_bad"));
  EXPECT_EQ(bad.status, 1) << bad.output;
}

// A mesh whose inputs did not change is not rewritten, and the output says so; a changed
// field input, or --force, remeshes. (Meshing the full roller takes ~10 s at the defaults.)
TEST(MeshCommand, UnchangedInputsAreNotRemeshed)
{
  const std::string dir = scratch("cmd_reuse");
  const std::string args = cases + "kawamoto_nip.yaml" + coarse + " --only nip -o " + dir;
  const Result first = run(args);
  ASSERT_EQ(first.status, 0) << first.output;
  EXPECT_NE(first.output.find("nip mesh (no mesh yet)"), std::string::npos) << first.output;
  const auto written = fs::last_write_time(dir + "/nip.msh");

  const Result again = run(args);
  ASSERT_EQ(again.status, 0) << again.output;
  EXPECT_NE(again.output.find("nip mesh: up to date"), std::string::npos) << again.output;
  EXPECT_EQ(fs::last_write_time(dir + "/nip.msh"), written);

  // The run-control keys change no mesh.
  const Result longer = run(args + " --set dem.duration=30ms");
  EXPECT_NE(longer.output.find("nip mesh: up to date"), std::string::npos) << longer.output;

  const Result gap = run(args + " --set drum.gap=0.45mm");
  ASSERT_EQ(gap.status, 0) << gap.output;
  EXPECT_NE(gap.output.find("its inputs changed"), std::string::npos) << gap.output;
  expect_mesh(dir + "/nip.msh", {"air", "shell"}, {"outer_boundary", "sleeve_surface", "drum_substrate"});

  const Result forced = run(args + " --set drum.gap=0.45mm --force");
  EXPECT_NE(forced.output.find("nip mesh (--force)"), std::string::npos) << forced.output;
}
