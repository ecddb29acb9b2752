// FileText: memory-mapped (or read) text of an input file (file_text.hpp).
#include "io/file_text.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>

#include <fmt/format.h>

#include "core/errors.hpp"

namespace umbmark::io::detail {
namespace {

std::string ErrnoText(int err) { return std::error_code(err, std::generic_category()).message(); }

}  // namespace

FileText::FileText(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw InputError(path, fmt::format("cannot open: {}", ErrnoText(errno)));
  try {
    struct stat st {};
    if (::fstat(fd, &st) != 0) throw InputError(path, fmt::format("cannot read: {}", ErrnoText(errno)));
    if (S_ISDIR(st.st_mode)) throw InputError(path, "cannot read: it is a directory");
    if (S_ISREG(st.st_mode) && st.st_size > 0) {
      const auto size = static_cast<std::size_t>(st.st_size);
      void* p = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
      if (p != MAP_FAILED) {
        map_ = static_cast<const char*>(p);
        size_ = size;
        ::close(fd);
        return;
      }
    }
    // Not mappable: read to the end.
    char buf[1 << 16];
    for (;;) {
      const ssize_t n = ::read(fd, buf, sizeof buf);
      if (n < 0) {
        if (errno == EINTR) continue;
        throw InputError(path, fmt::format("cannot read: {}", ErrnoText(errno)));
      }
      if (n == 0) break;
      owned_.append(buf, static_cast<std::size_t>(n));
    }
  } catch (...) {
    ::close(fd);
    throw;
  }
  ::close(fd);
}

FileText::~FileText() {
  if (map_ != nullptr) ::munmap(const_cast<char*>(map_), size_);
}

}  // namespace umbmark::io::detail
