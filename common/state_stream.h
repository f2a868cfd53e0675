// The binary stream a component writes its restartable state to, and reads it back from.
//
// A restart continues bit for bit only if every number that outlives a step is restored
// exactly, so state is written as raw bytes (native byte order): scalars, and arrays with
// their length in front. The DEM checkpoint (dem/checkpoint_file.h) is such a stream, with a
// checksum over everything; libraries below the engine (the magnetics) write their state
// through this interface without knowing the file behind it.
//
//   void Tracker::write_state(StateOut &out) const { out.put(t_last_); out.put_array(x_last_); }
//   void Tracker::read_state(StateIn &in) { t_last_ = in.get<double>(); in.get_array(x_last_); }
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace magbrush {

class StateOut
{
public:
  virtual ~StateOut() = default;
  virtual void write_bytes(const void *data, std::size_t size) = 0;

  template <typename T>
  void put(const T &value)
  {
    static_assert(std::is_trivially_copyable_v<T>, "state is written as raw bytes");
    write_bytes(&value, sizeof(T));
  }
  template <typename T>
  void put_array(const std::vector<T> &values)
  {
    static_assert(std::is_trivially_copyable_v<T>, "state is written as raw bytes");
    put<std::uint64_t>(values.size());
    write_bytes(values.data(), values.size() * sizeof(T));
  }
  void put_string(const std::string &s)
  {
    put<std::uint64_t>(s.size());
    write_bytes(s.data(), s.size());
  }
};

class StateIn
{
public:
  virtual ~StateIn() = default;
  // Reads exactly `size` bytes or calls fail().
  virtual void read_bytes(void *data, std::size_t size) = 0;
  // Throws, naming the source and what is wrong with it.
  [[noreturn]] virtual void fail(const std::string &what) const = 0;
  // Bytes left to read (a length larger than this is corruption, not a huge allocation).
  virtual std::size_t remaining() const = 0;

  template <typename T>
  T get()
  {
    static_assert(std::is_trivially_copyable_v<T>, "state is read as raw bytes");
    T value{};
    read_bytes(&value, sizeof(T));
    return value;
  }
  template <typename T>
  void get_array(std::vector<T> &values)
  {
    static_assert(std::is_trivially_copyable_v<T>, "state is read as raw bytes");
    const auto n = get<std::uint64_t>();
    if (n > remaining() / sizeof(T))
      fail("is corrupt (an array of " + std::to_string(n) + " elements, more than the file holds)");
    values.resize(static_cast<std::size_t>(n));
    read_bytes(values.data(), static_cast<std::size_t>(n) * sizeof(T));
  }
  std::string get_string()
  {
    std::vector<char> c;
    get_array(c);
    return std::string(c.begin(), c.end());
  }
};

// A state kept in memory: a component that may have to skip its state on reading (it was
// written under other settings) writes it as one block (put_string of bytes()) and reads it
// back through MemoryStateIn.
class MemoryStateOut : public StateOut
{
public:
  void write_bytes(const void *data, std::size_t size) override
  {
    bytes_.append(static_cast<const char *>(data), size);
  }
  const std::string &bytes() const { return bytes_; }

private:
  std::string bytes_;
};

class MemoryStateIn : public StateIn
{
public:
  // `what` names the state in messages ("checkpoint 'x.bin', magnetic state").
  MemoryStateIn(std::string bytes, std::string what) : bytes_(std::move(bytes)), what_(std::move(what)) {}
  void read_bytes(void *data, std::size_t size) override
  {
    if (size > remaining())
      fail("is truncated");
    if (size > 0)
      std::memcpy(data, bytes_.data() + at_, size);
    at_ += size;
  }
  [[noreturn]] void fail(const std::string &what) const override { throw std::runtime_error(what_ + " " + what); }
  std::size_t remaining() const override { return bytes_.size() - at_; }

private:
  std::string bytes_;
  std::string what_;
  std::size_t at_ = 0;
};

} // namespace magbrush
