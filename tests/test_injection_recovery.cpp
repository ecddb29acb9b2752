// Injection-recovery on a REAL recording (issue 28; the full harness is
// bench/injection_recovery.sh, its table in docs/diagnosis.md): contract
// effects injected into the June 2020 OptiOdom session s1 (the square set
// 230620202042 and the circular set 250620202104, data/optiodom-2020-06)
// with the real background left in (bench/injection.hpp: the encoders as
// recorded, the ground truth as the robot's path would have changed), then
// `umbmark diagnose` must name them and size them against the same session
// without injection.
//
// First, the injection itself against the contract's definitions on the
// real runs (closed forms); then the diagnosis on a few injections whose
// name and size current main recovers (session s1 is in the harness'
// tuning set).
#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "../bench/injection.hpp"
#include "support/run_cli.hpp"

using namespace umbmark::testing;
using umbmark_bench::InjectOptions;
using umbmark_bench::ParseEffect;
using umbmark_bench::Pose2;

namespace {

constexpr double kPi = 3.14159265358979323846;
const std::filesystem::path kJune = std::filesystem::path(UMBMARK_SOURCE_DIR) / "data" / "optiodom-2020-06";

/// The recordings `sets` (data/optiodom-2020-06/...), imported once each
/// (`umbmark import optiodom`).
std::vector<std::filesystem::path> Imported(const std::vector<std::string>& sets) {
  static std::map<std::string, std::filesystem::path> done;
  static const auto dir = TempDir("inject");
  std::vector<std::filesystem::path> csv;
  for (const std::string& set : sets) {
    if (!done.count(set)) {
      const auto out = dir / std::filesystem::path(set).filename();
      const auto r = RunCli("import optiodom " + Q(kJune / set) + " --out " + Q(out));
      INFO(r.err);
      REQUIRE(r.status == 0);
      done[set] = out / "runs.csv";
    }
    csv.push_back(done[set]);
  }
  return csv;
}

/// A session of the harness (bench/injection_recovery.sh: the same manifest)
/// with `effects` injected (none: the session as recorded, through the same
/// reader and writer), diagnosed; the diagnosis JSON.
nlohmann::json DiagnoseSession(const std::vector<std::string>& sets, const std::vector<std::string>& effects,
                               std::uint64_t seed) {
  const auto dir = TempDir("inject-session");
  InjectOptions o;
  for (const auto& e : effects) o.effects.push_back(ParseEffect(e));
  int first = 0;
  std::ofstream m(dir / "campaign.toml");
  m << "[robot]\nwheelbase_m = 0.2\nwheel_diameter_left_m = 0.084\nwheel_diameter_right_m = 0.084\n"
       "ticks_per_rev = 2796.8\n";
  const std::vector<std::filesystem::path> csv = Imported(sets);
  for (std::size_t i = 0; i < csv.size(); ++i) {
    auto tab = umbmark_bench::ReadTrajectory(csv[i].string());
    o.seed = seed * 10 + i + 1;
    o.first_run_index = first;
    first += umbmark_bench::InjectTable(tab, o).runs;
    const std::string name = "e" + std::to_string(i + 1) + ".csv";
    umbmark_bench::WriteTrajectory(tab, (dir / name).string());
    m << (sets[i].rfind("square/", 0) == 0 ? "\n[[experiment]]\nkind = \"square\"\nside_m = 0.75\n"
                                           : "\n[[experiment]]\nkind = \"free\"\n")
      << "file = \"" << name << "\"\n";
  }
  m.close();
  const auto r = RunCli("diagnose " + Q(dir / "campaign.toml") + " --json -");
  INFO(r.err);
  REQUIRE(r.status == 0);
  return nlohmann::json::parse(r.out);
}

/// Session s1: the square set 230620202042 and the circular set 250620202104.
nlohmann::json DiagnoseS1(const std::vector<std::string>& effects, std::uint64_t seed) {
  return DiagnoseSession({"square/230620202042", "circular/250620202104"}, effects, seed);
}

/// The recordings of session s1 (for the injection checks).
std::vector<std::filesystem::path> ImportedS1() { return Imported({"square/230620202042", "circular/250620202104"}); }

double Param(const nlohmann::json& j, const std::string& effect, const std::string& key) {
  for (const auto& c : j["candidates"])
    if (c["effect"] == effect) return c["params"].value(key, std::nan(""));
  return std::nan("");
}

/// Session s5 (Ivanjko paths and circles; harness tuning) with `effects`
/// injected (seed 109), each diagnosed once.
const nlohmann::json& S5(const std::vector<std::string>& effects) {
  static std::map<std::vector<std::string>, nlohmann::json> done;
  if (!done.count(effects))
    done[effects] = DiagnoseSession({"ivanjko/250620201618", "ivanjko/250620201636", "circular/250620202317",
                                     "circular/250620202345"},
                                    effects, 109);
  return done[effects];
}

bool Named(const nlohmann::json& j, const std::string& effect) {
  for (const auto& e : j["verdict"]["effects"])
    if (e == effect) return true;
  return false;
}

}  // namespace

TEST_CASE("injection into real runs follows the contract's definitions", "[inject][june]") {
  auto recorded = umbmark_bench::ReadTrajectory(ImportedS1()[0].string());  // the six squares
  const auto inject = [&](const std::string& effect) {
    auto tab = recorded;
    InjectOptions o;
    o.effects = {ParseEffect(effect)};
    umbmark_bench::InjectTable(tab, o);
    return tab;
  };
  const auto pose = [](const umbmark_bench::TrajectoryTable& t, std::size_t i) {
    return Pose2{std::stod(t.rows[i][t.x]), std::stod(t.rows[i][t.y]), std::stod(t.rows[i][t.th])};
  };
  const std::size_t n = recorded.rows.size();
  REQUIRE(n > 10000);

  SECTION("gt_offset: every sample reports the point (dx, dy) of the robot frame") {
    const auto tab = inject("gt_offset:dx=0.04,dy=-0.025");
    double worst = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const Pose2 p = pose(recorded, i), q = pose(tab, i);
      const double ex = p.x + 0.04 * std::cos(p.th) + 0.025 * std::sin(p.th);
      const double ey = p.y + 0.04 * std::sin(p.th) - 0.025 * std::cos(p.th);
      worst = std::max({worst, std::abs(q.x - ex), std::abs(q.y - ey), std::abs(q.th - p.th)});
    }
    CHECK(worst < 1e-8);
  }
  SECTION("time_offset tau = 0.1 s (two 20 Hz samples): a sample shows the recorded pose of two samples before") {
    const auto tab = inject("time_offset:tau=0.1");
    double shift = 0.0, miss = 0.0;
    int moving = 0;
    for (std::size_t i = 2; i < n; ++i) {
      if (recorded.rows[i][recorded.run] != recorded.rows[i - 2][recorded.run]) continue;
      const Pose2 now = pose(recorded, i), before = pose(recorded, i - 2), q = pose(tab, i);
      const double d = std::hypot(now.x - before.x, now.y - before.y);
      if (d < 0.003) continue;  // moving at 0.03 m/s or faster (legs: 0.05 m/s)
      ++moving;
      shift += d;
      miss += std::hypot(q.x - before.x, q.y - before.y);
    }
    INFO("moving samples " << moving << ", mean shift " << shift / moving << " m, left " << miss / moving << " m");
    REQUIRE(moving > 3000);
    // The shift is about 5 mm; what is left (measured 0.47 mm) is the
    // capture noise of two samples and the robot's own motion the wheels do
    // not show over 0.1 s; without the offset it would be the whole shift.
    CHECK(shift / moving > 0.004);
    CHECK(miss < 0.2 * shift);
  }
  SECTION("castor_kick: the heading jumps by kappa at every start of a leg, and nowhere else") {
    auto tab = recorded;
    InjectOptions o;
    o.effects = {ParseEffect("castor_kick:kappa=0.01")};
    const auto sum = umbmark_bench::InjectTable(tab, o);
    int jumps = 0;
    double off = 0.0;  // largest change of the heading difference that is no kick
    for (std::size_t i = 1; i < n; ++i) {
      if (recorded.rows[i][recorded.run] != recorded.rows[i - 1][recorded.run]) continue;
      const double step = (pose(tab, i).th - pose(recorded, i).th) - (pose(tab, i - 1).th - pose(recorded, i - 1).th);
      if (std::abs(step - 0.01) < 1e-6) ++jumps;
      else off = std::max(off, std::abs(step));
    }
    CHECK(jumps == sum.starts_kicked);
    CHECK(jumps >= 24);  // six squares of four legs (and a few one-wheel starts of a few mm)
    CHECK(off < 1e-6);
  }
  SECTION("scale_error and turn_scrub: legs longer by s, spot turns short by k of the wheels' travel") {
    umbmark_bench::RecordedRun run;  // run 1 of the squares
    for (std::size_t i = 0; i < n && recorded.rows[i][recorded.run] == recorded.rows[0][recorded.run]; ++i) {
      run.t.push_back(std::stod(recorded.rows[i][recorded.t]));
      run.wl.push_back(std::stod(recorded.rows[i][recorded.left]) * kPi * 0.084 / 2796.8);
      run.wr.push_back(std::stod(recorded.rows[i][recorded.right]) * kPi * 0.084 / 2796.8);
      run.gt.push_back(pose(recorded, i));
      run.has_gt.push_back(true);
    }
    const auto motions = umbmark_bench::SegmentMotions(run, InjectOptions{});
    const auto scaled = inject("scale_error:s=0.015"), scrubbed = inject("turn_scrub:k=0.05");
    int legs = 0, turns = 0;
    for (const auto& m : motions) {
      const auto a = static_cast<std::size_t>(m.first - 1), b = static_cast<std::size_t>(m.last);
      const double sL = run.wl[b] - run.wl[a], sR = run.wr[b] - run.wr[a];
      if (!m.turn) {
        legs += 0.5 * (sL + sR) > 0.5 ? 1 : 0;  // besides the legs: one-wheel nudges of a few mm
        const double d0 = std::hypot(run.gt[b].x - run.gt[a].x, run.gt[b].y - run.gt[a].y);
        const Pose2 p = pose(scaled, a), q = pose(scaled, b);
        CHECK(std::abs(std::hypot(q.x - p.x, q.y - p.y) - d0 - 0.015 * 0.5 * (sL + sR)) < 2e-4);
      } else {
        ++turns;
        const double dth0 = run.gt[b].th - run.gt[a].th;
        CHECK(std::abs(pose(scrubbed, b).th - pose(scrubbed, a).th - dth0 + 0.05 * (sR - sL) / 0.2) < 5e-4);
      }
    }
    CHECK(legs == 4);   // a square: four legs of 0.75 m and four spot turns
    CHECK(turns == 4);
  }
}

TEST_CASE("castor_kick: a kick at EVERY start from standstill the encoders show, creeps included (contract)",
          "[inject][june]") {
  const auto recorded = umbmark_bench::ReadTrajectory(ImportedS1()[0].string());  // the six squares
  const std::size_t n = recorded.rows.size();
  const auto pose = [](const umbmark_bench::TrajectoryTable& t, std::size_t i) {
    return Pose2{std::stod(t.rows[i][t.x]), std::stod(t.rows[i][t.y]), std::stod(t.rows[i][t.th])};
  };
  // Issue 28: the contract's standstill is the encoders reading still (here
  // 0.1 s, two 20 Hz intervals); every start after one that is no spot turn
  // kicks by +-kappa. The squares' one-wheel creeps of a millimetre before a
  // leg are such starts (the injector used to fold them into the
  // standstill: 29 kicks where these runs hold 54 starts). Counted here
  // from the ticks alone.
  auto tab = recorded;
  InjectOptions o;
  o.effects = {ParseEffect("castor_kick:kappa=0.01")};
  umbmark_bench::InjectTable(tab, o);
  const auto ticks = [&](std::size_t i, int col) { return std::stod(recorded.rows[i][col]); };
  const auto t = [&](std::size_t i) { return std::stod(recorded.rows[i][recorded.t]); };
  const auto moves = [&](std::size_t i) {
    return ticks(i, recorded.left) != ticks(i - 1, recorded.left) ||
           ticks(i, recorded.right) != ticks(i - 1, recorded.right);
  };
  std::vector<double> expected(n, 0.0);
  int starts = 0, creeps = 0;
  for (std::size_t a = 0; a < n;) {
    std::size_t e = a;
    while (e < n && recorded.rows[e][recorded.run] == recorded.rows[a][recorded.run]) ++e;
    // Motions of run [a, e): moving samples joined across still gaps under 0.1 s.
    for (std::size_t i = a + 1; i < e;) {
      if (!moves(i)) { ++i; continue; }
      std::size_t last = i, j = i + 1;
      while (j < e) {
        if (moves(j)) { last = j++; continue; }
        std::size_t k = j;
        while (k < e && !moves(k)) ++k;
        // As the injector reads it, to the bit: the imported clock is not
        // exact (0.0500000000000007), so of the still gaps of exactly two
        // intervals some reach 0.1 s and some fall short (with a 1e-9 s
        // tolerance: 64 starts, not 54; docs/diagnosis.md).
        if (k >= e || t(k - 1) - t(j - 1) >= 0.1) break;
        j = k;
      }
      const double sL = ticks(last, recorded.left) - ticks(i - 1, recorded.left);
      const double sR = ticks(last, recorded.right) - ticks(i - 1, recorded.right);
      if (std::abs(sL + sR) > 0.25 * std::abs(sR - sL)) {
        expected[i] = (sL + sR >= 0.0 ? 1.0 : -1.0) * 0.01;
        ++starts;
        creeps += std::max(std::abs(sL), std::abs(sR)) * kPi * 0.084 / 2796.8 < 0.002 ? 1 : 0;
      }
      i = last + 1;
    }
    a = e;
  }
  double worst = 0.0;
  int kicked = 0;
  for (std::size_t i = 1; i < n; ++i) {
    if (recorded.rows[i][recorded.run] != recorded.rows[i - 1][recorded.run]) continue;
    const double step = (pose(tab, i).th - pose(recorded, i).th) - (pose(tab, i - 1).th - pose(recorded, i - 1).th);
    worst = std::max(worst, std::abs(step - expected[i]));
    kicked += std::abs(step) > 0.005 ? 1 : 0;
  }
  INFO(starts << " starts from standstill, " << creeps << " of them creeps under 2 mm, " << kicked << " kicked");
  CHECK(starts == 54);  // 24 legs and 30 creeps or splits
  CHECK(creeps >= 20);  // measured 24: before, none of these was kicked (29 kicks)
  CHECK(kicked == starts);
  CHECK(worst < 1e-6);
}

TEST_CASE("diagnose names and sizes effects injected into a real session", "[diagnose][inject][june]") {
  // Chosen from the harness' rows for s1 on main d00203a (docs/diagnosis.md):
  // these three are named there with sizes 0.95x, 1.01x and a marker error
  // of 4.7 mm; time_offset (not named on s1, sized 0.71x) and the noise
  // effects are left to the harness.
  static const auto base = DiagnoseS1({}, 0);  // once for the three sections
  const auto sized = [&](const nlohmann::json& j, const std::string& effect, const std::string& key) {
    return Param(j, effect, key) - Param(base, effect, key);
  };
  SECTION("gt_offset (-30, +30) mm: named, the marker within 25 % of its distance") {
    const auto j = DiagnoseS1({"gt_offset:dx=-0.03,dy=0.03"}, 104);
    INFO(j["verdict"].dump());
    CHECK(j["verdict"]["effect"] != "none");
    CHECK(Named(j, "gt_offset"));
    CHECK(std::hypot(sized(j, "gt_offset", "dx") + 0.03, sized(j, "gt_offset", "dy") - 0.03) <
          0.25 * std::hypot(0.03, 0.03));
  }
  SECTION("turn_scrub k = 0.05: named, k within 25 %") {
    const auto j = DiagnoseS1({"turn_scrub:k=0.05"}, 106);
    INFO(j["verdict"].dump());
    CHECK(j["verdict"]["effect"] != "none");
    CHECK(Named(j, "turn_scrub"));
    CHECK_THAT(sized(j, "turn_scrub", "k"), Catch::Matchers::WithinAbs(0.05, 0.0125));
  }
  SECTION("time_offset -60 ms: no run is faulty (the screen's suspect is cleared under the explained model)") {
    // Issue 28: under the baseline, run 1 of the circles stood out by its
    // clock (z = 13.9 against 11.4) and was left out as faulty, though the
    // clock acts on every run; under the explained model it does not stand
    // out, and the note says so. With the ground truth's noise from the
    // standstills (issue 28 item 2) the screen suspects no run at all: no
    // run is left out and no note speaks of one.
    const auto j = DiagnoseS1({"time_offset:tau=-0.06"}, 102);
    INFO(j["notes"].dump());
    CHECK(j["run_faults"].empty());
    for (const auto& n : j["notes"]) CHECK(n.get<std::string>().find("left out of every fit") == std::string::npos);
  }
  SECTION("without injection the per-run clock is fitted at 0, and its check says there is nothing to check") {
    // It used to read "on all pieces 0.0 ms: the moving samples carry the
    // evidence" (docs/diagnosis.md, the per-run clock checked where it is
    // fitted).
    bool seen = false;
    for (const auto& c : base["candidates"])
      if (c["effect"] == "run_time_offset") {
        seen = true;
        CHECK(c["params"]["tau_sd"].get<double>() == 0.0);
        const std::string text = c["clock_check"]["evidence"].get<std::string>();
        INFO(text);
        CHECK(text.rfind("fitted at 0 on all pieces, so there is no per-run clock to check", 0) == 0);
        CHECK(text.find("carry the evidence") == std::string::npos);
      }
    CHECK(seen);
  }
  SECTION("castor_kick and castor_swivel kappa = 10 mrad: sized within 25 %") {
    // Issue 28: with the kicks at the contract's starts (creeps included),
    // s1 sizes them 11.9 and 9.95 mrad; with the creeps folded into the
    // standstills they came back as 3.1 and 0.08 mrad (0.23x, 0.01x).
    const auto kick = DiagnoseS1({"castor_kick:kappa=0.01"}, 112);
    CHECK_THAT(sized(kick, "castor_kick", "kappa"), Catch::Matchers::WithinAbs(0.01, 0.0025));
    const auto swivel = DiagnoseS1({"castor_swivel:kappa=0.01"}, 117);
    CHECK_THAT(sized(swivel, "castor_swivel", "kappa"), Catch::Matchers::WithinAbs(0.01, 0.0025));
  }
  SECTION("scale_error s = +1.5 %: named, s within 25 %") {
    const auto j = DiagnoseS1({"scale_error:s=0.015"}, 108);
    INFO(j["verdict"].dump());
    CHECK(j["verdict"]["effect"] != "none");
    CHECK(Named(j, "scale_error"));
    CHECK_THAT(sized(j, "scale_error", "s"), Catch::Matchers::WithinAbs(0.015, 0.00375));
  }
}

TEST_CASE("a clock common to all runs comes before the spread of the runs' clocks about it (real s1)",
          "[diagnose][inject][june]") {
  // Session 22 (docs/diagnosis.md, "The mean before the spread about it"):
  // with +80 ms injected into every run of s1 (the harness' seed), the
  // per-run clock (zero-mean by the contract, tau_sd = 110 ms) took the
  // common offset as spread and was the verdict; time_offset, tried after
  // it, lost 27 nats held out and was never named. run_time_offset is now
  // tried only once time_offset is chosen or may not be a step.
  const auto clock = DiagnoseS1({"time_offset:tau=0.08"}, 101);
  INFO(clock["verdict"].dump());
  CHECK(clock["verdict"]["effect"] == "time_offset");
  CHECK_FALSE(Named(clock, "run_time_offset"));
  REQUIRE_FALSE(clock["explanation"].empty());
  CHECK(clock["explanation"][0]["effect"] == "time_offset");
  CHECK_THAT(clock["explanation"][0]["params"]["tau"].get<double>(), Catch::Matchers::WithinAbs(0.08, 0.02));
  // A per-run clock alone (tau_sd = 120 ms, no common one) is still named as
  // the spread it is.
  const auto spread = DiagnoseS1({"run_time_offset:tau_sd=0.12"}, 103);
  INFO(spread["verdict"].dump());
  CHECK(spread["verdict"]["effect"] == "run_time_offset");
}

TEST_CASE("a fit outside its physical range, within its standard errors, is a step but never named (real s5)",
          "[diagnose][inject][june]") {
  // Session s5 (Ivanjko paths and circles; harness tuning) with a +1.5 %
  // scale error: the explanation adds a turn scrub at k of about -0.005.
  // Its single fit's standard error excuses the sign (not a symptom), but
  // a negative scrub ("spot turns turn 0.5 % MORE than the wheels say") is
  // no cause a robot can have: a step, listed, never named. Before, it was
  // named beside the injected scale error (an invention on 4 of the
  // harness's 10 tuning injections on s5).
  const nlohmann::json& j = S5({"scale_error:s=0.015"});
  INFO(j["verdict"].dump());
  const nlohmann::json* scrub = nullptr;
  for (const auto& e : j["explanation"])
    if (e["effect"] == "turn_scrub") scrub = &e;
  REQUIRE(scrub != nullptr);
  CHECK((*scrub)["params"]["k"].get<double>() < 0.0);
  REQUIRE(scrub->contains("outside_range"));
  CHECK((*scrub)["outside_range"].get<std::string>().find("negative turn scrub") != std::string::npos);
  CHECK_FALSE(scrub->contains("unphysical"));
  CHECK_FALSE(Named(j, "turn_scrub"));
  CHECK(Named(j, "scale_error"));
  CHECK(j["verdict"]["reason"].get<std::string>().find("fitted outside the physical range") != std::string::npos);
}

TEST_CASE("a note says when the baseline's wheel noise took a mean effect in (real s5, +1.5 % scale error)",
          "[diagnose][inject][june]") {
  // The baseline fits k_L, k_R with E_d, E_b: the injected scale error goes
  // into them (k_L about twice the session's own), and the gap score G
  // measured against that baseline hardly sees it. The note gives the k
  // the pieces show once the explanation's mean effects are fitted, which
  // must come back to the session's own wheel noise: the baseline's k of
  // the same session without injection (within 30 %), while the injected
  // session's baseline is more than 1.5 x off it.
  const nlohmann::json& j = S5({"scale_error:s=0.015"});
  const nlohmann::json& own = S5({});
  std::string note;
  for (const auto& n : j["notes"])
    if (n.get<std::string>().rfind("the baseline's wheel noise (k_L", 0) == 0) note = n.get<std::string>();
  INFO(note);
  REQUIRE_FALSE(note.empty());
  const std::string key = "fitted (k_L = ";
  const auto at = note.find(key);
  REQUIRE(at != std::string::npos);
  const double k_L = std::stod(note.substr(at + key.size()));
  const double own_k_L = own["baseline"]["k_L"].get<double>();
  CHECK_THAT(k_L, Catch::Matchers::WithinRel(own_k_L, 0.3));
  CHECK(j["baseline"]["k_L"].get<double>() > 1.5 * own_k_L);
  CHECK(note.find("scale_error") != std::string::npos);
}

TEST_CASE("where the baseline took the effect in, the shrinks are measured against its mean seen with the mean "
          "effects' wheel noise (real s5, +1.5 % scale error)",
          "[diagnose][inject][june]") {
  // Measured against the baseline, whose k_L took the injected scale error
  // in, the explanation closes less than the larger part of the gap
  // (-28 % before session 21) and the verdict was `unexplained`, though the
  // scale error earns about 100 nats held out. Against the baseline's mean
  // seen with the wheel noise left once the explanation's mean effects are
  // fitted it closes the larger part and leads (docs/diagnosis.md, "The
  // shrink's reference"); the JSON says which reference, and the shrink
  // against the baseline itself.
  const nlohmann::json& j = S5({"scale_error:s=0.015"});
  INFO(j["verdict"].dump());
  const auto& v = j["verdict"];
  REQUIRE_FALSE(j["explanation"].empty());
  CHECK(v["effect"] == "scale_error");
  CHECK(v["shrink_reference"] == "mean_effects_wheel_noise");
  const double against_reference = j["explanation"].back()["cumulative_heldout_shrink"].get<double>();
  CHECK(against_reference >= 0.5);
  CHECK(v["heldout_shrink_against_baseline"].get<double>() < 0.5);
  CHECK_THAT(v["unexplained_fraction"].get<double>(), Catch::Matchers::WithinAbs(1.0 - against_reference, 1e-9));
  double earned = 0.0;
  for (const auto& e : j["explanation"])
    if (e["effect"] == "scale_error") earned = e["earned_given_others_nats"].get<double>();
  CHECK(earned > 50.0);
  // The same session without injection: its own -0.3 % scale error is
  // named too (before: `unexplained`, the explanation closing -55 % of the
  // baseline's held-out gap, 81 % of the reference's), so the injected
  // session and its own agree on the effect, at a different size.
  const nlohmann::json& own = S5({});
  INFO(own["verdict"].dump());
  CHECK(own["verdict"]["effect"] == "scale_error");
  CHECK(own["verdict"]["shrink_reference"] == "mean_effects_wheel_noise");
}
