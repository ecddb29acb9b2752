// Atomic file output (temporary file in the target's directory, fsync,
// rename), staging directories renamed into place as a whole, clean-up of
// temporary files on SIGINT/SIGTERM/SIGHUP and the rename fault-injection
// hook, on POSIX file descriptors.
#include "output/atomic_write.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <system_error>

#include <fmt/format.h>

#include "core/errors.hpp"

namespace umbmark::io {
namespace {

namespace fs = std::filesystem;

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

// ---- Temporary paths in flight, for the signal handler ---------------------
// Fixed storage (no allocation, async-signal-safe to read): a handler unlinks
// the files, then removes the directories.
constexpr int kMaxPending = 64;
constexpr std::size_t kMaxPath = 4096;
struct PendingSlot {
  std::atomic<int> state{0};  // 0 free, 1 file, 2 directory
  char path[kMaxPath];
};
PendingSlot g_pending[kMaxPending];

int RegisterPending(const std::string& path, int kind) {
  if (path.size() >= kMaxPath) return -1;
  for (int i = 0; i < kMaxPending; ++i) {
    int expected = 0;
    if (g_pending[i].state.compare_exchange_strong(expected, -1)) {
      std::memcpy(g_pending[i].path, path.c_str(), path.size() + 1);
      g_pending[i].state.store(kind);
      return i;
    }
  }
  return -1;
}

void Unregister(int slot) {
  if (slot >= 0) g_pending[slot].state.store(0);
}

/// Unregisters a slot when the scope ends (success or error).
struct PendingGuard {
  int slot;
  ~PendingGuard() { Unregister(slot); }
};

extern "C" void CleanupOnSignal(int sig) {
  for (auto& s : g_pending)
    if (s.state.load() == 1) ::unlink(s.path);
  for (int i = kMaxPending - 1; i >= 0; --i)  // sub-folders were registered after their parent
    if (g_pending[i].state.load() == 2) ::rmdir(g_pending[i].path);
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

/// Test hook: raise a signal just before the N-th rename into place.
void BeforeRename() {
  static const long kill_at = [] {
    const char* v = std::getenv("UMBMARK_TEST_KILL_AT_RENAME");
    return v ? std::strtol(v, nullptr, 10) : 0L;
  }();
  static long renames = 0;
  if (kill_at <= 0 || ++renames != kill_at) return;
  const char* s = std::getenv("UMBMARK_TEST_KILL_SIGNAL");
  const std::string name = s ? s : "TERM";
  ::raise(name == "KILL" ? SIGKILL : name == "INT" ? SIGINT : SIGTERM);
}

/// True when `p` lies in a staging directory registered for clean-up: files
/// renamed into it are registered too, so a signal removes them.
bool InPendingDirectory(const fs::path& p) {
  const std::string parent = p.parent_path().string();
  for (auto& s : g_pending)
    if (s.state.load() == 2 && parent == s.path) return true;
  return false;
}

// ---- Temporaries left by SIGKILL ----------------------------------------
// Temporary names are ".NAME.tmp.PID.HOST.SUFFIX": the next write of NAME
// deletes those whose HOST is this machine and whose PID no longer runs.

/// This machine's name, reduced to [A-Za-z0-9-] (at most 32 characters) so
/// it never contains the '.' that separates the name's fields.
const std::string& HostTag() {
  static const std::string tag = [] {
    char buf[256] = {};
    std::string out;
    if (::gethostname(buf, sizeof buf - 1) == 0) {
      for (const char* c = buf; *c && out.size() < 32; ++c) {
        const bool keep = (*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || (*c >= '0' && *c <= '9') || *c == '-';
        out += keep ? *c : '-';
      }
    }
    return out.empty() ? std::string("host") : out;
  }();
  return tag;
}

/// ".NAME.tmp.PID.HOST." for this process.
std::string TemporaryPrefix(const std::string& name) {
  return fmt::format(".{}.tmp.{}.{}.", name, ::getpid(), HostTag());
}

/// Deletes, in `dir`, the temporaries of `name` that a process of this host
/// left behind and that no longer runs (kill(pid, 0) fails with ESRCH; a
/// process of another user, EPERM, is alive). Best effort: errors are ignored.
void SweepStaleTemporaries(const fs::path& dir, const std::string& name) noexcept {
  const std::string head = "." + name + ".tmp.";
  std::error_code ec;
  fs::directory_iterator it(dir.empty() ? fs::path(".") : dir, ec);
  if (ec) return;
  for (const fs::directory_iterator end; it != end; it.increment(ec)) {
    if (ec) return;
    const std::string entry = it->path().filename().string();
    if (entry.rfind(head, 0) != 0) continue;
    // PID.HOST.SUFFIX
    const std::string rest = entry.substr(head.size());
    const auto dot1 = rest.find('.');
    if (dot1 == std::string::npos || dot1 == 0 || dot1 > 10) continue;
    if (rest.find_first_not_of("0123456789") < dot1) continue;
    const auto dot2 = rest.find('.', dot1 + 1);
    if (dot2 == std::string::npos || rest.compare(dot1 + 1, dot2 - dot1 - 1, HostTag()) != 0) continue;
    const long pid = std::strtol(rest.c_str(), nullptr, 10);
    if (pid <= 0 || pid == ::getpid() || pid > 0x7fffffffL) continue;
    if (::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;
    std::error_code rm;
    fs::remove_all(it->path(), rm);
  }
}

bool UnderSpecialTree(const std::string& p) {
  return p == "/dev" || p.rfind("/dev/", 0) == 0 || p == "/proc" || p.rfind("/proc/", 0) == 0;
}

}  // namespace

std::string ResolveOutputTarget(const std::string& path) {
  if (path.empty()) throw InputError(path, "empty output file name");
  if (!fs::path(path).has_filename()) throw InputError(path, "refusing to write: the path names a directory");
  // Follow symbolic links by hand (a dangling link's target may not exist yet).
  fs::path p(path);
  for (int hops = 0;; ++hops) {
    if (UnderSpecialTree(fs::absolute(p).lexically_normal().string())) {
      struct stat st {};
      if (::lstat(p.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
        throw InputError(path, "refusing to write: it is a device or a process's file descriptor, not a regular file "
                               "(use '-' for standard output)");
      }
    }
    struct stat st {};
    if (::lstat(p.c_str(), &st) != 0) {
      if (errno != ENOENT) throw InputError(path, fmt::format("cannot write: {}", ErrnoText(errno)));
      return p.string();
    }
    if (S_ISREG(st.st_mode)) return p.string();
    if (S_ISDIR(st.st_mode)) throw InputError(path, "refusing to write: it is a directory");
    if (!S_ISLNK(st.st_mode)) {
      throw InputError(path, "refusing to write: it exists and is not a regular file (device, FIFO or socket)");
    }
    if (hops >= 40) throw InputError(path, "refusing to write: too many levels of symbolic links");
    std::error_code ec;
    const fs::path link = fs::read_symlink(p, ec);
    if (ec) throw InputError(path, fmt::format("cannot read the symbolic link: {}", ec.message()));
    p = link.is_absolute() ? link : p.parent_path() / link;
  }
}

void WriteFileAtomically(const std::string& path, std::string_view content) {
  const fs::path target(ResolveOutputTarget(path));
  struct stat old {};
  const bool had_old = ::stat(target.c_str(), &old) == 0;

  SweepStaleTemporaries(target.parent_path(), target.filename().string());
  static std::atomic<unsigned> counter{0};
  std::string tmp;
  int fd = -1;
  for (int attempt = 0; attempt < 100 && fd < 0; ++attempt) {
    const std::string tmp_name = TemporaryPrefix(target.filename().string()) + std::to_string(counter++);
    tmp = (target.parent_path() / tmp_name).string();
    fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0 && errno != EEXIST) {
      throw InputError(path, fmt::format("cannot create temporary file '{}': {}", tmp, ErrnoText(errno)));
    }
  }
  if (fd < 0) throw InputError(path, fmt::format("cannot create a temporary file next to it"));
  PendingGuard pending{RegisterPending(tmp, 1)};

  FdGuard guard(fd);
  const auto fail = [&](const char* what, int err) {
    guard.Close();
    ::unlink(tmp.c_str());
    throw InputError(path, fmt::format("{}: {}", what, ErrnoText(err)));
  };
  if (had_old && ::fchmod(fd, old.st_mode & 07777) != 0) fail("cannot set the permissions", errno);
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
  // A file renamed into a staging directory stays registered until the
  // directory is committed, so an interrupted run leaves nothing behind.
  if (InPendingDirectory(target)) RegisterPending(target.string(), 1);
  BeforeRename();
  if (::rename(tmp.c_str(), target.c_str()) != 0) {
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

std::string MakeStagingDirectory(const std::string& dir) {
  fs::path d = fs::path(dir).lexically_normal();
  if (!d.has_filename()) d = d.parent_path();
  if (d.empty() || d == "." || d == "..") {
    d = fs::absolute(d).lexically_normal();
    if (!d.has_filename()) d = d.parent_path();
  }
  const fs::path parent = d.parent_path().empty() ? fs::path(".") : d.parent_path();
  SweepStaleTemporaries(parent, d.filename().string());
  std::string templ = (parent / (TemporaryPrefix(d.filename().string()) + "XXXXXX")).string();
  if (::mkdtemp(templ.data()) == nullptr) {
    throw InputError(dir, fmt::format("cannot create a temporary folder in '{}': {}", parent.string(), ErrnoText(errno)));
  }
  RegisterPending(templ, 2);
  return templ;
}

void CreateStagedFolder(const std::string& path) {
  std::error_code ec;
  const fs::path p(path);
  if (fs::is_directory(p, ec)) return;
  if (!p.parent_path().empty()) CreateStagedFolder(p.parent_path().string());
  if (!fs::create_directory(p, ec) && ec) throw InputError(path, "cannot create folder: " + ec.message());
  if (InPendingDirectory(p)) RegisterPending(p.string(), 2);
}

void DiscardStagingDirectory(const std::string& staging) noexcept {
  std::error_code ec;
  fs::remove_all(staging, ec);
  for (int i = 0; i < kMaxPending; ++i) {
    const int st = g_pending[i].state.load();
    if (st <= 0) continue;
    const std::string p = g_pending[i].path;
    if (p == staging || p.rfind(staging + "/", 0) == 0) Unregister(i);
  }
}

void CommitStagingDirectory(const std::string& staging, const std::string& dir, bool replace) {
  struct stat st {};
  const bool exists = ::lstat(dir.c_str(), &st) == 0;
  if (exists && !S_ISDIR(st.st_mode)) {
    DiscardStagingDirectory(staging);
    throw InputError(dir, S_ISLNK(st.st_mode) ? "refusing to replace a symbolic link with a folder"
                                              : "refusing to replace: it exists and is not a folder");
  }
  BeforeRename();
  if (::rename(staging.c_str(), dir.c_str()) == 0) {
    DiscardStagingDirectory(staging);  // only unregisters: the folder moved
    return;
  }
  const int err = errno;
  if ((err != ENOTEMPTY && err != EEXIST) || !replace) {
    DiscardStagingDirectory(staging);
    if (err == ENOTEMPTY || err == EEXIST) {
      throw InputError(dir, "refusing to write into a folder that is not empty (use --force to replace it)");
    }
    throw InputError(dir, fmt::format("cannot rename the finished folder into place: {}", ErrnoText(err)));
  }
  // Replace a non-empty folder: swap both in one step, then delete the old.
  if (::renameat2(AT_FDCWD, staging.c_str(), AT_FDCWD, dir.c_str(), RENAME_EXCHANGE) != 0) {
    const int e2 = errno;
    DiscardStagingDirectory(staging);
    throw InputError(dir, fmt::format("cannot replace the folder: {}", ErrnoText(e2)));
  }
  DiscardStagingDirectory(staging);  // now holds the old contents
}

void InstallTemporaryFileCleanup() {
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction sa {};
    sa.sa_handler = CleanupOnSignal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESETHAND;
    ::sigaction(sig, &sa, nullptr);
  }
}

}  // namespace umbmark::io
