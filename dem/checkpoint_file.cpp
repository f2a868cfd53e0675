#include "dem/checkpoint_file.h"

#include <zlib.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <system_error>

namespace magbrush::dem {

namespace fs = std::filesystem;

namespace {
constexpr char checkpoint_magic[9] = "MBDEMCK6";
constexpr std::size_t trailer_size = sizeof(std::uint64_t) + sizeof(std::uint32_t);

// zlib's crc32 takes 32-bit lengths: feed it in pieces.
std::uint32_t crc32_update(std::uint32_t crc, const void *data, std::size_t size)
{
  const auto *p = static_cast<const Bytef *>(data);
  while (size > 0)
  {
    const std::size_t piece = std::min<std::size_t>(size, 1u << 30);
    crc = static_cast<std::uint32_t>(::crc32(crc, p, static_cast<uInt>(piece)));
    p += piece;
    size -= piece;
  }
  return crc;
}

std::string hex(std::uint32_t v)
{
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08x", v);
  return buf;
}

// What to do with a checkpoint that cannot be used.
std::string what_to_do(const std::string &path)
{
  const std::string previous = previous_checkpoint_path(path);
  if (previous != path && fs::exists(previous))
    return "restart from the checkpoint kept before it, '" + previous + "' (--restart " + previous +
           "), or rerun the case from the start";
  return "rerun the case from the start (no earlier checkpoint is kept beside it)";
}
} // namespace

// ---------------------------------------------------------------------------------------
// Writing.

CheckpointWriter::CheckpointWriter(const std::string &path, const CheckpointIdentity &identity) : file_(path)
{
  out_.open(file_.temp_path(), std::ios::binary | std::ios::trunc);
  if (!out_)
    throw std::runtime_error("cannot write checkpoint '" + file_.temp_path() +
                             "': check that the directory exists and is writable");
  crc_ = static_cast<std::uint32_t>(::crc32(0L, Z_NULL, 0));
  write_bytes(checkpoint_magic, 8);
  put_string(identity.case_hash);
  put<std::uint64_t>(identity.inputs.size());
  for (const auto &[key, value] : identity.inputs)
  {
    put_string(key);
    put_string(value);
  }
}

// The stream closes first, then file_ removes the temporary file unless commit() renamed it.
CheckpointWriter::~CheckpointWriter() = default;

void CheckpointWriter::write_bytes(const void *data, std::size_t size)
{
  out_.write(static_cast<const char *>(data), static_cast<std::streamsize>(size));
  crc_ = crc32_update(crc_, data, size);
  length_ += size;
}

void CheckpointWriter::commit()
{
  // The trailer is not part of the checksum it carries.
  out_.write(reinterpret_cast<const char *>(&length_), sizeof length_);
  out_.write(reinterpret_cast<const char *>(&crc_), sizeof crc_);
  out_.close();
  if (!out_)
    throw std::runtime_error("writing checkpoint '" + file_.temp_path() + "' failed (disk full?)");
  file_.commit();
}

// ---------------------------------------------------------------------------------------
// Reading.

CheckpointReader::CheckpointReader(const std::string &path) : path_(path), in_(path, std::ios::binary)
{
  if (!in_)
    throw std::runtime_error("cannot open checkpoint '" + path + "'");
  char magic[8] = {};
  in_.read(magic, 8);
  if (!in_ || std::memcmp(magic, "MBDEMCK", 7) != 0)
    throw std::runtime_error("'" + path + "' is not a magbrush DEM checkpoint (expected header " +
                             std::string(checkpoint_magic) + ")");
  if (std::memcmp(magic, checkpoint_magic, 8) != 0)
    throw std::runtime_error("checkpoint '" + path + "' has format " + std::string(magic, 8) +
                             ", written by another version of magbrush; this one reads " +
                             std::string(checkpoint_magic) +
                             " (with case identity and checksum) only: rerun the case from the start, "
                             "or finish the run with the version that wrote it");
  verify_checksum();
  in_.clear();
  in_.seekg(8);
  position_ = 8;
  identity_.case_hash = get_string();
  const auto n = get<std::uint64_t>();
  if (n > remaining())
    fail("is corrupt (" + std::to_string(n) + " case inputs)");
  for (std::uint64_t k = 0; k < n; ++k)
  {
    std::string key = get_string();
    identity_.inputs.emplace_back(std::move(key), get_string());
  }
}

void CheckpointReader::verify_checksum()
{
  in_.seekg(0, std::ios::end);
  const auto size = static_cast<std::uint64_t>(in_.tellg());
  std::uint64_t stored_length = 0;
  std::uint32_t stored_crc = 0;
  if (size >= 8 + trailer_size)
  {
    in_.seekg(static_cast<std::streamoff>(size - trailer_size));
    in_.read(reinterpret_cast<char *>(&stored_length), sizeof stored_length);
    in_.read(reinterpret_cast<char *>(&stored_crc), sizeof stored_crc);
  }
  if (!in_ || size < 8 + trailer_size || stored_length != size - trailer_size)
    throw std::runtime_error("checkpoint '" + path_ + "' is damaged or truncated (" + std::to_string(size) +
                             " bytes, its trailer says " + std::to_string(stored_length + trailer_size) +
                             "); nothing was read from it: " + what_to_do(path_));
  in_.seekg(0);
  std::uint32_t crc = static_cast<std::uint32_t>(::crc32(0L, Z_NULL, 0));
  std::vector<char> buffer(1 << 20);
  for (std::uint64_t left = stored_length; left > 0;)
  {
    const std::size_t piece = static_cast<std::size_t>(std::min<std::uint64_t>(left, buffer.size()));
    in_.read(buffer.data(), static_cast<std::streamsize>(piece));
    if (!in_)
      throw std::runtime_error("checkpoint '" + path_ + "' could not be read to its end; nothing was read from it: " +
                               what_to_do(path_));
    crc = crc32_update(crc, buffer.data(), piece);
    left -= piece;
  }
  if (crc != stored_crc)
    throw std::runtime_error("checkpoint '" + path_ + "' is damaged: its CRC-32 checksum does not match its contents (stored " +
                             hex(stored_crc) + ", computed " + hex(crc) + "); nothing was read from it: " +
                             what_to_do(path_));
  length_ = stored_length;
}

void CheckpointReader::read_bytes(void *data, std::size_t size)
{
  if (size > remaining())
    fail("is truncated");
  in_.read(static_cast<char *>(data), static_cast<std::streamsize>(size));
  if (!in_)
    fail("is truncated");
  position_ += size;
}

void CheckpointReader::fail(const std::string &what) const
{
  throw std::runtime_error("checkpoint '" + path_ + "' " + what);
}

// ---------------------------------------------------------------------------------------
// The checkpoint kept before.

std::string previous_checkpoint_path(const std::string &path)
{
  const fs::path p(path);
  return (p.parent_path() / (p.stem().string() + ".previous" + p.extension().string())).string();
}

void keep_previous_checkpoint(const std::string &path)
{
  std::error_code ec;
  if (!fs::exists(path, ec))
    return;
  const std::string previous = previous_checkpoint_path(path);
  // A second name for the current file, renamed over the previous one: at every moment both
  // names hold a complete checkpoint (or the previous one is missing, never the current).
  AtomicFile link(previous);
  fs::create_hard_link(path, link.temp_path(), ec);
  if (ec) // (a file system without hard links: a copy)
    fs::copy_file(path, link.temp_path(), fs::copy_options::overwrite_existing);
  link.commit();
}

} // namespace magbrush::dem
