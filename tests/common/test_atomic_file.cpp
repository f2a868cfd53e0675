// common/atomic_file.h: a commit replaces the file; a failure before it leaves the old file
// byte for byte and no temporary file behind.
#include "common/atomic_file.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace {

namespace fs = std::filesystem;
using magbrush::AtomicFile;
using magbrush::AtomicFileError;
using namespace std::string_literals;

class AtomicFileTest : public ::testing::Test
{
protected:
  fs::path dir = fs::temp_directory_path() / ("magbrush_atomic_file_" + std::to_string(::getpid()));
  fs::path target = dir / "result.csv";
  const std::string old_text = "old,content\n1,2\n\0binary\xff"s;

  void SetUp() override
  {
    fs::remove_all(dir);
    fs::create_directories(dir);
    std::ofstream(target, std::ios::binary) << old_text;
  }
  void TearDown() override { fs::remove_all(dir); }

  static std::string read(const fs::path &path)
  {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
  }
  // Only the target is left in the folder: no temporary file.
  std::vector<std::string> files() const
  {
    std::vector<std::string> names;
    for (const auto &e : fs::directory_iterator(dir))
      names.push_back(e.path().filename().string());
    return names;
  }
};

TEST_F(AtomicFileTest, WriteReplacesTheFile)
{
  magbrush::write_file_atomically(target.string(), [](std::ostream &out) { out << "new\n"; });
  EXPECT_EQ(read(target), "new\n");
  EXPECT_EQ(files(), std::vector<std::string>{"result.csv"});
  magbrush::write_text_atomically((dir / "fresh.txt").string(), "text");
  EXPECT_EQ(read(dir / "fresh.txt"), "text");
}

TEST_F(AtomicFileTest, AnExceptionLeavesTheOldFileByteIdentical)
{
  EXPECT_THROW(magbrush::write_file_atomically(target.string(),
                                               [](std::ostream &out) {
                                                 out << "half a file";
                                                 throw std::runtime_error("disk on fire");
                                               }),
               std::runtime_error);
  EXPECT_EQ(read(target), old_text);
  EXPECT_EQ(files(), std::vector<std::string>{"result.csv"});
}

TEST_F(AtomicFileTest, TheTemporaryFileIsHiddenNextToTheTarget)
{
  AtomicFile file(target.string());
  EXPECT_EQ(fs::path(file.temp_path()).parent_path(), dir);
  EXPECT_EQ(fs::path(file.temp_path()).filename().string().rfind(".result.csv.tmp-", 0), 0u) << file.temp_path();
  AtomicFile other(target.string());
  EXPECT_NE(file.temp_path(), other.temp_path());
  AtomicFile mesh((dir / "roller.msh").string(), AtomicFile::Extension::kept);
  EXPECT_EQ(fs::path(mesh.temp_path()).extension(), ".msh");
}

TEST_F(AtomicFileTest, CommitReplacesAndUncommittedIsRemoved)
{
  {
    AtomicFile file(target.string());
    std::ofstream(file.temp_path()) << "binary writer output";
    file.commit();
    EXPECT_EQ(file.path(), target.string());
  }
  EXPECT_EQ(read(target), "binary writer output");
  {
    AtomicFile file(target.string());
    std::ofstream(file.temp_path()) << "never committed";
  }
  EXPECT_EQ(read(target), "binary writer output");
  EXPECT_EQ(files(), std::vector<std::string>{"result.csv"});
}

TEST_F(AtomicFileTest, FailuresNameThePath)
{
  const std::string nowhere = (dir / "no_such_folder" / "x.csv").string();
  try
  {
    magbrush::write_text_atomically(nowhere, "x");
    FAIL() << "no error";
  }
  catch (const AtomicFileError &e)
  {
    EXPECT_NE(std::string(e.what()).find("cannot write '" + nowhere + "'"), std::string::npos) << e.what();
  }
  // A folder in the way: the rename fails, the folder stays, no temporary file is left.
  fs::create_directories(dir / "occupied" / "inside");
  try
  {
    magbrush::write_text_atomically((dir / "occupied").string(), "x");
    FAIL() << "no error";
  }
  catch (const AtomicFileError &e)
  {
    EXPECT_NE(std::string(e.what()).find((dir / "occupied").string()), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::is_directory(dir / "occupied" / "inside"));
  auto names = files();
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"occupied", "result.csv"}));
}

} // namespace
