// CDR decoding as rosbag2 stores ROS 2 messages (OMG XCDR version 1, "plain
// CDR"): a 4-byte encapsulation header {0x00, 0x00 big-endian | 0x01
// little-endian, options, options}, then the fields in declaration order,
// each primitive aligned to its own size (8 for 64-bit types) counted from
// the end of the header. A string is a uint32 length that includes the
// terminating NUL, then the bytes; a sequence is a uint32 element count,
// then the elements; a fixed array has no count.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>

namespace umbmark::io::rosbag2 {

/// A message whose bytes do not hold what its type says; offset is from the
/// start of the message (encapsulation header included).
class CdrError : public std::runtime_error {
 public:
  CdrError(std::size_t offset, const std::string& what)
      : std::runtime_error("CDR byte " + std::to_string(offset) + ": " + what), offset_(offset) {}
  std::size_t offset() const { return offset_; }

 private:
  std::size_t offset_;
};

class CdrReader {
 public:
  /// Checks the encapsulation header; throws CdrError for anything but
  /// XCDR1 plain CDR in either byte order.
  CdrReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {
    if (size < 4) throw CdrError(0, "message shorter than the 4-byte encapsulation header");
    if (data[0] != 0 || data[1] > 1) {
      throw CdrError(0, "unsupported CDR encapsulation 0x" + Hex(data[0]) + Hex(data[1]) +
                            " (plain CDR, 0x0000 or 0x0001, expected)");
    }
    swap_ = (data[1] == 1) != (std::endian::native == std::endian::little);
    pos_ = 4;
  }

  template <typename T>
  T Read() {
    static_assert(std::is_arithmetic_v<T>);
    Align(sizeof(T));
    Need(sizeof(T), "value");
    T v;
    if constexpr (sizeof(T) == 1) {
      std::memcpy(&v, data_ + pos_, 1);
    } else {
      using U = std::conditional_t<sizeof(T) == 2, std::uint16_t,
                                   std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>>;
      U u;
      std::memcpy(&u, data_ + pos_, sizeof(T));
      if (swap_) u = ByteSwap(u);
      std::memcpy(&v, &u, sizeof(T));
    }
    pos_ += sizeof(T);
    return v;
  }
  double Float64() { return Read<double>(); }
  std::uint32_t Uint32() { return Read<std::uint32_t>(); }
  std::int32_t Int32() { return Read<std::int32_t>(); }

  /// A string: uint32 length including the NUL, the bytes, the NUL. The view
  /// points into the message.
  std::string_view String() {
    const std::size_t at = pos_;
    const std::uint32_t n = Uint32();
    if (n == 0) return {};  // some writers emit 0 for the empty string
    Need(n, "string");
    if (data_[pos_ + n - 1] != 0) throw CdrError(at, "string of " + std::to_string(n) + " bytes is not NUL-terminated");
    std::string_view s(reinterpret_cast<const char*>(data_ + pos_), n - 1);
    pos_ += n;
    return s;
  }

  /// A sequence's element count, checked against the bytes left (each
  /// element takes at least `min_element_bytes`), so a corrupt count can
  /// never make the caller allocate more than the message holds.
  std::uint32_t SequenceLength(std::size_t min_element_bytes) {
    const std::size_t at = pos_;
    const std::uint32_t n = Uint32();
    if (min_element_bytes > 0 && n > (size_ - pos_) / min_element_bytes) {
      throw CdrError(at, "sequence of " + std::to_string(n) + " elements does not fit in the " +
                             std::to_string(size_ - pos_) + " bytes left");
    }
    return n;
  }

  /// Skips n elements of a primitive type (aligned like the type).
  void Skip(std::size_t n, std::size_t element_bytes) {
    if (n == 0) return;
    Align(element_bytes);
    Need(n * element_bytes, "array");
    pos_ += n * element_bytes;
  }

  std::size_t offset() const { return pos_; }
  std::size_t size() const { return size_; }
  bool big_endian() const { return data_[1] == 0; }

 private:
  void Align(std::size_t n) {
    const std::size_t rel = pos_ - 4;
    const std::size_t pad = (n - rel % n) % n;
    if (pad > size_ - pos_) throw CdrError(pos_, "message ends inside alignment padding");
    pos_ += pad;
  }
  void Need(std::size_t n, const char* what) const {
    if (n > size_ - pos_) {
      throw CdrError(pos_, std::string("message ends inside a ") + what + " (" + std::to_string(n) + " bytes needed, " +
                               std::to_string(size_ - pos_) + " left)");
    }
  }
  template <typename U>
  static U ByteSwap(U u) {
    if constexpr (sizeof(U) == 2) return static_cast<U>(__builtin_bswap16(u));
    if constexpr (sizeof(U) == 4) return __builtin_bswap32(u);
    if constexpr (sizeof(U) == 8) return __builtin_bswap64(u);
  }
  static std::string Hex(std::uint8_t b) {
    const char* d = "0123456789abcdef";
    return {d[b >> 4], d[b & 15]};
  }

  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
  bool swap_ = false;
};

}  // namespace umbmark::io::rosbag2
