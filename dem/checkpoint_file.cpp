#include "dem/checkpoint_file.h"

#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace magbrush::dem {

namespace {
constexpr char checkpoint_magic[9] = "MBDEMCK2";
}

CheckpointWriter::CheckpointWriter(const std::string &path) : path_(path), temp_(path + ".tmp")
{
  out_.open(temp_, std::ios::binary | std::ios::trunc);
  if (!out_)
    throw std::runtime_error("cannot write checkpoint '" + temp_ +
                             "': check that the directory exists and is writable");
  out_.write(checkpoint_magic, 8);
}

CheckpointWriter::~CheckpointWriter()
{
  if (!committed_)
  {
    out_.close();
    std::remove(temp_.c_str());
  }
}

void CheckpointWriter::commit()
{
  out_.close();
  if (!out_)
    throw std::runtime_error("writing checkpoint '" + temp_ + "' failed (disk full?)");
  if (std::rename(temp_.c_str(), path_.c_str()) != 0)
    throw std::runtime_error("cannot rename '" + temp_ + "' to '" + path_ + "'");
  committed_ = true;
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
