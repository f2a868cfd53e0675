// `magbrush mesh` end to end on the repository's case files (coarse sizes through --set):
// the files appear where asked, the table is printed, bad input gives the documented codes.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>
#include <unistd.h>

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

std::string scratch(const std::string &name)
{
  const fs::path dir = fs::path(MAGBRUSH_BINARY_DIR) / "tests" / "scratch" / (name + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir.string();
}

const std::string cases = std::string(MAGBRUSH_SOURCE_DIR) + "/cases/";
const std::string coarse = " --set field.mesh_size_sleeve=0.5mm --set field.mesh_size_gap=60um --set field.mesh_size_far=4mm";
} // namespace

TEST(MeshCommand, WritesBothMeshesOfTheFullRoller)
{
  const std::string dir = scratch("cmd_kweon");
  const Result r = run(cases + "kweon_full_roller.yaml" + coarse + " -o " + dir);
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir + "/roller.msh"));
  EXPECT_TRUE(fs::exists(dir + "/nip.msh"));
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
  EXPECT_TRUE(fs::exists(dir + "/nip.msh"));
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
