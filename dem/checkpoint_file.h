// The DEM checkpoint's file format: a flat binary file, the 8-byte magic "MBDEMCK3" (2: 32-bit
// pair flags; 3: force-term state), then scalars and length-prefixed arrays in the order the
// writer puts them (the clock, the particles, the forces, the neighbour list with its contact
// history, the wall-contact slots, then each force term's name and state:
// DemSystem::write_checkpoint). Native byte order: a checkpoint is for
// restarting on the machine (or the same architecture) that wrote it.
//
// The writer writes to a temporary file in the same folder and renames it over the target
// only when everything was written, so a crash never leaves half a checkpoint and the last
// good one survives. The reader names the file and what is wrong with it.
#pragma once

#include "common/atomic_file.h"

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

namespace magbrush::dem {

class CheckpointWriter
{
public:
  explicit CheckpointWriter(const std::string &path); // opens the temporary file, writes the magic
  ~CheckpointWriter();                                // removes the temporary file unless committed

  template <typename T>
  void put(const T &value)
  {
    out_.write(reinterpret_cast<const char *>(&value), sizeof(T));
  }
  template <typename T>
  void put_array(const std::vector<T> &values)
  {
    put<std::uint64_t>(values.size());
    out_.write(reinterpret_cast<const char *>(values.data()), static_cast<std::streamsize>(values.size() * sizeof(T)));
  }
  // Closes the file and puts it in place of `path` (throws, naming the file, on failure).
  void commit();

private:
  AtomicFile file_;   // the temporary file and its rename (common/atomic_file.h)
  std::ofstream out_; // declared after file_: closed before file_ removes an uncommitted file
};

class CheckpointReader
{
public:
  explicit CheckpointReader(const std::string &path); // opens the file, checks the magic

  template <typename T>
  T get()
  {
    T value{};
    in_.read(reinterpret_cast<char *>(&value), sizeof(T));
    if (!in_)
      fail("is truncated");
    return value;
  }
  template <typename T>
  void get_array(std::vector<T> &values)
  {
    const auto n = get<std::uint64_t>();
    if (n > (1ull << 34))
      fail("is corrupt (an array of " + std::to_string(n) + " elements)");
    values.resize(n);
    in_.read(reinterpret_cast<char *>(values.data()), static_cast<std::streamsize>(n * sizeof(T)));
    if (!in_)
      fail("is truncated");
  }
  const std::string &path() const { return path_; }
  [[noreturn]] void fail(const std::string &what) const;

private:
  std::string path_;
  std::ifstream in_;
};

} // namespace magbrush::dem
