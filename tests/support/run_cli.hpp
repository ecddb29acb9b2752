// Runs the built `umbmark` executable from a test and captures its exit
// status, stdout and stderr (through temporary files).
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

namespace umbmark::testing {

struct CliResult {
  int status = -1;
  std::string out, err;
};

inline std::string Slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

/// The temporary directories this test process made, removed when it ends
/// (set UMBMARK_KEEP_TEST_DIRS=1 to keep them for a look after a failure).
struct TempDirRegistry {
  std::vector<std::filesystem::path> dirs;
  TempDirRegistry() = default;
  TempDirRegistry(const TempDirRegistry&) = delete;
  TempDirRegistry& operator=(const TempDirRegistry&) = delete;
  ~TempDirRegistry() {
    if (std::getenv("UMBMARK_KEEP_TEST_DIRS") != nullptr) return;
    std::error_code ec;
    for (const auto& d : dirs) std::filesystem::remove_all(d, ec);
  }
};

/// A fresh temporary directory under the system temp path, unique per call.
inline std::filesystem::path TempDir(const std::string& tag) {
  static int counter = 0;
  static TempDirRegistry registry;
  auto dir = std::filesystem::temp_directory_path() /
             ("umbmark-test-" + tag + "-" + std::to_string(::getpid()) + "-" + std::to_string(++counter));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  registry.dirs.push_back(dir);
  return dir;
}

/// Runs `umbmark ARGS` (ARGS is passed to /bin/sh, quote paths yourself),
/// in the working directory `cwd` when given.
inline CliResult RunCliIn(const std::filesystem::path& cwd, const std::string& args) {
  static const auto dir = TempDir("cli");
  const std::string out = (dir / "stdout").string(), err = (dir / "stderr").string();
  const std::string cd = cwd.empty() ? std::string() : "cd '" + cwd.string() + "' && ";
  const std::string cmd = cd + "'" + UMBMARK_EXE + "' " + args + " </dev/null >'" + out + "' 2>'" + err + "'";
  const int raw = std::system(cmd.c_str());
  CliResult r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + (WIFSIGNALED(raw) ? WTERMSIG(raw) : 0);
  r.out = Slurp(out);
  r.err = Slurp(err);
  return r;
}

inline CliResult RunCli(const std::string& args) { return RunCliIn({}, args); }

inline std::string Q(const std::filesystem::path& p) { return "'" + p.string() + "'"; }

}  // namespace umbmark::testing
