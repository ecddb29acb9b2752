// InputStream, ReadLimitedFile and ReadWholeFile: chunked read() of input
// files with size limits (file_text.hpp).
#include "formats/file_text.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <system_error>
#include <utility>

#include <fmt/format.h>

#include "core/errors.hpp"

namespace umbmark::io::detail {
namespace {

std::string ErrnoText(int err) { return std::error_code(err, std::generic_category()).message(); }

}  // namespace

std::string FormatBytes(std::uint64_t bytes) {
  if (bytes >= (std::uint64_t{1} << 30) && bytes % (std::uint64_t{1} << 30) == 0) {
    return fmt::format("{} GiB", bytes >> 30);
  }
  if (bytes >= (std::uint64_t{1} << 20) && bytes % (std::uint64_t{1} << 20) == 0) {
    return fmt::format("{} MiB", bytes >> 20);
  }
  return fmt::format("{} bytes", bytes);
}

InputStream::InputStream(const std::string& path) : name_(path) {
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) throw InputError(path, fmt::format("cannot open: {}", ErrnoText(errno)));
  struct stat st {};
  if (::fstat(fd_, &st) != 0) {
    const int err = errno;
    ::close(fd_);
    throw InputError(path, fmt::format("cannot read: {}", ErrnoText(err)));
  }
  if (S_ISDIR(st.st_mode)) {
    ::close(fd_);
    throw InputError(path, "cannot read: it is a directory");
  }
  if (S_ISREG(st.st_mode)) {
    sized_ = true;
    size_ = static_cast<std::uint64_t>(st.st_size);
    ::posix_fadvise(fd_, 0, 0, POSIX_FADV_SEQUENTIAL);
  }
}

InputStream::InputStream(const std::string& path, std::uint64_t begin, std::uint64_t end) : InputStream(path) {
  if (!sized_ || begin > end || end > size_) throw InputError(path, "cannot read a part of it: not a regular file");
  if (::lseek(fd_, static_cast<off_t>(begin), SEEK_SET) < 0)
    throw InputError(path, fmt::format("cannot read: {}", ErrnoText(errno)));
  limit_ = end - begin;
}

InputStream::InputStream(std::string_view text, std::size_t max_chunk)
    : text_(text), max_chunk_(max_chunk), sized_(true), size_(text.size()) {}

InputStream::InputStream(InputStream&& other) noexcept
    : name_(std::move(other.name_)),
      fd_(std::exchange(other.fd_, -1)),
      text_(other.text_),
      max_chunk_(other.max_chunk_),
      sized_(other.sized_),
      size_(other.size_),
      bytes_read_(other.bytes_read_),
      limit_(other.limit_) {}

InputStream::~InputStream() {
  if (fd_ >= 0) ::close(fd_);
}

std::size_t InputStream::Read(char* dst, std::size_t n) {
  if (fd_ < 0) {
    std::size_t k = std::min(n, text_.size() - static_cast<std::size_t>(bytes_read_));
    if (max_chunk_ > 0) k = std::min(k, max_chunk_);
    if (k > 0) std::memcpy(dst, text_.data() + bytes_read_, k);
    bytes_read_ += k;
    return k;
  }
  if (!sized_ && bytes_read_ >= kMaxStreamBytes) {
    throw InputError(name_, fmt::format("input is not a regular file and goes on past the {} limit for pipes and "
                                        "devices; save it to a file first",
                                        FormatBytes(kMaxStreamBytes)));
  }
  n = static_cast<std::size_t>(std::min<std::uint64_t>(n, limit_ - bytes_read_));
  if (n == 0) return 0;
  for (;;) {
    const ssize_t got = ::read(fd_, dst, n);
    if (got < 0) {
      if (errno == EINTR) continue;
      throw InputError(name_, fmt::format("cannot read: {}", ErrnoText(errno)));
    }
    bytes_read_ += static_cast<std::uint64_t>(got);
    return static_cast<std::size_t>(got);
  }
}

std::string ReadLimitedFile(const std::string& path, std::size_t max_bytes) {
  InputStream in(path);
  if (in.sized() && in.size() > max_bytes) {
    throw InputError(path, fmt::format("file is {} bytes, over the {} limit for this kind of input", in.size(),
                                       FormatBytes(max_bytes)));
  }
  // Regular files: one read of the known size (+1 to see the end at once);
  // pipes and devices: grow as data comes, up to the limit.
  std::string out;
  out.resize(in.sized() ? static_cast<std::size_t>(in.size()) + 1 : std::size_t{1} << 16);
  std::size_t len = 0;
  for (;;) {
    if (len == out.size()) {
      if (len > max_bytes) {
        throw InputError(path, fmt::format("input goes on past the {} limit for this kind of input{}",
                                           FormatBytes(max_bytes),
                                           in.sized() ? " (the file grew while it was read)"
                                                      : " (a device or a pipe that does not end?)"));
      }
      out.resize(std::min(out.size() * 2, max_bytes + 1));
    }
    const std::size_t n = in.Read(out.data() + len, out.size() - len);
    if (n == 0) break;
    len += n;
  }
  out.resize(len);
  return out;
}

}  // namespace umbmark::io::detail

namespace umbmark::io {

std::string ReadWholeFile(const std::string& path) { return detail::ReadLimitedFile(path); }

}  // namespace umbmark::io
