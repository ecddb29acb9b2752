// Output safety for one command (see output_set.hpp).
#include "output/output_set.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <thread>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "output/atomic_write.hpp"

namespace umbmark::io {
namespace {

namespace fs = std::filesystem;

std::string Normalised(const std::string& path) {
  std::error_code ec;
  fs::path p = fs::weakly_canonical(fs::absolute(path), ec);
  if (ec) p = fs::absolute(path).lexically_normal();
  return p.string();
}

/// A path with a NUL byte names another file for the operating system (the
/// C string ends there): refused, naming the flag.
void RejectNul(const std::string& flag, const std::string& path) {
  if (path.find('\0') != std::string::npos)
    throw InvalidOptions(fmt::format("{}: the path contains a NUL byte; a file name cannot hold one", flag));
}

/// True when `inner` is `outer` or lies below it (both normalised).
bool Within(const std::string& inner, const std::string& outer) {
  if (inner == outer) return true;
  const std::string prefix = outer.back() == '/' ? outer : outer + "/";
  return inner.rfind(prefix, 0) == 0;
}

/// The folder holding the lock files ($TMPDIR/umbmark-locks, shared by all
/// users: sticky and world-writable like /tmp), or "" when it cannot be made.
std::string LockFolder() {
  std::error_code ec;
  const fs::path dir = fs::temp_directory_path(ec) / "umbmark-locks";
  if (ec) return "";
  if (::mkdir(dir.c_str(), 01777) == 0) ::chmod(dir.c_str(), 01777);  // umask would drop the bits
  struct stat st {};
  if (::stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) return "";
  return dir.string();
}

/// FNV-1a 64 of `s`, in hex: the lock file's name for an output path.
std::string HashName(const std::string& s) {
  std::uint64_t h = 14695981039346656037ull;
  for (const unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return fmt::format("{:016x}.lock", h);
}

}  // namespace

double LockWaitSeconds() {
  if (const char* v = std::getenv("UMBMARK_LOCK_WAIT_S")) {
    char* end = nullptr;
    const double s = std::strtod(v, &end);
    if (end != v && *end == '\0' && s >= 0.0 && s <= 1e6) return s;
  }
  return 60.0;
}

OutputSet::~OutputSet() {
  // Removed while still held, then released: a process waiting on the old
  // file finds it gone once it gets the lock and takes a fresh one (Lock), so
  // no lock file outlives its writer and no two writers hold "the" lock.
  for (const auto& l : locks_) {
    ::unlink(l.file.c_str());
    ::close(l.fd);
  }
}

void OutputSet::Lock(const std::string& flag, const std::string& path) {
  const std::string key = Normalised(path);
  for (const auto& held : locks_)
    if (held.key == key) return;
  const std::string folder = LockFolder();
  if (folder.empty()) return;  // no place for locks (read-only /tmp): write unlocked, as before
  const std::string file = (fs::path(folder) / HashName(key)).string();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(LockWaitSeconds());
  for (;;) {
    const int fd = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
    if (fd < 0) return;  // cannot lock here: write unlocked, as before
    ::fchmod(fd, 0666);  // another user's umbmark must be able to open it too
    bool locked = false;
    while (!locked) {
      if (::flock(fd, LOCK_EX | LOCK_NB) == 0) {
        locked = true;
      } else if (errno == EINTR) {
        continue;
      } else if (errno != EWOULDBLOCK) {
        ::close(fd);
        return;  // locking unsupported here: write unlocked
      } else if (std::chrono::steady_clock::now() >= deadline) {
        ::close(fd);
        throw InputError(path, fmt::format("{}: another umbmark process is writing this output (waited {:g} s for it "
                                           "to finish); run the two one after the other, or give each its own "
                                           "output (UMBMARK_LOCK_WAIT_S sets the wait)",
                                           flag, LockWaitSeconds()));
      } else {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
    }
    // The holder before us may have removed the file while we waited on it:
    // then our lock is on a file nobody else will open; take the new one.
    struct stat held {}, now {};
    if (::fstat(fd, &held) == 0 && ::stat(file.c_str(), &now) == 0 && held.st_dev == now.st_dev &&
        held.st_ino == now.st_ino) {
      locks_.push_back({key, file, fd});
      return;
    }
    ::close(fd);
  }
}

bool SameFile(const std::string& a, const std::string& b) {
  struct stat sa {}, sb {};
  const bool ea = ::stat(a.c_str(), &sa) == 0, eb = ::stat(b.c_str(), &sb) == 0;
  if (ea && eb) return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
  if (ea != eb) return false;
  return Normalised(a) == Normalised(b);
}

void OutputSet::AddInput(const std::string& path) {
  RejectNul("input", path);
  if (path.empty() || path == "-") return;
  inputs_.push_back({"input", path, path});
}

void OutputSet::AddManifestInputs(const std::string& manifest_path, const Manifest& manifest) {
  AddInput(manifest_path);
  for (const auto& e : manifest.experiments) AddInput(e.resolved_file);
}

void OutputSet::AddOutput(const std::string& flag, const std::string& path) {
  RejectNul(flag, path);
  if (path.empty()) return;
  outputs_.push_back({flag, path, path == "-" ? path : ResolveOutputTarget(path)});
}

void OutputSet::AddOutputDirectory(const std::string& flag, const std::string& dir,
                                   const std::vector<std::string>& files, bool force) {
  RejectNul(flag, dir);
  if (dir.empty()) throw InvalidOptions(fmt::format("{}: empty folder name", flag));
  const std::string abs = Normalised(dir);
  struct stat st {};
  if (::stat(dir.c_str(), &st) == 0) {
    if (!S_ISDIR(st.st_mode)) throw InputError(dir, fmt::format("{}: it exists and is not a folder", flag));
    if (!force && !fs::is_empty(dir)) {
      throw InvalidOptions(fmt::format("{} '{}': the folder is not empty; give an empty or new folder, or --force "
                                       "to replace the folder and everything in it",
                                       flag, dir));
    }
  }
  for (const auto& in : inputs_) {
    if (Within(Normalised(in.path), abs)) {
      throw InvalidOptions(fmt::format("{} '{}' contains the input '{}', which writing the folder would destroy; "
                                       "choose another folder",
                                       flag, dir, in.path));
    }
  }
  folders_.push_back({flag, dir, abs});
  for (const auto& f : files) outputs_.push_back({flag, (fs::path(dir) / f).string(), (fs::path(abs) / f).string()});
}

void OutputSet::CheckOutput(const Entry& out, std::size_t self) const {
  if (out.target == "-") {
    for (std::size_t i = 0; i < outputs_.size(); ++i) {
      if (i != self && outputs_[i].target == "-" && i < self) {
        throw InvalidOptions(fmt::format("{} - and {} - both ask for standard output; give one of them a file",
                                         outputs_[i].flag, out.flag));
      }
    }
    return;
  }
  for (const auto& in : inputs_) {
    if (SameFile(out.target, in.path)) {
      throw InvalidOptions(fmt::format("{} '{}' is the input file '{}'; writing it would destroy the input. "
                                       "Choose another output name",
                                       out.flag, out.path, in.path));
    }
  }
  for (std::size_t i = 0; i < outputs_.size(); ++i) {
    if (i == self || outputs_[i].target == "-") continue;
    if (SameFile(out.target, outputs_[i].target) && i < self) {
      throw InvalidOptions(fmt::format("{} '{}' and {} '{}' name the same file; one output would be lost",
                                       outputs_[i].flag, outputs_[i].path, out.flag, out.path));
    }
  }
  for (const auto& f : folders_) {
    if (f.flag == out.flag) continue;
    if (Within(Normalised(out.target), f.absolute)) {
      throw InvalidOptions(fmt::format("{} '{}' lies inside the output folder {} '{}', which is replaced as a whole; "
                                       "write it elsewhere",
                                       out.flag, out.path, f.flag, f.path));
    }
  }
}

void OutputSet::Check() {
  for (std::size_t i = 0; i < outputs_.size(); ++i) CheckOutput(outputs_[i], i);
  // Writer locks in one global order (sorted keys), so two processes that
  // share several outputs cannot each hold one the other waits for.
  std::vector<std::pair<std::string, std::string>> order;  // key, flag
  for (const auto& f : folders_) order.emplace_back(f.absolute, f.flag);
  for (const auto& o : outputs_)
    if (o.target != "-") order.emplace_back(Normalised(o.target), o.flag);
  std::sort(order.begin(), order.end());
  for (const auto& [key, flag] : order) Lock(flag, key);
}

void OutputSet::Write(const std::string& path, std::string_view content) {
  if (path == "-") {
    std::fwrite(content.data(), 1, content.size(), stdout);
    std::fflush(stdout);
    return;
  }
  const std::string target = ResolveOutputTarget(path);
  for (const auto& in : inputs_) {
    if (SameFile(target, in.path)) {
      throw InvalidOptions(fmt::format("output '{}' is the input file '{}'; writing it would destroy the input. "
                                       "Choose another output name",
                                       path, in.path));
    }
  }
  for (const auto& w : written_) {
    if (SameFile(target, w)) {
      throw InvalidOptions(fmt::format("output '{}' was already written by this command ('{}'); one output would be "
                                       "lost",
                                       path, w));
    }
  }
  Lock("output", target);  // an output named only now (batch names)
  WriteFileAtomically(path, content);
  written_.push_back(target);
}

}  // namespace umbmark::io
