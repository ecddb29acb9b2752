// Atomic file output (temporary file in the target's directory, fsync,
// rename) and whole-file input, on POSIX file descriptors.
#include "io/atomic_write.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <filesystem>
#include <system_error>

#include <fmt/format.h>

#include "core/errors.hpp"

namespace umbmark::io {
namespace {

std::string ErrnoText(int err) { return std::error_code(err, std::generic_category()).message(); }

/// Closes a file descriptor on scope exit.
class FdGuard {
 public:
  explicit FdGuard(int fd) : fd_(fd) {}
  FdGuard(const FdGuard&) = delete;
  FdGuard& operator=(const FdGuard&) = delete;
  ~FdGuard() {
    if (fd_ >= 0) ::close(fd_);
  }
  int get() const { return fd_; }
  /// Closes now and reports the error close() returns (deferred write errors).
  int Close() {
    const int r = ::close(fd_);
    fd_ = -1;
    return r;
  }

 private:
  int fd_;
};

}  // namespace

void WriteFileAtomically(const std::string& path, std::string_view content) {
  namespace fs = std::filesystem;
  if (path.empty()) throw InputError(path, "empty output file name");
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) {
    if (!S_ISREG(st.st_mode)) {
      throw InputError(path, S_ISDIR(st.st_mode)
                                 ? "refusing to write: it is a directory"
                                 : "refusing to write: it exists and is not a regular file (device, FIFO or socket)");
    }
  } else if (errno != ENOENT) {
    throw InputError(path, fmt::format("cannot write: {}", ErrnoText(errno)));
  }

  const fs::path target(path);
  if (!target.has_filename()) throw InputError(path, "refusing to write: the path names a directory");
  static std::atomic<unsigned> counter{0};
  std::string tmp;
  int fd = -1;
  for (int attempt = 0; attempt < 100 && fd < 0; ++attempt) {
    const std::string tmp_name = fmt::format(".{}.tmp.{}.{}", target.filename().string(), ::getpid(), counter++);
    tmp = (target.parent_path() / tmp_name).string();
    fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0 && errno != EEXIST) {
      throw InputError(path, fmt::format("cannot create temporary file '{}': {}", tmp, ErrnoText(errno)));
    }
  }
  if (fd < 0) throw InputError(path, fmt::format("cannot create a temporary file next to it"));

  FdGuard guard(fd);
  const auto fail = [&](const char* what, int err) {
    guard.Close();
    ::unlink(tmp.c_str());
    throw InputError(path, fmt::format("{}: {}", what, ErrnoText(err)));
  };
  const char* p = content.data();
  std::size_t left = content.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      fail("cannot write", errno);
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) fail("cannot flush to disk", errno);
  if (guard.Close() != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    throw InputError(path, fmt::format("cannot close: {}", ErrnoText(err)));
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    throw InputError(path, fmt::format("cannot rename the temporary file into place: {}", ErrnoText(err)));
  }
  // Make the rename itself durable; failure here does not undo the write.
  const std::string dir = target.parent_path().empty() ? std::string(".") : target.parent_path().string();
  const int dir_fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd >= 0) {
    ::fsync(dir_fd);
    ::close(dir_fd);
  }
}

std::string ReadWholeFile(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw InputError(path, fmt::format("cannot open: {}", ErrnoText(errno)));
  FdGuard guard(fd);
  struct stat st {};
  if (::fstat(fd, &st) != 0) throw InputError(path, fmt::format("cannot read: {}", ErrnoText(errno)));
  if (S_ISDIR(st.st_mode)) throw InputError(path, "cannot read: it is a directory");
  // Regular files: one read of the known size (+1 to see the end at once);
  // pipes and devices: grow as data comes.
  std::string out;
  out.resize(S_ISREG(st.st_mode) ? static_cast<std::size_t>(st.st_size) + 1 : std::size_t{1} << 16);
  std::size_t len = 0;
  for (;;) {
    if (len == out.size()) out.resize(out.size() * 2);
    const ssize_t n = ::read(fd, out.data() + len, out.size() - len);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw InputError(path, fmt::format("cannot read: {}", ErrnoText(errno)));
    }
    if (n == 0) break;
    len += static_cast<std::size_t>(n);
  }
  out.resize(len);
  return out;
}

}  // namespace umbmark::io
