// Hostile-input corpus for the whole executable: every case of issue 9 (and
// more) with its expected exit status and a substring of its message. Every
// case also checks that the inputs are unchanged (hash of every file in the
// case's folder before and after, minus the outputs it is meant to write),
// that it ends within a time bound (coreutils `timeout`), that no temporary
// file remains, and, over the whole corpus, that no child process grew
// beyond a memory bound (getrusage of the children's peak RSS).
#include <catch2/catch.hpp>

#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/utf8.hpp"
#include "support/run_cli.hpp"

namespace fs = std::filesystem;
using umbmark::testing::Slurp;

namespace {

const fs::path kSource = fs::path(UMBMARK_SOURCE_DIR);
constexpr int kTimeoutSeconds = 120;  // generous: the machine is shared; a hang is caught, not a slow run
constexpr long kMaxRssKb = 2L * 1024 * 1024;

void Put(const fs::path& p, const std::string& s) {
  fs::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << s;
}

std::map<std::string, std::size_t> Hashes(const fs::path& dir) {
  std::map<std::string, std::size_t> out;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (fs::is_symlink(e.path()) || !e.is_regular_file()) continue;
    out[fs::relative(e.path(), dir).string()] = std::hash<std::string>{}(Slurp(e.path().string()));
  }
  return out;
}

struct Run {
  int status = -1;
  std::string out, err;
};

Run Exec(const fs::path& dir, const std::string& args) {
  const std::string cmd = "cd '" + dir.string() + "' && timeout " + std::to_string(kTimeoutSeconds) + " '" +
                          UMBMARK_EXE + "' " + args + " </dev/null >.stdout 2>.stderr";
  const int raw = std::system(cmd.c_str());
  Run r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + (WIFSIGNALED(raw) ? WTERMSIG(raw) : 0);
  r.out = Slurp((dir / ".stdout").string());
  r.err = Slurp((dir / ".stderr").string());
  fs::remove(dir / ".stdout");
  fs::remove(dir / ".stderr");
  return r;
}

const std::string kRobot =
    "wheelbase_m = 0.340\nwheel_diameter_left_m = 0.1524\nwheel_diameter_right_m = 0.1524\nticks_per_rev = 2048\n";
const std::string kEndpoints = Slurp((kSource / "data/examples/endpoints.csv").string());
const std::string kExampleRobot = Slurp((kSource / "data/examples/robot.toml").string());
const std::string kManifest =
    "[robot]\nwheelbase_m = 0.3\nwheel_diameter_left_m = 0.08\nwheel_diameter_right_m = 0.08\nticks_per_rev = 2000\n\n"
    "[[experiment]]\nkind = \"square\"\nside_m = 1.0\nfile = \"sq.csv\"\n";

/// Endpoint rows scaled by `k` (k = 1000: millimetres written as metres).
std::string ScaledEndpoints(double k) {
  std::string out = "run,direction,ex_m,ey_m,etheta_rad\n";
  std::istringstream in(kEndpoints);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line.rfind("run", 0) == 0) continue;
    std::vector<std::string> c;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) c.push_back(cell);
    out += c[0] + "," + c[1] + "," + std::to_string(std::stod(c[2]) * k) + "," + std::to_string(std::stod(c[3]) * k) +
           "," + (c.size() > 4 ? c[4] : "") + "\n";
  }
  return out;
}

/// A trajectory CSV (wheel travel, ground truth) of `runs` straight 1 m
/// runs of 11 samples; `moves`: the wheels and the truth advance; `gt_moves`:
/// the truth advances; `gt_every`: ground truth at every k-th sample (and
/// the last); `same`: every run identical (else each ends 1 mm further).
std::string Trajectories(int runs, bool moves, bool gt_moves, int gt_every, bool same) {
  std::string out = "run,direction,t_s,dist_left_m,dist_right_m,x_gt_m,y_gt_m,theta_gt_rad\n";
  for (int r = 0; r < runs; ++r) {
    for (int i = 0; i <= 10; ++i) {
      const double s = moves ? 0.1 * i : 0.0;
      const double x = gt_moves ? 0.1 * i * (same ? 1.0 : 1.0 + 0.001 * r) : 0.0;
      out += fmt::format("{},fwd,{},{},{},", r + 1, 0.1 * i, s, s);
      out += (i % gt_every == 0 || i == 10) ? fmt::format("{},0,0\n", x) : ",,\n";
    }
  }
  return out;
}

std::string Repeated(const std::string& cw, const std::string& ccw, int n) {
  std::string out = "run,direction,ex_m,ey_m,etheta_rad\n";
  for (int i = 0; i < n; ++i) out += std::to_string(2 * i + 1) + ",cw," + cw + "\n" + std::to_string(2 * i + 2) + ",ccw," + ccw + "\n";
  return out;
}

struct Case {
  std::string name;
  std::function<void(const fs::path&)> setup;
  std::string args;
  int status;
  std::string message;                 ///< substring of stderr (or of stdout for status 0)
  std::set<std::string> outputs = {};  ///< files the case may create or change
  std::function<void(const Run&, const fs::path&)> extra = nullptr;
};

/// `s` with bytes outside printable ASCII as \\xNN (case names).
std::string EscapeForName(const std::string& s) {
  std::string out;
  for (const unsigned char ch : s) out += ch >= 0x20 && ch < 0x7F ? std::string(1, static_cast<char>(ch)) : fmt::format("\\x{:02X}", ch);
  return out;
}

void Examples(const fs::path& d) {
  Put(d / "ep.csv", kEndpoints);
  Put(d / "robot.toml", kExampleRobot);
}

/// A calibrate JSON of one robot: corrected and recorded parameters.
std::string CalJson(double b, double dl, double dr, double rec_b, double e_b) {
  return nlohmann::json{{"E_d", dr / dl},
                        {"E_b", e_b},
                        {"E_max_syst_m", 0.01},
                        {"parameters", {{"wheelbase_m", b}, {"wheel_diameter_left_m", dl}, {"wheel_diameter_right_m", dr}}},
                        {"recorded_parameters",
                         {{"wheelbase_m", rec_b}, {"wheel_diameter_left_m", 0.084}, {"wheel_diameter_right_m", 0.084}}}}
      .dump();
}

/// The OptiOdom square dataset 230620202042 copied to `dst`.
void CopyOptiOdom(const fs::path& dst) {
  const fs::path src = kSource / "data/optiodom-2020-06/square/230620202042";
  fs::create_directories(dst);
  for (const auto& e : fs::directory_iterator(src)) fs::copy_file(e.path(), dst / e.path().filename());
}

/// Issue 23: the three failing cases of the withheld corpus and their
/// siblings (other commands, other numeric cells and options, other writers).
void AddIssue23Cases(std::vector<Case>& c) {
  const std::string cal = "calibrate ep.csv --robot robot.toml --side 4 ";
  auto endpoint_cell = [](const std::string& from, const std::string& to) {
    return [from, to](const fs::path& d) {
      Examples(d);
      std::string text = kEndpoints;
      const auto at = text.find(from);
      REQUIRE(at != std::string::npos);
      text.replace(at, from.size(), to);
      Put(d / "ep.csv", text);
    };
  };
  c.push_back({"1e308 in an endpoint CSV", endpoint_cell("1,cw,-0.009925,", "1,cw,1e308,"), cal + "--json -", 1,
               "ep.csv:5:6: ex_m: '1e308' is beyond any measured value"});
  c.push_back({"-1e300 in an endpoint CSV's heading", endpoint_cell(",0.031601\n", ",-1e300\n"), cal, 1,
               "etheta_rad: '-1e300' is beyond any measured value"});
  c.push_back({"a 16-digit plain length in an endpoint CSV", endpoint_cell("1,cw,-0.009925,", "1,cw,1000000000000000,"),
               cal, 1, "beyond any measured value"});
  c.push_back({"1e308 ground truth in a trajectory CSV",
               [](const fs::path& d) {
                 Examples(d);
                 std::string t = Trajectories(3, true, true, 1, false);
                 const std::string row = "\n2,fwd,0.5,0.5,0.5,";
                 const auto at = t.find(row);
                 REQUIRE(at != std::string::npos);
                 const auto cell = at + row.size();
                 t.replace(cell, t.find(',', cell) - cell, "1e308");
                 Put(d / "tr.csv", t);
               },
               "evaluate tr.csv --robot robot.toml --json -", 1, "x_gt_m: '1e308' is beyond any measured value"});
  c.push_back({"1e308 wheelbase in --params JSON", [](const fs::path& d) {
                 Examples(d);
                 Put(d / "cal.json", "{\"parameters\": {\"wheelbase_m\": 1e308, \"wheel_diameter_left_m\": 0.15, "
                                     "\"wheel_diameter_right_m\": 0.15}}");
                 Put(d / "tr.csv", Trajectories(3, true, true, 1, false));
               },
               "evaluate tr.csv --robot robot.toml --params cal.json", 1, "cal.json: parameters: wheelbase_m = 1e+308"});
  // Negative and absurd numeric options of import (rejected before anything is read).
  const std::string bag = "import rosbag2 " + (kSource / "tests/data/rosbag2/run1_head_unchunked.mcap").string() +
                          " --out o --robot " + (kSource / "tests/data/rosbag2/robot.toml").string() +
                          " --wheels /joint_states ";
  for (const char* bad : {"--side -1", "--side=-1", "--side -0", "--side nan", "--side 1e308"})
    c.push_back({fmt::format("import {}", bad), [](const fs::path&) {}, bag + "--experiment square " + bad, 2, "side"});
  c.push_back({"import --distance -3", [](const fs::path&) {}, bag + "--experiment back_and_forth --distance -3", 2,
               "distance"});
  c.push_back({"import --pause -1", [](const fs::path&) {}, bag + "--experiment free --pause -1", 2, "pause"});
  c.push_back({"import --max-gt-gap -0.1", [](const fs::path&) {}, bag + "--experiment free --max-gt-gap -0.1", 2,
               "max-gt-gap"});
  // The side (and robot) an OptiOdom metadata file gives: refused at the cell, never written.
  for (const auto& [from, to, what] : {std::tuple{"\nL,0.75,", "\nL,-0.75,", "L: side_m = -0.75"},
                                       std::tuple{"\nLi,0.2,", "\nLi,200,", "Li: wheelbase_m = 200"},
                                       std::tuple{"\nDi,0.084,", "\nDi,-0.084,", "Di: wheel_diameter_right_m"}}) {
    c.push_back({fmt::format("import optiodom: metadata {}", to + 1),
                 [from = std::string(from), to = std::string(to)](const fs::path& d) {
                   const fs::path dst = d / "square" / "230620202042";
                   CopyOptiOdom(dst);
                   std::string meta = Slurp((dst / "230620202042_metadata.csv").string());
                   const auto at = meta.find(from);
                   REQUIRE(at != std::string::npos);
                   meta.replace(at, from.size(), to);
                   Put(dst / "230620202042_metadata.csv", meta);
                 },
                 "import optiodom square/230620202042 --out imp", 1, std::string("230620202042_metadata.csv:") ,
                 {}, [what = std::string(what)](const Run& r, const fs::path& d) {
                   CHECK_THAT(r.err, Catch::Contains(what) && Catch::Contains("outside the plausible range"));
                   CHECK_FALSE(fs::exists(d / "imp"));
                 }});
  }
  // A non-UTF-8 (and a newline in a) folder name of a recording: written
  // escaped into the comments, the outputs stay valid UTF-8 and read back.
  for (const std::string& parent : {std::string("lab\xff\xfe"), std::string("lab\nrobot = 1")}) {
    c.push_back({"import rosbag2 from a folder named " + EscapeForName(parent),
                 [parent](const fs::path& d) {
                   fs::create_directories(d / parent);
                   fs::copy_file(kSource / "tests/data/rosbag2/run1_head_unchunked.mcap", d / parent / "run1.mcap");
                 },
                 "import rosbag2 '" + parent + "/run1.mcap' --out imp --robot " +
                     (kSource / "tests/data/rosbag2/robot.toml").string() +
                     " --wheels /joint_states --ground-truth /mocap/pose --experiment free",
                 0, "200 wheel messages", {"imp/runs.csv", "imp/campaign.toml"},
                 [](const Run&, const fs::path& d) {
                   const std::string toml = Slurp((d / "imp/campaign.toml").string());
                   CHECK(umbmark::IsValidUtf8(toml));
                   CHECK(umbmark::IsValidUtf8(Slurp((d / "imp/runs.csv").string())));
                   CHECK(toml.find("lab\\x") != std::string::npos);
                   CHECK(toml.find("\nrobot = 1") == std::string::npos);  // no line of TOML from the folder name
                   // The manifest reads back.
                   CHECK(std::system(("cd '" + d.string() + "' && '" + UMBMARK_EXE +
                                      "' evaluate imp/campaign.toml >/dev/null 2>&1").c_str()) == 0);
                 }});
  }
}

void AddIssue23Options(std::vector<Case>& c) {
  const std::string cal = "calibrate ep.csv --robot robot.toml --side 4 ";
  // simulate: options far out of range would write inf into the campaign.
  for (const char* bad : {"--E-b 1e308", "--E-d 0", "--kl 1e308", "--gt-sigma-xy 1e308", "--gt-sigma-theta 7"})
    c.push_back({fmt::format("simulate {}", bad), [](const fs::path& d) { Put(d / "m.toml", kManifest); },
                 fmt::format("simulate m.toml --out o {}", bad), 2, "must be a number from"});
  c.push_back({"a manifest's [ground_truth] sigma_xy_m = 1e308", [](const fs::path& d) {
                 Put(d / "m.toml", kManifest + "\n[ground_truth]\nsigma_xy_m = 1e308\nsigma_theta_rad = 0.001\n");
               },
               "simulate m.toml --out o", 1, "m.toml:13:14: sigma_xy_m = 1e+308 is more than 1"});
  // Empty and NUL paths.
  for (const std::string& args : {cal + "--json ''", cal + "--report ''", cal + "--plot ''", std::string("calibrate '' --robot robot.toml --side 4"),
                                  std::string("summarize ep.csv --json ''"), std::string("evaluate ep.csv --robot '' ")})
    c.push_back({"empty path: " + args, Examples, args, 2, "empty path"});
  c.push_back({"a NUL byte in a manifest's file path", [](const fs::path& d) {
                 Put(d / "sq.csv", kEndpoints);
                 std::string m = kManifest;
                 m.replace(m.find("sq.csv"), 6, "sq.csv\\u0000.txt");
                 Put(d / "m.toml", m);
               },
               "calibrate m.toml --json -", 1, "NUL byte"});
  // import --out: non-empty folder without --force; --force leaves no stale file.
  c.push_back({"import --out into a non-empty folder", [](const fs::path& d) {
                 CopyOptiOdom(d / "square" / "230620202042");
                 Put(d / "imp/notes.txt", "mine\n");
               },
               "import optiodom square/230620202042 --out imp", 2, "--force"});
  c.push_back({"import --out --force replaces the old campaign whole", [](const fs::path& d) {
                 CopyOptiOdom(d / "square" / "230620202042");
                 Put(d / "imp/fwd_back.csv", "stale\n");
                 Put(d / "imp/campaign.toml", "stale\n");
               },
               "import optiodom square/230620202042 --out imp --force", 0, "Imported OptiOdom dataset",
               {"imp/runs.csv", "imp/campaign.toml", "imp/fwd_back.csv"},
               [](const Run&, const fs::path& d) {
                 CHECK(!fs::exists(d / "imp/fwd_back.csv"));
                 CHECK(Slurp((d / "imp/campaign.toml").string()).find("[robot]") != std::string::npos);
               }});
  // summarize: duplicates, impossible parameters, overflow.
  auto fleet = [](const fs::path& d) {
    for (int i = 0; i < 5; ++i)
      Put(d / fmt::format("r{}.json", i), CalJson(0.2 * (1 + 1e-4 * i), 0.084, 0.084 * (1 + 1e-4 * i), 0.2, 1 + 1e-4 * i));
  };
  c.push_back({"summarize: the same file three ways", [fleet](const fs::path& d) {
                 fleet(d);
                 fs::create_symlink("r0.json", d / "link.json");
                 fs::create_hard_link(d / "r1.json", d / "hard.json");
               },
               "summarize r0.json ./r0.json link.json r1.json hard.json r2.json --json -", 0, "counted once", {},
               [](const Run& r, const fs::path&) {
                 const auto j = nlohmann::json::parse(r.out);
                 CHECK(j["robots"].size() == 3);
                 CHECK(j["warnings"].size() >= 3);
               }});
  for (const char* bad : {"-0.2", "1e308", "0"})
    c.push_back({fmt::format("summarize: wheelbase {}", bad), [fleet, bad](const fs::path& d) {
                   fleet(d);
                   Put(d / "bad.json", CalJson(std::stod(bad), 0.084, 0.084, 0.2, 1.0));
                 },
                 "summarize r0.json r1.json bad.json r2.json", 1, "bad.json: parameters: wheelbase_m"});
  c.push_back({"summarize: a number overflow names the file", [fleet](const fs::path& d) {
                 fleet(d);
                 Put(d / "big.json", "{\n  \"E_b\": 1e400,\n  \"parameters\": {}\n}\n");
               },
               "summarize r0.json big.json", 1, "big.json:2:10: a number is out of range"});
}

void AddFilesDestroyed(std::vector<Case>& c) {
  const std::string cal = "calibrate ep.csv --robot robot.toml --side 4 ";
  // 1. Files destroyed.
  c.push_back({"--json equal to the input CSV", Examples, cal + "--json ep.csv", 2, "is the input file"});
  c.push_back({"--plot equal to the robot file", Examples, cal + "--plot robot.toml", 2, "is the input file"});
  c.push_back({"--ros2 and --json the same file", Examples, cal + "--ros2 o.json --json o.json", 2, "name the same file"});
  c.push_back({"--json through a symlink to the input",
               [](const fs::path& d) {
                 Examples(d);
                 fs::create_symlink("ep.csv", d / "l.json");
               },
               cal + "--json l.json", 2, "is the input file"});
  c.push_back({"--json /dev/stdout", Examples, cal + "--json /dev/stdout", 1, "use '-' for standard output"});
  c.push_back({"--json a FIFO",
               [](const fs::path& d) {
                 Examples(d);
                 REQUIRE(::mkfifo((d / "fifo").c_str(), 0600) == 0);
               },
               cal + "--json fifo", 1, "not a regular file"});
  c.push_back({"--json a directory",
               [](const fs::path& d) {
                 Examples(d);
                 fs::create_directory(d / "dir");
               },
               cal + "--json dir", 1, "directory"});
  c.push_back({"--json in a folder that does not exist", Examples, cal + "--json no/such/o.json", 1,
               "cannot create temporary file"});
  c.push_back({"simulate --out into its manifest's folder", [](const fs::path& d) { Put(d / "m.toml", kManifest); },
               "simulate m.toml --out . --force", 2, "contains the input"});
  c.push_back({"simulate --out non-empty without --force",
               [](const fs::path& d) {
                 Put(d / "m.toml", kManifest);
                 Put(d / "out/keep.txt", "user file\n");
               },
               "simulate m.toml --out out", 2, "not empty"});
  c.push_back({"fit-noise --plot equal to the input",
               [](const fs::path& d) {
                 Put(d / "m.toml", kManifest);
                 Put(d / "sq.csv", "x");
               },
               "fit-noise m.toml --plot sq.csv", 2, "is the input file"});
  c.push_back({"evaluate --plot equal to --json", Examples,
               "evaluate ep.csv --robot robot.toml --plot o.x --json o.x", 2, "name the same file"});
}

void AddImpossibleResults(std::vector<Case>& c) {
  const std::string cal = "calibrate ep.csv --robot robot.toml --side 4 ";
  // 2. Impossible results.
  c.push_back({"return errors in mm given as m",
               [](const fs::path& d) {
                 Examples(d);
                 Put(d / "ep.csv", ScaledEndpoints(1000.0));
               },
               cal, 1, "ep.csv: the square runs' return errors are 26.83 m (median) on a 4 m square"});
  c.push_back({"--side 0.002", Examples, "calibrate ep.csv --robot robot.toml --side 0.002", 2,
               "side_m = 0.002 is outside the plausible range 0.05 to 100 m"});
  c.push_back({"1e308 in a CSV",
               [](const fs::path& d) {
                 Examples(d);
                 Put(d / "ep.csv", "run,direction,ex_m,ey_m\n1,cw,1e308,0\n2,ccw,-1e308,0\n3,cw,1e308,1\n4,ccw,1,1\n");
               },
               cal, 1, "ep.csv:2:6: ex_m: '1e308' is beyond any measured value"});
  c.push_back({"1e308 in one row of five",
               [](const fs::path& d) {
                 Examples(d);
                 Put(d / "ep.csv", "run,direction,ex_m,ey_m\n1,cw,1e308,0\n2,ccw,-0.01,0\n3,cw,0.01,1\n4,ccw,0.01,0.01\n"
                                   "5,cw,0.01,0.01\n");
               },
               cal, 1, "ep.csv:2:6: ex_m: '1e308' is beyond any measured value"});
  c.push_back({"predict --path line:1e308", Examples,
               "predict --robot robot.toml --kl 0.001 --kr 0.001 --path line:1e308", 2, "limit"});
  c.push_back({"predict: P0 not positive semi-definite", Examples,
               "predict --robot robot.toml --kl 0.001 --kr 0.001 --path line:1 --P0 1,2,0,1,0,1", 2,
               "positive semi-definite"});
  c.push_back({"one run per direction", [](const fs::path& d) {
                 Examples(d);
                 Put(d / "ep.csv", "run,direction,ex_m,ey_m\n1,cw,0.01,0.02\n2,ccw,-0.01,0.03\n");
               },
               cal + "--json -", 0, "only 1 cw run"});
  c.push_back({"identical runs", [](const fs::path& d) {
                 Examples(d);
                 Put(d / "ep.csv", Repeated("0.01,0.02,0.001", "-0.01,0.03,0.002", 5));
               },
               cal + "--json -", 0, "zero scatter"});
  c.push_back({"runs that never move (all errors zero)", [](const fs::path& d) {
                 Examples(d);
                 Put(d / "ep.csv", Repeated("0,0,0", "0,0,0", 5));
               },
               cal + "--json -", 0, "exactly zero"});
  // Unit mix-ups, refused where they are read (file:line:column) or seen in the data.
  const auto robot_with = [](std::string key, std::string value) {
    return [key, value](const fs::path& d) {
      Examples(d);
      std::string text = kRobot;
      const auto at = text.find(key + " = ");
      REQUIRE(at != std::string::npos);
      const auto end = text.find('\n', at);
      text.replace(at, end - at, key + " = " + value);
      Put(d / "robot.toml", text);
    };
  };
  c.push_back({"robot file wheelbase in mm (200)", robot_with("wheelbase_m", "200"), cal, 1,
               "robot.toml:1:15: wheelbase_m = 200 is outside the plausible range 0.01 to 10 m: was it given in "
               "millimetres (200 mm = 0.2 m)?"});
  c.push_back({"robot file diameters in mm (84)", robot_with("wheel_diameter_left_m", "84"), cal, 1,
               "robot.toml:2:25: wheel_diameter_left_m = 84 is outside the plausible range 0.005 to 3 m: was it "
               "given in millimetres (84 mm = 0.084 m)?"});
  c.push_back({"robot file ticks_per_rev 1e-300", robot_with("ticks_per_rev", "1e-300"), cal, 1,
               "robot.toml:4:17: ticks_per_rev = 1e-300 is outside the plausible range 1 to 1e+09 ticks per wheel "
               "revolution"});
  c.push_back({"--ticks-per-rev 1e-300", Examples, cal + "--ticks-per-rev 1e-300", 2,
               "--ticks-per-rev: ticks_per_rev = 1e-300 is outside the plausible range"});
  c.push_back({"--wheelbase 340 (mm)", Examples, cal + "--wheelbase 340", 2, "(340 mm = 0.34 m)?"});
  c.push_back({"--side 4000 (mm)", Examples, "calibrate ep.csv --robot robot.toml --side 4000", 2,
               "side_m = 4000 is outside the plausible range 0.05 to 100 m: was it given in millimetres"});
  c.push_back({"manifest side_m in mm", [](const fs::path& d) {
                 std::string m = kManifest;
                 m.replace(m.find("side_m = 1.0"), 12, "side_m = 4000");
                 Put(d / "m.toml", m);
                 Put(d / "sq.csv", kEndpoints);
               },
               "calibrate m.toml", 1, "m.toml:9:10: side_m = 4000 is outside the plausible range"});
  c.push_back({"manifest distance_m in mm", [](const fs::path& d) {
                 Put(d / "m.toml", kManifest + "\n[[experiment]]\nkind = \"back_and_forth\"\ndistance_m = 2000\n"
                                               "file = \"bf.csv\"\n");
               },
               "calibrate m.toml", 1, "m.toml:14:14: distance_m = 2000 is outside the plausible range 0.05 to 1000 m: "
                                      "was it given in millimetres"});
}

void AddImpossibleImports(std::vector<Case>& c) {
  const std::string cal = "calibrate ep.csv --robot robot.toml --side 4 ";
  c.push_back({"trajectories with the wrong side (travel vs 4 sides)", [](const fs::path& d) {
                 Put(d / "robot.toml", kRobot);
                 Put(d / "tr.csv", Slurp((kSource / "tests/data/good/trajectory_ticks.csv").string()));
               },
               "calibrate tr.csv --robot robot.toml --side 40", 1, "but 4 sides of 40 m are 160 m"});
  // Swapped channels / reversed labels on endpoint data, corrections UMBmark cannot support.
  c.push_back({"endpoint file with cw/ccw labels reversed (swapped channels)", [](const fs::path& d) {
                 Examples(d);
                 std::string t = kEndpoints;
                 for (std::size_t at = 0; (at = t.find("cw,", at)) != std::string::npos; at += 3) {
                   if (at > 0 && t[at - 1] == 'c') {
                     t.replace(at - 1, 4, "cw,");
                   } else {
                     t.replace(at, 3, "ccw,");
                     ++at;
                   }
                 }
                 Put(d / "ep.csv", t);
               },
               cal, 3, "the cw/ccw labels are reversed, or the left and right encoder channels swapped"});
  c.push_back({"a 1 % diameter error on a 4 m square: the E_b correction is mostly artefact",
               [](const fs::path& d) {
                 Examples(d);
                 // commanded_square, E_b 1, E_d 1.01, 0.34 m wheelbase: cw (-0.731, -1.189), ccw (1.058, -0.650)
                 std::string t = "run,direction,ex_m,ey_m\n";
                 const char* jitter[] = {"0.004", "-0.003", "0.001", "-0.002", "0"};
                 for (int i = 0; i < 5; ++i) {
                   t += fmt::format("{},cw,{:.4f},{:.4f}\n", 2 * i + 1, -0.731 + std::stod(jitter[i]), -1.189 - std::stod(jitter[(i + 2) % 5]));
                   t += fmt::format("{},ccw,{:.4f},{:.4f}\n", 2 * i + 2, 1.058 + std::stod(jitter[(i + 1) % 5]), -0.650 + std::stod(jitter[(i + 3) % 5]));
                 }
                 Put(d / "ep.csv", t);
                 Put(d / "robot.toml", kRobot);
               },
               cal, 3, "correction larger than UMBmark can support"});
  // Degenerate data: warnings in the JSON (and the text) of evaluate, predict, diagnose, import.
  const auto traj = [](int runs, bool moves, bool gt_moves, int gt_every, bool same) {
    return [=](const fs::path& d) {
      Put(d / "robot.toml", kRobot);
      Put(d / "tr.csv", Trajectories(runs, moves, gt_moves, gt_every, same));
    };
  };
  const std::string ev = "evaluate tr.csv --robot robot.toml --json -";
  c.push_back({"evaluate: runs that never move", traj(3, false, false, 1, false), ev, 0,
               "tr.csv: 3 of 3 runs never move"});
  c.push_back({"evaluate: wheels turn, ground truth still", traj(3, true, false, 1, false), ev, 0,
               "the wheels turn but the ground truth stays at the start (run 1, 2, 3)"});
  c.push_back({"evaluate: ground truth missing for most samples", traj(3, true, true, 10, false), ev, 0,
               "ground truth at only 6 of 33 samples (18 %)"});
  c.push_back({"evaluate: one run", traj(1, true, true, 1, false), ev, 0, "a single run"});
  c.push_back({"evaluate: identical runs (zero scatter)", traj(4, true, true, 1, true), ev, 0,
               "all 4 runs end at exactly the same ground-truth pose (zero scatter)"});
  const std::string pr = "predict --robot robot.toml --path line:1 --json - ";
  c.push_back({"predict: no noise at all", Examples, pr + "--kl 0 --kr 0", 0, "no noise at all"});
  c.push_back({"predict: a path that does not move", Examples, "predict --robot robot.toml --path line:0 --kl 0.001 --kr 0.001 --json -", 0,
               "the path does not move"});
  c.push_back({"predict: Monte Carlo with 10 runs", Examples, pr + "--kl 0.001 --kr 0.001 --monte-carlo 10", 0,
               "Monte Carlo with 10 runs"});
  c.push_back({"diagnose: one run per direction",
               [](const fs::path& d) {
                 Put(d / "m.toml", kManifest);
                 REQUIRE(std::system(("cd '" + d.string() + "' && '" + UMBMARK_EXE +
                                      "' simulate m.toml --out sim --square-runs 1 --seed 1 >/dev/null 2>&1").c_str()) == 0);
               },
               "diagnose sim/campaign.toml --null-sims 20 --json -", 0, "only 1 cw run"});
  c.push_back({"import optiodom: a single run",
               [](const fs::path& d) {
                 const fs::path src = kSource / "data/optiodom-2020-06/square/230620202042";
                 const fs::path dst = d / "square" / "230620202042";
                 fs::create_directories(dst);
                 fs::copy_file(src / "230620202042_run-01.csv", dst / "230620202042_run-01.csv");
                 std::string meta = Slurp((src / "230620202042_metadata.csv").string());
                 const auto at = meta.find("\nN,6,");
                 REQUIRE(at != std::string::npos);
                 meta.replace(at, 5, "\nN,1,");
                 Put(dst / "230620202042_metadata.csv", meta);
               },
               "import optiodom square/230620202042 --out imp --json -", 0,
               "imp/runs.csv: a single run: nothing shows how runs scatter", {"imp/runs.csv", "imp/campaign.toml"}});
}

void AddCrashesAndMessages(std::vector<Case>& c) {
  const std::string cal = "calibrate ep.csv --robot robot.toml --side 4 ";
  // 3. Crashes.
  c.push_back({"non-UTF-8 byte in run id and direction", [](const fs::path& d) {
                 Examples(d);
                 std::string text = kEndpoints;
                 const auto at = text.find("\n1,cw,");
                 REQUIRE(at != std::string::npos);
                 text.replace(at, 6, "\n1\xff\xfe,cw,");
                 Put(d / "ep.csv", text);
               },
               cal + "--json -", 0, "\\\\xFF\\\\xFE",  {},
               [](const Run& r, const fs::path&) { CHECK_NOTHROW(nlohmann::json::parse(r.out)); }});
  c.push_back({"non-UTF-8 direction", [](const fs::path& d) {
                 Examples(d);
                 Put(d / "ep.csv", "run,direction,ex_m,ey_m\n1,c\xe9w,0.01,0.02\n");
               },
               cal, 1, "\\xE9"});
  c.push_back({"1e400 in --params JSON", [](const fs::path& d) {
                 Examples(d);
                 Put(d / "cal.json", "{\"parameters\": {\"wheelbase_m\": 1e400, \"wheel_diameter_left_m\": 0.15, "
                                     "\"wheel_diameter_right_m\": 0.15}}");
                 Put(d / "tr.csv", Slurp((kSource / "tests/data/good/trajectory_ticks.csv").string()));
               },
               "evaluate tr.csv --robot robot.toml --params cal.json", 1, "out of range"});
  c.push_back({"predict --monte-carlo 1e12", Examples,
               "predict --robot robot.toml --kl 0.001 --kr 0.001 --path line:1 --monte-carlo 1000000000000", 2,
               "GB of memory"});
  c.push_back({"simulate --speed 1e-9", [](const fs::path& d) { Put(d / "m.toml", kManifest); },
               "simulate m.toml --out o --speed 1e-9", 2, "samples"});
  // 4. Unbounded sizes.
  c.push_back({"simulate --square-runs 1e8", [](const fs::path& d) { Put(d / "m.toml", kManifest); },
               "simulate m.toml --out o --square-runs 100000000", 2, "got '100000000'"});
  c.push_back({"diagnose --piece-length 1e-9", [](const fs::path& d) { Put(d / "m.toml", kManifest); },
               "diagnose m.toml --piece-length 1e-9", 2, "from 0.01 to 1000"});
  // 7. Messages.
  c.push_back({"import foo DIR", [](const fs::path&) {}, "import foo .", 2, "unknown import format 'foo'"});
  c.push_back({"--seed -1", [](const fs::path& d) { Put(d / "m.toml", kManifest); },
               "simulate m.toml --out o --seed -1", 2, "got '-1'"});
  c.push_back({"repeated --effect", [](const fs::path& d) { Put(d / "m.toml", kManifest); },
               "simulate m.toml --out o --effect turn_scrub:k=0.01 --effect turn_scrub:k=0.02", 2, "given twice"});
  c.push_back({"negative --side quotes the value", Examples, "calibrate ep.csv --robot robot.toml --side -412.3", 2,
               "got '-412.3'"});
  // More: garbage, empty, unwritable stdout.
  c.push_back({"binary garbage as CSV", [](const fs::path& d) {
                 Examples(d);
                 Put(d / "ep.csv", std::string("\x00\x01\xff\xfe garbage\n\x7f", 14));
               },
               cal, 1, "ep.csv"});
  c.push_back({"empty CSV", [](const fs::path& d) {
                 Examples(d);
                 Put(d / "ep.csv", "");
               },
               cal, 1, "ep.csv"});
  c.push_back({"stdout is /dev/full", Examples, cal + "--json - >/dev/full 2>/dev/null; exit $?",
               1, ""});  // the message itself: test_output_safety
  c.push_back({"a manifest whose experiment file is the manifest", [](const fs::path& d) {
                 std::string m = kManifest;
                 m.replace(m.find("sq.csv"), 6, "m.toml");
                 Put(d / "m.toml", m);
               },
               "calibrate m.toml --json -", 1, "m.toml"});
}

/// The corpus, in the order of the sections above (split by section so
/// that no function runs past 120 lines).
std::vector<Case> Corpus() {
  std::vector<Case> c;
  AddFilesDestroyed(c);
  AddImpossibleResults(c);
  AddImpossibleImports(c);
  AddCrashesAndMessages(c);
  AddIssue23Cases(c);
  AddIssue23Options(c);
  return c;
}

}  // namespace

TEST_CASE("hostile corpus: exit status, message, inputs unchanged, bounded time and memory", "[safety][corpus][cli]") {
  const auto cases = Corpus();
  REQUIRE(cases.size() >= 30);
  for (const auto& c : cases) {
    INFO("case: " << c.name << "\n  umbmark " << c.args);
    const fs::path dir = umbmark::testing::TempDir("hostile");
    c.setup(dir);
    const auto before = Hashes(dir);
    const Run r = Exec(dir, c.args);
    INFO("stderr: " << r.err);
    CHECK(r.status != 124);  // timeout: a hang
    CHECK(r.status == c.status);
    if (!c.message.empty()) CHECK_THAT(c.status == 0 ? r.out : r.err, Catch::Contains(c.message));
    if (c.status != 0) CHECK_THAT(r.err, !Catch::Contains("internal error"));
    auto after = Hashes(dir);
    for (const auto& o : c.outputs) after.erase(o);
    auto expected = before;
    for (const auto& o : c.outputs) expected.erase(o);
    CHECK(after == expected);  // inputs unchanged, nothing else written
    for (const auto& e : fs::recursive_directory_iterator(dir)) CHECK(e.path().filename().string().find(".tmp.") == std::string::npos);
    if (c.extra) c.extra(r, dir);
  }
  struct rusage ru {};
  REQUIRE(::getrusage(RUSAGE_CHILDREN, &ru) == 0);
  CHECK(ru.ru_maxrss < kMaxRssKb);
}
