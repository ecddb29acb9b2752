// Output safety end to end (the real executable): outputs that resolve to an
// input or to another output are refused before anything is written,
// symbolic links are written through (never replaced), device paths are
// refused, stdout write errors fail, `simulate` replaces its folder as a
// whole, and fault injection (UMBMARK_TEST_KILL_AT_RENAME) at every rename
// of `simulate` and `calibrate --json/--ros2/--plot` leaves every output
// complete old or complete new, with no temporary file behind.
#include <catch2/catch.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "output/output_set.hpp"
#include "support/run_cli.hpp"

namespace fs = std::filesystem;
using umbmark::testing::Q;
using umbmark::testing::RunCli;
using umbmark::testing::Slurp;

namespace {

const fs::path kExamples = fs::path(UMBMARK_SOURCE_DIR) / "data" / "examples";

/// Every regular file below `dir` (relative path -> content).
std::map<std::string, std::string> Tree(const fs::path& dir) {
  std::map<std::string, std::string> out;
  if (!fs::exists(dir)) return out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) out[fs::relative(e.path(), dir).string()] = Slurp(e.path().string());
  return out;
}

/// Names in `dir` (not recursive) that look like our temporaries.
int Temporaries(const fs::path& dir) {
  int n = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.path().filename().string().find(".tmp.") != std::string::npos) ++n;
  return n;
}

void Write(const fs::path& p, const std::string& s) { std::ofstream(p, std::ios::binary) << s; }

/// Sets an environment variable for the scope (the child inherits it).
struct ScopedEnv {
  std::string name;
  ScopedEnv(std::string n, const std::string& v) : name(std::move(n)) { ::setenv(name.c_str(), v.c_str(), 1); }
  ~ScopedEnv() { ::unsetenv(name.c_str()); }
};

fs::path CopyExamples(const std::string& tag) {
  const fs::path dir = umbmark::testing::TempDir(tag);
  fs::copy_file(kExamples / "endpoints.csv", dir / "endpoints.csv");
  fs::copy_file(kExamples / "robot.toml", dir / "robot.toml");
  return dir;
}

std::string Calibrate(const fs::path& dir, const std::string& extra) {
  return "calibrate " + Q(dir / "endpoints.csv") + " --robot " + Q(dir / "robot.toml") + " --side 4 " + extra;
}

}  // namespace

TEST_CASE("outputs that are inputs or each other are refused before writing", "[safety][cli]") {
  const fs::path dir = CopyExamples("outsafe");
  const auto before = Tree(dir);
  struct Case {
    std::string extra, message;
  };
  fs::create_symlink("endpoints.csv", dir / "link.json");
  const Case cases[] = {
      {"--json " + Q(dir / "endpoints.csv"), "is the input file"},
      {"--plot " + Q(dir / "robot.toml"), "is the input file"},
      {"--ros2 " + Q(dir / "o.json") + " --json " + Q(dir / "o.json"), "name the same file"},
      {"--ros2 " + Q(dir / "o.yaml") + " --plot " + Q(dir / "." / "o.yaml"), "name the same file"},
      {"--json " + Q(dir / "link.json"), "is the input file"},
  };
  for (const auto& c : cases) {
    INFO(c.extra);
    const auto r = RunCli(Calibrate(dir, c.extra));
    CHECK(r.status == 2);
    CHECK_THAT(r.err, Catch::Contains(c.message));
    CHECK(r.out.empty());  // nothing computed or printed before the refusal
  }
  auto after = Tree(dir);
  after.erase("link.json");  // the symlink itself reads as endpoints.csv
  CHECK(after == before);
  CHECK(fs::is_symlink(dir / "link.json"));
}

TEST_CASE("a symbolic link output is written through, devices are refused", "[safety][cli]") {
  const fs::path dir = CopyExamples("outlink");
  Write(dir / "real.json", "old\n");
  fs::create_symlink("real.json", dir / "link.json");
  auto r = RunCli(Calibrate(dir, "--json " + Q(dir / "link.json")));
  REQUIRE(r.status == 0);
  CHECK(fs::is_symlink(dir / "link.json"));
  CHECK_THAT(Slurp((dir / "real.json").string()), Catch::Contains("\"E_d\""));
  // A dangling link creates its target.
  fs::create_symlink("new.svg", dir / "dangling.svg");
  r = RunCli(Calibrate(dir, "--plot " + Q(dir / "dangling.svg")));
  REQUIRE(r.status == 0);
  CHECK(fs::is_symlink(dir / "dangling.svg"));
  CHECK_THAT(Slurp((dir / "new.svg").string()), Catch::Contains("</svg>"));

  r = RunCli(Calibrate(dir, "--json /dev/stdout"));
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Catch::Contains("use '-' for standard output"));
  fs::create_symlink("/dev/null", dir / "null.json");
  r = RunCli(Calibrate(dir, "--json " + Q(dir / "null.json")));
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Catch::Contains("not a regular file"));
  CHECK(fs::is_symlink(dir / "null.json"));
  // stdout that cannot be written is a failure.
  for (const char* extra : {"", "--json -"}) {
    const std::string cmd = std::string("'") + UMBMARK_EXE + "' " + Calibrate(dir, extra) + " >/dev/full 2>/dev/null";
    const int raw = std::system(cmd.c_str());
    CHECK((WIFEXITED(raw) && WEXITSTATUS(raw) == 1));
  }
  CHECK(Temporaries(dir) == 0);
}

TEST_CASE("simulate replaces its folder as a whole and never an input", "[safety][simulate][cli]") {
  const fs::path dir = umbmark::testing::TempDir("simsafe");
  Write(dir / "m.toml",
        "[robot]\nwheelbase_m = 0.3\nwheel_diameter_left_m = 0.08\nwheel_diameter_right_m = 0.08\n"
        "ticks_per_rev = 2000\n\n[[experiment]]\nkind = \"square\"\nside_m = 1.0\nfile = \"sq.csv\"\n\n"
        "[[experiment]]\nkind = \"back_and_forth\"\ndistance_m = 1.0\nfile = \"sub/bf.csv\"\n");
  const std::string sim = "simulate " + Q(dir / "m.toml") + " --square-runs 2 --back-and-forth-runs 2 ";
  // Into the folder of its own manifest: refused even with --force.
  auto r = RunCli(sim + "--out " + Q(dir) + " --force");
  CHECK(r.status == 2);
  CHECK_THAT(r.err, Catch::Contains("contains the input"));
  r = RunCli(sim + "--out " + Q(dir / "out") + " --seed 3");
  REQUIRE(r.status == 0);
  const auto old_tree = Tree(dir / "out");
  REQUIRE(old_tree.size() == 4);  // campaign.toml, sq.csv, sub/bf.csv, truth.json
  r = RunCli(sim + "--out " + Q(dir / "out") + " --seed 4");
  CHECK(r.status == 2);
  CHECK_THAT(r.err, Catch::Contains("not empty"));
  CHECK(Tree(dir / "out") == old_tree);
  // Default ground truth carries motion-capture noise, stated in the manifest.
  CHECK_THAT(old_tree.at("campaign.toml"), Catch::Contains("sigma_xy_m = 0.0003"));
  // Size bound: refused before any memory is taken.
  r = RunCli(sim + "--out " + Q(dir / "big") + " --speed 1e-9");
  CHECK(r.status == 2);
  CHECK_THAT(r.err, Catch::Contains("samples"));
  CHECK_FALSE(fs::exists(dir / "big"));
  CHECK(Temporaries(dir) == 0);
}

TEST_CASE("fault injection: simulate killed at every rename", "[safety][simulate][cli][fault]") {
  const fs::path dir = umbmark::testing::TempDir("simfault");
  Write(dir / "m.toml",
        "[robot]\nwheelbase_m = 0.3\nwheel_diameter_left_m = 0.08\nwheel_diameter_right_m = 0.08\n"
        "ticks_per_rev = 2000\n\n[[experiment]]\nkind = \"square\"\nside_m = 1.0\nfile = \"sq.csv\"\n\n"
        "[[experiment]]\nkind = \"back_and_forth\"\ndistance_m = 1.0\nfile = \"sub/bf.csv\"\n");
  const std::string sim = "simulate " + Q(dir / "m.toml") + " --square-runs 2 --back-and-forth-runs 2 --force ";
  REQUIRE(RunCli(sim + "--out " + Q(dir / "new") + " --seed 4").status == 0);
  const auto new_tree = Tree(dir / "new");
  REQUIRE(RunCli(sim + "--out " + Q(dir / "out") + " --seed 3").status == 0);
  const auto old_tree = Tree(dir / "out");
  REQUIRE(old_tree != new_tree);
  // 4 files + the folder = 5 renames; 6 and later: the run completes.
  for (const char* sig : {"TERM", "INT", "KILL"}) {
    for (int n = 1; n <= 6; ++n) {
      INFO(sig << " at rename " << n);
      ScopedEnv kill_at("UMBMARK_TEST_KILL_AT_RENAME", std::to_string(n));
      ScopedEnv kill_sig("UMBMARK_TEST_KILL_SIGNAL", sig);
      const auto r = RunCli(sim + "--out " + Q(dir / "out") + " --seed 4");
      const auto tree = Tree(dir / "out");
      CHECK((tree == old_tree || tree == new_tree));
      if (n <= 5) CHECK(r.status >= 128);
      if (n == 6) CHECK(tree == new_tree);
      // SIGKILL cannot be caught: its temporaries stay (.NAME.tmp.PID.HOST.*)
      // until the next run that writes the same output (tested below).
      if (std::string(sig) != "KILL") CHECK(Temporaries(dir) == 0);
      if (n == 6) {
        ::unsetenv("UMBMARK_TEST_KILL_AT_RENAME");
        REQUIRE(RunCli(sim + "--out " + Q(dir / "out") + " --seed 3").status == 0);
      }
    }
  }
}

TEST_CASE("fault injection: calibrate --json --ros2 --plot killed at every rename", "[safety][cli][fault]") {
  const fs::path dir = CopyExamples("calfault");
  const std::string outs =
      "--json " + Q(dir / "o.json") + " --ros2 " + Q(dir / "o.yaml") + " --plot " + Q(dir / "o.svg") + " ";
  REQUIRE(RunCli(Calibrate(dir, outs + "--estimator x")).status == 0);
  const std::map<std::string, std::string> old_files = {{"o.json", Slurp((dir / "o.json").string())},
                                                        {"o.yaml", Slurp((dir / "o.yaml").string())},
                                                        {"o.svg", Slurp((dir / "o.svg").string())}};
  REQUIRE(RunCli(Calibrate(dir, outs + "--estimator y")).status == 0);
  std::map<std::string, std::string> new_files;
  for (const auto& [name, text] : old_files) new_files[name] = Slurp((dir / name).string());
  REQUIRE(new_files.at("o.json") != old_files.at("o.json"));
  for (int n = 1; n <= 4; ++n) {
    INFO("SIGTERM at rename " << n);
    REQUIRE(RunCli(Calibrate(dir, outs + "--estimator x")).status == 0);
    ScopedEnv kill_at("UMBMARK_TEST_KILL_AT_RENAME", std::to_string(n));
    const auto r = RunCli(Calibrate(dir, outs + "--estimator y"));
    CHECK(r.status == (n <= 3 ? 128 + 15 : 0));
    for (const auto& [name, text] : old_files) {
      const std::string now = Slurp((dir / name).string());
      CHECK((now == text || now == new_files.at(name)));
    }
    CHECK(Temporaries(dir) == 0);
  }
}

namespace {

/// Names (not recursive) in `dir` that look like our temporaries.
std::vector<std::string> TemporaryNames(const fs::path& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().find(".tmp.") != std::string::npos) out.push_back(e.path().filename().string());
  return out;
}

/// A PID that no longer runs: a child that has exited and been reaped.
long DeadPid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  return child;
}

/// `name` (".NAME.tmp.PID.HOST.SUFFIX") with its PID or HOST field replaced.
std::string WithField(const std::string& name, const std::string& head, int field, const std::string& value) {
  std::string rest = name.substr(head.size());
  const auto dot1 = rest.find('.'), dot2 = rest.find('.', dot1 + 1);
  if (field == 0) return head + value + rest.substr(dot1);
  return head + rest.substr(0, dot1 + 1) + value + rest.substr(dot2);
}

}  // namespace

TEST_CASE("SIGKILL leaves temporaries; the next write of the same output deletes them", "[safety][cli][fault]") {
  SECTION("calibrate --json: a file") {
    const fs::path dir = CopyExamples("sweepfile");
    const std::string cmd = Calibrate(dir, "--json " + Q(dir / "o.json"));
    {
      ScopedEnv kill_at("UMBMARK_TEST_KILL_AT_RENAME", "1");
      ScopedEnv kill_sig("UMBMARK_TEST_KILL_SIGNAL", "KILL");
      CHECK(RunCli(cmd).status == 128 + 9);
    }
    const auto left = TemporaryNames(dir);
    REQUIRE(left.size() == 1);  // ".o.json.tmp.PID.HOST.N"
    const std::string head = ".o.json.tmp.";
    REQUIRE(left[0].rfind(head, 0) == 0);
    // Temporaries that must stay: a live process's (this test's PID) and a
    // dead PID of another host (its PID means nothing here).
    const std::string live = WithField(left[0], head, 0, std::to_string(::getpid()));
    const std::string other_host = WithField(WithField(left[0], head, 1, "otherhost"), head, 0, std::to_string(DeadPid()));
    const std::string dead_here = WithField(left[0], head, 0, std::to_string(DeadPid()));
    Write(dir / live, "x");
    Write(dir / other_host, "x");
    Write(dir / dead_here, "x");
    Write(dir / ".endpoints.csv.tmp.1.x.1", "another output's temporary");
    REQUIRE(RunCli(cmd).status == 0);
    CHECK(fs::exists(dir / "o.json"));
    CHECK_FALSE(fs::exists(dir / left[0]));
    CHECK_FALSE(fs::exists(dir / dead_here));
    CHECK(fs::exists(dir / live));
    CHECK(fs::exists(dir / other_host));
    CHECK(fs::exists(dir / ".endpoints.csv.tmp.1.x.1"));
  }
  SECTION("simulate --out: the staging folder") {
    const fs::path dir = umbmark::testing::TempDir("sweepdir");
    Write(dir / "m.toml",
          "[robot]\nwheelbase_m = 0.3\nwheel_diameter_left_m = 0.08\nwheel_diameter_right_m = 0.08\n"
          "ticks_per_rev = 2000\n\n[[experiment]]\nkind = \"square\"\nside_m = 1.0\nfile = \"sq.csv\"\n");
    const std::string sim = "simulate " + Q(dir / "m.toml") + " --square-runs 2 --out " + Q(dir / "out");
    {
      ScopedEnv kill_at("UMBMARK_TEST_KILL_AT_RENAME", "2");
      ScopedEnv kill_sig("UMBMARK_TEST_KILL_SIGNAL", "KILL");
      CHECK(RunCli(sim).status == 128 + 9);
    }
    REQUIRE(TemporaryNames(dir).size() == 1);  // ".out.tmp.PID.HOST.XXXXXX/" with files inside
    CHECK_FALSE(fs::exists(dir / "out"));
    REQUIRE(RunCli(sim).status == 0);
    CHECK(TemporaryNames(dir).empty());
    CHECK(Temporaries(dir) == 0);
    CHECK(fs::exists(dir / "out" / "sq.csv"));
  }
}

// One writer per output set (issue 23): two calibrates with different robot
// files writing the same --json and --ros2 at once must leave both files
// from the same run (before the lock: 6 of 40 trials mixed them); a writer
// that cannot get the lock within UMBMARK_LOCK_WAIT_S exits 1 naming the
// output, and gets it once the holder is gone.
TEST_CASE("concurrent writers of the same outputs run one after the other", "[safety][cli][lock]") {
  const fs::path dir = CopyExamples("lock");
  Write(dir / "other.toml", "wheelbase_m = 0.21\nwheel_diameter_left_m = 0.084\nwheel_diameter_right_m = 0.084\n"
                            "ticks_per_rev = 2796.8\n");  // robot.toml has 0.2: the wheelbase tells the runs apart
  const auto calibrate = [&](const char* robot) {
    return "'" + std::string(UMBMARK_EXE) + "' calibrate " + Q(dir / "endpoints.csv") + " --robot " + Q(dir / robot) +
           " --side 4 --json " + Q(dir / "o.json") + " --ros2 " + Q(dir / "o.yaml") + " >/dev/null 2>&1";
  };
  const std::string both = "(" + calibrate("robot.toml") + " & " + calibrate("other.toml") + " & wait)";
  for (int trial = 0; trial < 12; ++trial) {
    INFO("trial " << trial);
    REQUIRE(std::system(both.c_str()) == 0);
    const std::string json = Slurp((dir / "o.json").string()), yaml = Slurp((dir / "o.yaml").string());
    const bool json_b = nlohmann::json::parse(json)["recorded_parameters"]["wheelbase_m"].get<double>() == 0.21;
    const bool yaml_b = yaml.find("wheel_separation: 0.21 ") != std::string::npos;
    CHECK(json_b == yaml_b);
  }
  CHECK(Temporaries(dir) == 0);
}

TEST_CASE("a writer waits for the lock, then gives up with a clear message", "[safety][cli][lock]") {
  const fs::path dir = CopyExamples("lockwait");
  const std::string cmd = "calibrate " + Q(dir / "endpoints.csv") + " --robot " + Q(dir / "robot.toml") +
                          " --side 4 --json " + Q(dir / "o.json");
  ScopedEnv wait("UMBMARK_LOCK_WAIT_S", "0.3");
  {
    umbmark::io::OutputSet holder;  // another writer of o.json, in this process
    holder.AddOutput("--json", (dir / "o.json").string());
    holder.Check();
    const auto r = RunCli(cmd);
    CHECK(r.status == 1);
    CHECK_THAT(r.err, Catch::Contains("o.json") && Catch::Contains("another umbmark process is writing this output"));
    CHECK_FALSE(fs::exists(dir / "o.json"));
  }
  CHECK(RunCli(cmd).status == 0);  // the holder is gone
  CHECK(fs::exists(dir / "o.json"));
}
