// `umbmark plan` and `plan --check` end to end: the contract's JSON keys,
// exit 3 naming the target that cannot be met, bad input (exit 1/2, nothing
// written), the motions list, and --check's predicted intervals against the
// spread between the four June square sessions.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <fmt/format.h>
#include <tuple>
#include <vector>

#include "support/run_cli.hpp"

using namespace umbmark::testing;
namespace fs = std::filesystem;

namespace {
const fs::path kSrc = UMBMARK_SOURCE_DIR;
const std::string kRobot = Q(kSrc / "data/examples/robot.toml");
}  // namespace

TEST_CASE("plan --json writes the contract's design and predicted_ci95", "[plan][cli]") {
  const fs::path dir = TempDir("plan");
  const auto r = RunCli("plan --robot " + kRobot + " --kl 1e-3 --kr 8e-4 --target-E_d 5e-4 --target-E_b 2e-3 "
                        "--target-k 2e-4 --max-side 2 --json " + Q(dir / "plan.json") + " --motions " +
                        Q(dir / "motions.json"));
  INFO(r.out << r.err);
  REQUIRE(r.status == 0);
  const auto j = nlohmann::json::parse(Slurp((dir / "plan.json").string()));
  for (const char* key : {"square_side_m", "runs_cw", "runs_ccw", "back_and_forth_runs", "back_and_forth_length_m",
                          "pause_s", "time_s"})
    CHECK(j.at("design").at(key).is_number());
  CHECK(j["design"]["free_paths"].is_array());
  for (const char* key : {"E_d", "E_b", "k_L", "k_R"}) {
    INFO(key);
    CHECK(j.at("predicted_ci95").at(key).get<double>() > 0.0);
    CHECK(j["predicted_ci95"][key].get<double>() <= j["targets"][key].get<double>());
  }
  CHECK_FALSE(j["predicted_ci95"].contains("scale"));  // not targeted
  CHECK(j["design"]["square_side_m"].get<double>() <= 2.0);
  // The motions: every run's lines and turns, and the time they take equals time_s.
  const auto m = nlohmann::json::parse(Slurp((dir / "motions.json").string()));
  REQUIRE(m.is_array());
  double t = 0.0, turn = 0.0;
  int runs = 0;
  for (const auto& x : m) {
    const std::string kind = x.at("kind");
    if (kind == "line") t += std::abs(x["distance_m"].get<double>()) / x["speed"].get<double>();
    if (kind == "turn") {
      t += std::abs(x["angle_rad"].get<double>()) / x["speed"].get<double>();
      turn += x["angle_rad"].get<double>();
    }
    if (kind == "pause") t += x["duration_s"].get<double>();
    runs = std::max(runs, x["run"].get<int>());
  }
  CHECK(t == Approx(j["design"]["time_s"].get<double>()).epsilon(1e-9));
  CHECK(runs == j["design"]["runs_cw"].get<int>() + j["design"]["runs_ccw"].get<int>() +
                    j["design"]["back_and_forth_runs"].get<int>());
  CHECK(turn == Approx(0.0).margin(1e-9));  // as many cw as ccw squares
}

TEST_CASE("plan exits 3 naming the target that cannot be met", "[plan][cli]") {
  const fs::path dir = TempDir("plan3");
  const auto tape = RunCli("plan --robot " + kRobot + " --kl 1e-3 --kr 1e-3 --ground-truth tape --target-scale 0.01 "
                           "--json " + Q(dir / "p.json"));
  CHECK(tape.status == 3);
  CHECK(tape.err.find("scale") != std::string::npos);
  CHECK(tape.err.find("never determine the overall scale") != std::string::npos);
  CHECK_FALSE(fs::exists(dir / "p.json"));
  const auto slow = RunCli("plan --robot " + kRobot + " --kl 1e-3 --kr 1e-3 --target-E_b 1e-3 --max-time 60");
  CHECK(slow.status == 3);
  CHECK(slow.err.find("E_b") != std::string::npos);
  CHECK(slow.err.find("--max-time allows 60 s") != std::string::npos);
  // Out of reach within 200 runs per direction at the largest side: says how many it would take.
  const auto far = RunCli("plan --robot " + kRobot + " --kl 1e-3 --kr 1e-3 --target-E_b 1e-4");
  CHECK(far.status == 3);
  CHECK(far.err.find("E_b half-width") != std::string::npos);
  CHECK(far.err.find("the target needs about") != std::string::npos);
}

TEST_CASE("plan: bad input exits 1 or 2 and writes nothing", "[plan][cli]") {
  const fs::path dir = TempDir("planbad");
  const std::string out = " --json " + Q(dir / "p.json");
  CHECK(RunCli("plan --robot " + kRobot + " --kl 1e-3 --kr 1e-3" + out).status == 2);          // no target
  CHECK(RunCli("plan --robot " + kRobot + " --target-E_d 1e-3" + out).status == 2);            // no noise
  CHECK(RunCli("plan --robot " + kRobot + " --kl -1 --kr 1e-3 --target-E_d 1e-3" + out).status == 2);
  CHECK(RunCli("plan --robot " + kRobot + " --kl 1e-3 --kr 1e-3 --target-E_d 0" + out).status == 2);
  CHECK(RunCli("plan --robot " + kRobot + " --kl 1e-3 --kr 1e-3 --target-E_d 1e-3 --ground-truth laser" + out).status == 2);
  const auto missing = RunCli("plan --robot " + kRobot + " --noise " + Q(dir / "none.json") + " --target-E_d 1e-3" + out);
  CHECK(missing.status == 1);
  std::ofstream((dir / "fit.json").string()) << "{\"k_L\": 0.001}";
  const auto partial = RunCli("plan --robot " + kRobot + " --noise " + Q(dir / "fit.json") + " --target-E_d 1e-3" + out);
  CHECK(partial.status == 1);
  CHECK(partial.err.find("k_R") != std::string::npos);
  CHECK(RunCli("plan --check " + Q(dir / "nope.toml") + out).status == 1);
  CHECK_FALSE(fs::exists(dir / "p.json"));
}

TEST_CASE("plan --check on the June square sessions: predicted E_d and E_b intervals agree with their spread", "[plan][cli]") {
  // The four square sessions of 23 June 2020 (0.75 m, 3-5 runs per
  // direction): each session's plain least-squares calibration (what
  // calibrate recommends on them, docs/calibration-comparison.md) against
  // plan --check's predicted half-width for that session. From four
  // sessions a factor of 2 between the predicted standard deviation and
  // the sessions' spread is what can be checked (issue 30).
  //
  // The wheel noise: fit-noise on the four sessions pooled. With the
  // return errors' heading (k_L = 0.000229, k_R = 0.00115 m^1/2,
  // docs/diagnosis.md) E_b's prediction is 2.3 times the spread: the June
  // heading return errors carry a scatter their positions do not (the
  // fit's own goodness of fit: x, y variances 10 and 3 times below what
  // those k imply), and the plain fit sees positions only. fit-noise on
  // the return POSITIONS (an endpoint CSV without etheta: the tape-measure
  // case) is the wheel noise the plain fit's positions carry
  // (docs/plan.md, "plan --check on the June recordings").
  const char* sessions[] = {"230620202042", "230620202144", "230620202258", "230620202317"};
  const fs::path pooled = TempDir("june_positions");
  std::string manifest =
      "[robot]\nwheelbase_m = 0.2\nwheel_diameter_left_m = 0.084\nwheel_diameter_right_m = 0.084\n";
  std::vector<double> ed, b;
  std::vector<fs::path> dirs;
  for (const char* s : sessions) {
    const fs::path dir = TempDir(std::string("june") + s);
    dirs.push_back(dir);
    REQUIRE(RunCli("import optiodom " + Q(kSrc / "data/optiodom-2020-06/square" / s) + " --out " + Q(dir)).status == 0);
    const auto cal = RunCli("calibrate " + Q(dir / "campaign.toml") + " --json -");
    REQUIRE(cal.status == 0);
    const auto jc = nlohmann::json::parse(cal.out);
    const auto p = jc["heldout_error"]["plain_least_squares"]["parameters"];
    ed.push_back(p["wheel_diameter_right_m"].get<double>() / p["wheel_diameter_left_m"].get<double>());
    b.push_back(p["wheelbase_m"].get<double>());
    std::ofstream csv((pooled / (std::string(s) + ".csv")).string());
    csv << "run,direction,ex_m,ey_m,etheta_rad\n";
    for (const auto& r : jc["runs"])
      csv << r["run"].get<std::string>() << "," << r["direction"].get<std::string>() << ","
          << fmt::format("{:.9g},{:.9g},", r["ex_m"].get<double>(), r["ey_m"].get<double>()) << "\n";
    manifest += fmt::format("\n[[experiment]]\nkind = \"square\"\nside_m = 0.75\nfile = \"{}.csv\"\n", s);
  }
  std::ofstream((pooled / "campaign.toml").string()) << manifest;
  const auto fn = RunCli("fit-noise " + Q(pooled / "campaign.toml") + " --meas-sigma 0.0003,0.001 --json -");
  INFO(fn.err);
  REQUIRE(fn.status == 0);
  const auto jf = nlohmann::json::parse(fn.out);
  const double kl_pos = std::max(jf["k_L"].get<double>(), 1e-7), kr_pos = std::max(jf["k_R"].get<double>(), 1e-7);
  auto sd = [](const std::vector<double>& v, double scale) {
    double m = 0.0, s = 0.0;
    for (double x : v) m += x / static_cast<double>(v.size());
    for (double x : v) s += (x - m) * (x - m);
    return std::sqrt(s / static_cast<double>(v.size() - 1)) / scale;
  };
  auto rms = [](const std::vector<double>& v) {
    double s = 0.0;
    for (double x : v) s += x / static_cast<double>(v.size());
    return std::sqrt(s);
  };
  for (const auto& [kl, kr, what] : {std::tuple{0.000229, 0.00115, "with heading"}, std::tuple{kl_pos, kr_pos, "positions"}}) {
    std::vector<double> var_ed, var_eb;
    for (const fs::path& dir : dirs) {
      const auto check = RunCli("plan --check " + Q(dir / "campaign.toml") + fmt::format(" --kl {} --kr {}", kl, kr) +
                                " --json -");
      INFO(check.err);
      REQUIRE(check.status == 0);
      const auto jc = nlohmann::json::parse(check.out);
      CHECK(jc["method"] == "plain_least_squares");
      var_ed.push_back(std::pow(jc["predicted_ci95"]["E_d"].get<double>() / 1.96, 2));
      var_eb.push_back(std::pow(jc["predicted_ci95"]["E_b"].get<double>() / 1.96, 2));
    }
    const double ratio_ed = sd(ed, 1.0) / rms(var_ed), ratio_eb = sd(b, 0.2007) / rms(var_eb);
    INFO("k " << what << ": k_L " << kl << ", k_R " << kr);
    INFO("E_d: sessions' sd " << sd(ed, 1.0) << ", predicted sd " << rms(var_ed) << ", ratio " << ratio_ed);
    INFO("E_b: sessions' sd " << sd(b, 0.2007) << ", predicted sd " << rms(var_eb) << ", ratio " << ratio_eb);
    CHECK(ratio_ed >= 0.5);
    CHECK(ratio_ed <= 2.0);
    CHECK(ratio_eb <= 2.0);  // plan does not promise more than the sessions show
    if (std::string(what) == "positions") CHECK(ratio_eb >= 0.5);  // with heading: 0.44 (see above)
  }
}

TEST_CASE("plan and plan --check: hostile input names the file and line, exits 1 or 2, writes nothing", "[plan][cli]") {
  const fs::path dir = TempDir("planhostile");
  const std::string json = Q(dir / "out.json"), motions = Q(dir / "m.json");
  auto nothing_written = [&] { return !fs::exists(dir / "out.json") && !fs::exists(dir / "m.json"); };
  // A return-error campaign plan --check accepts as it is.
  auto campaign = [&](const std::string& name, const std::string& toml_extra, const std::string& bad_row) {
    const fs::path d = dir / name;
    fs::create_directories(d);
    std::ofstream csv((d / "sq.csv").string());
    csv << "run,direction,ex_m,ey_m,etheta_rad\n";
    for (int i = 0; i < 5; ++i) {
      csv << fmt::format("{},cw,{:.4f},{:.4f},{:.4f}\n", i + 1, 0.010 + 0.001 * i, -0.004 + 0.0007 * i, 0.01);
      csv << fmt::format("{},ccw,{:.4f},{:.4f},{:.4f}\n", i + 6, -0.006 + 0.0009 * i, 0.005 - 0.0006 * i, -0.01);
    }
    csv << bad_row;
    std::ofstream((d / "campaign.toml").string())
        << "[robot]\nwheelbase_m = 0.4\nwheel_diameter_left_m = 0.1\nwheel_diameter_right_m = 0.1\n"
        << "\n[[experiment]]\nkind = \"square\"\n" << toml_extra << "file = \"sq.csv\"\n";
    return Q(d / "campaign.toml");
  };
  REQUIRE(RunCli("plan --check " + campaign("good", "side_m = 2\n", "") + " --kl 1e-3 --kr 1e-3").status == 0);

  // A CSV row with a word for a number: file, line and column.
  const auto word = RunCli("plan --check " + campaign("word", "side_m = 2\n", "11,cw,abc,0.0,0.0\n") + " --json " + json);
  CHECK(word.status == 1);
  CHECK(word.err.find("sq.csv:12:") != std::string::npos);
  // A truncated last row.
  const auto cut = RunCli("plan --check " + campaign("cut", "side_m = 2\n", "11,cw\n") + " --json " + json);
  CHECK(cut.status == 1);
  CHECK(cut.err.find("sq.csv:12:") != std::string::npos);
  // A manifest value of the wrong type: file, line and column.
  const auto type = RunCli("plan --check " + campaign("type", "side_m = \"two\"\n", "") + " --json " + json);
  CHECK(type.status == 1);
  CHECK(type.err.find("campaign.toml:8:") != std::string::npos);
  // A robot file that is not TOML, a noise file that is not JSON.
  std::ofstream((dir / "bad_robot.toml").string()) << "wheelbase_m = 0.4\nwheel_diameter_left_m = = 0.1\n";
  const auto robot = RunCli("plan --robot " + Q(dir / "bad_robot.toml") + " --kl 1e-3 --kr 1e-3 --target-E_d 1e-3 "
                            "--json " + json + " --motions " + motions);
  CHECK(robot.status == 1);
  CHECK(robot.err.find("bad_robot.toml:2:") != std::string::npos);
  std::ofstream((dir / "bad_noise.json").string()) << "{\"k_L\": 0.001,\n \"k_R\": }\n";
  const auto noise = RunCli("plan --robot " + kRobot + " --noise " + Q(dir / "bad_noise.json") +
                            " --target-E_d 1e-3 --json " + json + " --motions " + motions);
  CHECK(noise.status == 1);
  CHECK(noise.err.find("bad_noise.json") != std::string::npos);
  CHECK(noise.err.find("line 2") != std::string::npos);
  // Not numbers where numbers belong: usage errors.
  CHECK(RunCli("plan --robot " + kRobot + " --kl nan --kr 1e-3 --target-E_d 1e-3 --json " + json).status == 2);
  CHECK(RunCli("plan --robot " + kRobot + " --kl 1e-3 --kr 1e-3 --target-E_d inf --json " + json).status == 2);
  CHECK(RunCli("plan --robot " + kRobot + " --kl 1e-3 --kr 1e-3 --target-E_d 1e-3 --max-side -1 --json " + json).status == 2);
  CHECK(RunCli("plan --check " + campaign("good", "side_m = 2\n", "") + " --motions " + motions).status == 2);
  // --motions into a folder that does not exist: exit 1 naming it, and the JSON is not written either.
  const auto nodir = RunCli("plan --robot " + kRobot + " --kl 1e-3 --kr 1e-3 --target-E_d 1e-3 --json " + json +
                            " --motions " + Q(dir / "no_such_dir" / "m.json"));
  CHECK(nodir.status == 1);
  CHECK(nodir.err.find("no_such_dir") != std::string::npos);
  CHECK(nothing_written());
  // The other way round: --json into a missing folder leaves no motions file either.
  const auto nojson = RunCli("plan --robot " + kRobot + " --kl 1e-3 --kr 1e-3 --target-E_d 1e-3 --json " +
                             Q(dir / "no_such_dir" / "out.json") + " --motions " + motions);
  CHECK(nojson.status == 1);
  CHECK(nojson.err.find("no_such_dir") != std::string::npos);
  CHECK(nojson.out.empty());
  CHECK(nothing_written());
}

TEST_CASE("calibrate --json: design_advice holds plan --check's analysis as data, the same as its sentences",
          "[plan][cli][advice]") {
  // Return errors of 4 + 4 squares whose centres of gravity lie within
  // their scatter: the corrections classic UMBmark finds are not
  // determined (E_d's +0.001 % by no practical design: N = 0; E_b's -0.28 %
  // by 23 more runs per direction). Its half-width shrinks as 1/sqrt(n) with n runs per
  // direction, so each record_more entry's half-width after its extra runs
  // is the closed form h sqrt(4 / (4 + N)), and its warning sentence names
  // the same N.
  const fs::path dir = TempDir("design_advice");
  std::ofstream((dir / "sq.csv").string()) << "run,direction,ex_m,ey_m,etheta_rad\n"
                                              "1,cw,0.018,-0.002,0.010\n2,cw,-0.004,0.015,-0.012\n"
                                              "3,cw,0.014,0.017,0.006\n4,cw,-0.002,-0.004,-0.003\n"
                                              "5,ccw,-0.005,0.001,-0.009\n6,ccw,0.015,-0.016,0.011\n"
                                              "7,ccw,-0.001,-0.018,-0.005\n8,ccw,0.016,0.005,0.004\n";
  // --no-heldout: outputs_use is the classic correction (with the held-out
  // comparison the recorded parameters win on such runs: nothing to advise).
  const auto r = RunCli("calibrate " + Q(dir / "sq.csv") + " --robot " + kRobot + " --side 0.75 --no-heldout --json -");
  INFO(r.err);
  REQUIRE(r.status == 0);
  const auto j = nlohmann::json::parse(r.out);
  REQUIRE(j.contains("design_advice"));
  const auto& a = j["design_advice"];
  REQUIRE(a["available"].get<bool>());
  REQUIRE(a["cannot_separate"].is_array());
  REQUIRE(a["record_more"].is_array());
  REQUIRE_FALSE(a["record_more"].empty());
  const auto& warnings = j["warnings"];
  for (const auto& m : a["record_more"]) {
    const std::string q = m["quantity"];
    INFO(q);
    CHECK((q == "E_d" || q == "E_b"));
    const double h = m["half_width"], after = m["half_width_after"], corr = m["correction"];
    const int n = m["extra_runs_per_direction"];
    CHECK(h > 0.5 * std::abs(corr));  // listed because the runs do not determine it
    if (n > 0) {
      CHECK(after == Approx(h * std::sqrt(4.0 / (4.0 + n))).epsilon(1e-6));
      CHECK(after <= 0.5 * std::abs(corr) * (1.0 + 1e-9));
      CHECK(h * std::sqrt(4.0 / (4.0 + n - 1)) > 0.5 * std::abs(corr));  // the fewest: one run less is not enough
      CHECK(m["side_m"].get<double>() == Approx(0.75));
      CHECK(m["time_s"].get<double>() > 0.0);
    }
    const std::string head = q + "'s correction";
    const auto said = std::find_if(warnings.begin(), warnings.end(), [&](const nlohmann::json& w) {
      return w.get<std::string>().rfind(head, 0) == 0;
    });
    REQUIRE(said != warnings.end());
    if (n > 0) CHECK(said->get<std::string>().find(fmt::format("record {} more square run(s)", n)) != std::string::npos);
  }
  for (const auto& c : a["cannot_separate"]) CHECK(c["kind"] == "parameters");
  // Both branches: one correction no practical design determines, one that more runs do.
  REQUIRE(a["record_more"].size() == 2);
  CHECK(a["record_more"][0]["extra_runs_per_direction"] == 0);
  CHECK(a["record_more"][1]["extra_runs_per_direction"].get<int>() > 0);
}
