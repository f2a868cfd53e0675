// The DEM checkpoint's file format: a flat binary file
//
//   "MBDEMCK6"                        8-byte magic (3: force-term state; 4: case identity
//                                     and checksum; 5: toner carried by the carriers;
//                                     6: the forces of the subcycled contacts)
//   case identity                     the case hash and the resolved case inputs (key = value
//                                     lines) of the run that wrote it (CheckpointIdentity)
//   state                             scalars and length-prefixed arrays in the order the
//                                     writer puts them (the clock, the particles, the forces,
//                                     the neighbour list with its contact history, the
//                                     wall-contact slots, then each force term's name and
//                                     state: DemSystem::write_checkpoint)
//   trailer                           the length of everything above (8 bytes) and its
//                                     CRC-32 (zlib, 4 bytes)
//
// Native byte order: a checkpoint is for restarting on the machine (or the same architecture)
// that wrote it.
//
// The writer writes to a temporary file in the same folder and renames it over the target
// only when everything was written, so a crash never leaves half a checkpoint and the last
// good one survives. The reader checks the length and the checksum of the whole file BEFORE
// it hands out a single value: a file damaged on disk (one flipped bit) is refused with a
// message that names it and points to the checkpoint kept before it (keep_previous_checkpoint).
#pragma once

#include "common/atomic_file.h"
#include "common/state_stream.h"

#include <cstdint>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

namespace magbrush::dem {

// Which case wrote a checkpoint: its hash and its resolved inputs, one (key, value) per key
// (case/case_hash.h: case_inputs). Empty when the writer did not say (tests that drive
// the engine directly).
struct CheckpointIdentity
{
  std::string case_hash;
  std::vector<std::pair<std::string, std::string>> inputs;
};

class CheckpointWriter : public StateOut
{
public:
  // Opens the temporary file, writes the magic and the identity.
  explicit CheckpointWriter(const std::string &path, const CheckpointIdentity &identity = {});
  ~CheckpointWriter() override; // removes the temporary file unless committed

  void write_bytes(const void *data, std::size_t size) override;
  // Writes the trailer, closes the file and puts it in place of `path` (throws, naming the
  // file, on failure).
  void commit();

private:
  AtomicFile file_;   // the temporary file and its rename (common/atomic_file.h)
  std::ofstream out_; // declared after file_: closed before file_ removes an uncommitted file
  std::uint64_t length_ = 0;
  std::uint32_t crc_ = 0;
};

class CheckpointReader : public StateIn
{
public:
  // Opens the file, checks the magic, the length and the checksum, reads the identity.
  explicit CheckpointReader(const std::string &path);

  const CheckpointIdentity &identity() const { return identity_; }
  const std::string &path() const { return path_; }

  void read_bytes(void *data, std::size_t size) override;
  [[noreturn]] void fail(const std::string &what) const override;
  std::size_t remaining() const override { return static_cast<std::size_t>(length_ - position_); }

private:
  std::string path_;
  std::ifstream in_;
  std::uint64_t length_ = 0;   // bytes before the trailer
  std::uint64_t position_ = 0; // bytes read so far
  CheckpointIdentity identity_;

  void verify_checksum();
};

// The checkpoint kept before `path`: "<dir>/checkpoint.previous.bin" for "<dir>/checkpoint.bin".
std::string previous_checkpoint_path(const std::string &path);
// Keeps the checkpoint at `path` (if any) as previous_checkpoint_path(path) — a hard link
// renamed into place, so that `path` itself is never missing — before a new one replaces it.
void keep_previous_checkpoint(const std::string &path);

} // namespace magbrush::dem
