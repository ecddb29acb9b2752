// Internal to the file rooms (formats/, ros2/, import/): how input files are read, and the size limits that keep a
// hostile or mistaken input (a device, a pipe that never ends, a file with
// no line breaks) from growing memory without bound.
//
// Files are read with read() in chunks, never memory-mapped: a file that
// another process truncates while it is being read then only ends early
// (the readers report a truncated row), instead of killing the process with
// SIGBUS as a mapping would.
//
// Limits (documented in docs/formats.md, "Size limits"):
//  - kMaxLineBytes: a CSV line (header or row) longer than 1 MiB is an error
//    (so /dev/zero given as a data file fails after 1 MiB).
//  - kMaxStreamBytes: a CSV read from a pipe or device stops with an error
//    after 4 GiB (a regular file is read to its end, whatever its size).
//  - kMaxWholeFileBytes: small text inputs read whole (TOML robot files and
//    manifests, JSON parameter files, OptiOdom CSVs) stop with an error after
//    64 MiB, regular file or not (`--robot /dev/zero` fails at once instead
//    of growing memory).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

namespace umbmark::io::detail {

inline constexpr std::size_t kMaxLineBytes = std::size_t{1} << 20;
inline constexpr std::uint64_t kMaxStreamBytes = std::uint64_t{4} << 30;
inline constexpr std::size_t kMaxWholeFileBytes = std::size_t{64} << 20;

/// "1 MiB", "4 GiB": a byte limit for messages.
std::string FormatBytes(std::uint64_t bytes);

/// A sequence of bytes read in chunks: an open file (regular, pipe, device)
/// or text in memory (optionally handed out in small chunks, so tests and
/// fuzzers exercise every chunk boundary of the streaming readers).
class InputStream {
 public:
  /// Opens `path` for reading. Throws InputError(path, reason) when it cannot
  /// be opened or is a directory.
  explicit InputStream(const std::string& path);
  /// The bytes [begin, end) of the regular file `path` (a part of a large
  /// file read by one of several threads).
  InputStream(const std::string& path, std::uint64_t begin, std::uint64_t end);
  /// Text in memory (not copied: it must outlive the stream); Read() hands
  /// out at most `max_chunk` bytes per call (0 = no limit).
  InputStream(std::string_view text, std::size_t max_chunk = 0);
  ~InputStream();
  InputStream(const InputStream&) = delete;
  InputStream& operator=(const InputStream&) = delete;
  InputStream(InputStream&& other) noexcept;
  InputStream& operator=(InputStream&&) = delete;

  /// Reads up to `n` bytes into `dst`; 0 only at the end. Throws
  /// InputError(name, reason) on a read error and when a non-regular input
  /// passes kMaxStreamBytes.
  std::size_t Read(char* dst, std::size_t n);

  const std::string& name() const { return name_; }
  /// True for a regular file or text in memory (its size is known).
  bool sized() const { return sized_; }
  /// The size of a regular file or of the text; 0 when not known.
  std::uint64_t size() const { return size_; }
  std::uint64_t bytes_read() const { return bytes_read_; }

 private:
  std::string name_;
  int fd_ = -1;
  std::string_view text_;
  std::size_t max_chunk_ = 0;
  bool sized_ = false;
  std::uint64_t size_ = 0;
  std::uint64_t bytes_read_ = 0;
  std::uint64_t limit_ = UINT64_MAX;  ///< bytes Read() hands out at most (a range)
};

/// Reads a whole text file of at most `max_bytes` (regular or not). Throws
/// InputError(path, reason) when it cannot be read, is a directory, or is
/// larger than the limit (the message names the limit).
std::string ReadLimitedFile(const std::string& path, std::size_t max_bytes = kMaxWholeFileBytes);

}  // namespace umbmark::io::detail

namespace umbmark::io {

/// Reads a whole file (at most 64 MiB, kMaxWholeFileBytes). Throws
/// InputError(path, reason) when it cannot or when it is larger.
std::string ReadWholeFile(const std::string& path);

}  // namespace umbmark::io
