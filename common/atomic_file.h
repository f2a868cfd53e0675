// Writing an output file so that nobody ever sees half of it.
//
// A reader (ParaView, the next stage, a restart) must find either the old file or the
// complete new one, never a file cut short by a crash, a full disk or an exception. So every
// output is written to a temporary file in the same folder and renamed onto its name only
// when complete: a rename within one file system replaces the file in one step.
//
// For text, hand over what writes it:
//
//   write_file_atomically("dem/time_series.csv", [&](std::ostream &out) { out << table; });
//
// For a library that wants a file name (HDF5, Gmsh, a binary writer), hold an AtomicFile:
//
//   AtomicFile file("fields/roller.h5");
//   write_hdf5(file.temp_path());   // may throw: the destructor removes the temporary file
//   file.commit();                  // now fields/roller.h5 is the new file
#pragma once

#include <functional>
#include <ostream>
#include <stdexcept>
#include <string>

namespace magbrush {

// A file could not be written or put in place; the message names the final path.
class AtomicFileError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

class AtomicFile
{
public:
  // Whether the temporary name ends in the final name's extension, for writers that choose
  // the format from it (Gmsh: ".msh").
  enum class Extension { dropped, kept };

  // Chooses the temporary name, next to `path`: ".<name>.tmp-<pid>-<n>", hidden and unique
  // per process and file. Creates nothing yet.
  explicit AtomicFile(std::string path, Extension extension = Extension::dropped);
  // Removes the temporary file unless commit() has put it in place.
  ~AtomicFile();
  AtomicFile(const AtomicFile &) = delete;
  AtomicFile &operator=(const AtomicFile &) = delete;

  const std::string &path() const { return path_; }
  const std::string &temp_path() const { return temp_path_; }

  // Renames the temporary file onto path(). Throws AtomicFileError (naming both) on failure;
  // the temporary file is then removed and the old file stays as it was.
  void commit();

private:
  std::string path_;
  std::string temp_path_;
  bool committed_ = false;
};

// Writes a file through `write` and puts it in place only when `write` returned and the
// stream is still good. Anything `write` throws passes through, with the old file intact.
void write_file_atomically(const std::string &path, const std::function<void(std::ostream &)> &write);

// The same for a text that is already complete.
void write_text_atomically(const std::string &path, const std::string &text);

} // namespace magbrush
