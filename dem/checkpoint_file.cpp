#include "dem/checkpoint_file.h"

#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace magbrush::dem {

namespace {
constexpr char checkpoint_magic[9] = "MBDEMCK3";
}

CheckpointWriter::CheckpointWriter(const std::string &path) : file_(path)
{
  out_.open(file_.temp_path(), std::ios::binary | std::ios::trunc);
  if (!out_)
    throw std::runtime_error("cannot write checkpoint '" + file_.temp_path() +
                             "': check that the directory exists and is writable");
  out_.write(checkpoint_magic, 8);
}

// The stream closes first, then file_ removes the temporary file unless commit() renamed it.
CheckpointWriter::~CheckpointWriter() = default;

void CheckpointWriter::commit()
{
  out_.close();
  if (!out_)
    throw std::runtime_error("writing checkpoint '" + file_.temp_path() + "' failed (disk full?)");
  file_.commit();
}

CheckpointReader::CheckpointReader(const std::string &path) : path_(path), in_(path, std::ios::binary)
{
  if (!in_)
    throw std::runtime_error("cannot open checkpoint '" + path + "'");
  char magic[8];
  in_.read(magic, 8);
  if (!in_ || std::memcmp(magic, checkpoint_magic, 8) != 0)
    throw std::runtime_error("'" + path + "' is not a magbrush DEM checkpoint (expected header " +
                             std::string(checkpoint_magic) + ")");
}

void CheckpointReader::fail(const std::string &what) const
{
  throw std::runtime_error("checkpoint '" + path_ + "' " + what);
}

} // namespace magbrush::dem
