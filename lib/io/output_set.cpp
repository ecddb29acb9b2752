// Output safety for one command (see output_set.hpp).
#include "io/output_set.hpp"

#include <sys/stat.h>

#include <cstdio>
#include <filesystem>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "io/atomic_write.hpp"

namespace umbmark::io {
namespace {

namespace fs = std::filesystem;

std::string Normalised(const std::string& path) {
  std::error_code ec;
  fs::path p = fs::weakly_canonical(fs::absolute(path), ec);
  if (ec) p = fs::absolute(path).lexically_normal();
  return p.string();
}

/// True when `inner` is `outer` or lies below it (both normalised).
bool Within(const std::string& inner, const std::string& outer) {
  if (inner == outer) return true;
  const std::string prefix = outer.back() == '/' ? outer : outer + "/";
  return inner.rfind(prefix, 0) == 0;
}

}  // namespace

bool SameFile(const std::string& a, const std::string& b) {
  struct stat sa {}, sb {};
  const bool ea = ::stat(a.c_str(), &sa) == 0, eb = ::stat(b.c_str(), &sb) == 0;
  if (ea && eb) return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
  if (ea != eb) return false;
  return Normalised(a) == Normalised(b);
}

void OutputSet::AddInput(const std::string& path) {
  if (path.empty() || path == "-") return;
  inputs_.push_back({"input", path, path});
}

void OutputSet::AddManifestInputs(const std::string& manifest_path, const Manifest& manifest) {
  AddInput(manifest_path);
  for (const auto& e : manifest.experiments) AddInput(e.resolved_file);
}

void OutputSet::AddOutput(const std::string& flag, const std::string& path) {
  if (path.empty()) return;
  outputs_.push_back({flag, path, path == "-" ? path : ResolveOutputTarget(path)});
}

void OutputSet::AddOutputDirectory(const std::string& flag, const std::string& dir,
                                   const std::vector<std::string>& files, bool force) {
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

void OutputSet::Check() const {
  for (std::size_t i = 0; i < outputs_.size(); ++i) CheckOutput(outputs_[i], i);
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
  WriteFileAtomically(path, content);
  written_.push_back(target);
}

}  // namespace umbmark::io
