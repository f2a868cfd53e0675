// AtomicFile and write_file_atomically(): a temporary file next to the final one, renamed
// onto it at the end (see atomic_file.h for why).
#include "common/atomic_file.h"

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <unistd.h>

namespace magbrush {

namespace fs = std::filesystem;

namespace {

// The process id tells two programs apart, the counter two files of one program (threads
// included), so that two writers of the same path never share a temporary file.
std::string unique_suffix()
{
  static std::atomic<unsigned long> counter{0};
  return ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
}

std::string temporary_name_for(const std::string &path, AtomicFile::Extension extension)
{
  const fs::path final_path(path);
  std::string name = "." + final_path.filename().string() + unique_suffix();
  if (extension == AtomicFile::Extension::kept)
    name += final_path.extension().string();
  return (final_path.parent_path() / name).string();
}

} // namespace

AtomicFile::AtomicFile(std::string path, Extension extension)
  : path_(std::move(path)), temp_path_(temporary_name_for(path_, extension))
{
}

AtomicFile::~AtomicFile()
{
  if (!committed_)
    std::remove(temp_path_.c_str()); // nothing to do when it was never created
}

void AtomicFile::commit()
{
  if (committed_)
    return;
  if (std::rename(temp_path_.c_str(), path_.c_str()) != 0)
  {
    const std::string why = std::strerror(errno);
    std::remove(temp_path_.c_str());
    throw AtomicFileError("cannot write '" + path_ + "': cannot rename the finished temporary file '" +
                          temp_path_ + "' onto it (" + why + "); is the path a folder, or the folder read-only?");
  }
  committed_ = true;
}

void write_file_atomically(const std::string &path, const std::function<void(std::ostream &)> &write)
{
  AtomicFile file(path);
  {
    std::ofstream out(file.temp_path(), std::ios::binary | std::ios::trunc);
    if (!out)
      throw AtomicFileError("cannot write '" + path + "': cannot create '" + file.temp_path() + "' (" +
                            std::strerror(errno) + "); does the folder exist and is it writable?");
    write(out);
    out.flush();
    if (!out)
      throw AtomicFileError("writing '" + path + "' failed (disk full?); the old file is unchanged");
  }
  file.commit();
}

void write_text_atomically(const std::string &path, const std::string &text)
{
  write_file_atomically(path, [&](std::ostream &out) { out << text; });
}

} // namespace magbrush
