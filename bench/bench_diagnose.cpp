// Blind validation benchmark of `umbmark diagnose`: for every contract
// effect, for no effect, and for two effects outside the contract's list,
// simulate campaigns of random robots with random systematic errors, noise
// and effect magnitudes in realistic ranges, hide the truth, diagnose, and
// report the confusion matrix, top-1 accuracy on listed effects, the
// false-alarm rate on clean campaigns, the `unexplained` rate on outside
// effects, the median heldout_shrink and the time per diagnosis.
//
// Standard campaign (the issue's): 10 cw + 10 ccw squares and 20
// back-and-forth runs, trajectories with ground truth. The design varies:
// each campaign gets a free experiment of 4 figure-eight runs (arcs) with
// probability --arc-fraction (default 0.5, drawn from a stream of its own
// so the other draws do not change; --extended: every campaign). Arcs
// separate turn_scrub from a wheelbase error; without them the two are the
// same ground truth (spot turns only), so the expected answer for a
// turn_scrub campaign without arcs is `none` with the diagnosis' note that
// a scrub is inside the fitted wheelbase (design_check.hpp) -- scored as
// such, not dropped; naming turn_scrub there counts too (the truth, when
// the spot turns' small forward motion gives it held-out evidence).
//
// Random draws (uniform unless stated; "+-" = random sign):
//   robot      wheelbase 0.2-0.6 m, wheel diameter 0.06-0.2 m (both nominal
//              equal), ticks 500-20000 per wheel revolution
//   truth      E_d = 1 +- 0-0.01, E_b = 1 +- 0-0.03, k_L, k_R log-uniform
//              3e-4-3e-3 m^1/2 (independently), ground truth sigma_xy
//              0.1-0.5 mm, sigma_theta 0.5-3 mrad (stated in the manifest)
//   motion     square side 2-4 m, back-and-forth distance 2-5 m, speed
//              0.2-0.5 m/s, spot turns 0.5-1.5 rad/s, 20-50 Hz, 1 s pauses
//   effects    scale_error s +-0.005-0.03; turn_scrub k 0.02-0.10;
//              direction_asymmetry a +-0.005-0.03; castor_kick kappa
//              +-0.003-0.02 rad; bump_outliers rate 0.2-1 /m, sigma 3-10 mm;
//              correlated_noise rho +-0.5-0.9; parameter_drift r
//              +-5e-5-5e-4 per run; gt_offset |(dx, dy)| 0.01-0.05 m in a
//              random direction; time_offset tau +-0.02-0.1 s;
//              standstill_motion sigma_xy, sigma_theta 2-10 mm / mrad;
//              motion_noise_floor sigma 2-10 mm; run_time_offset tau_sd
//              0.02-0.1 s; stop_slide d 0.03-0.12 s^2/m, a 0.005-0.02
//              s^2/rad; castor_swivel kappa +-0.003-0.02 rad (these two
//              classes last, so that the others keep their campaigns);
//   outside    gt_yaw_misalignment delta +-0.005-0.02 rad; floor_slope g
//              0.002-0.01 m/m towards a random direction
//
// Classes beyond the catalogue's (--classes): `negligible` (500 ticks/rev,
// k_L = k_R 2-5e-3 m^1/2, ground truth 0.8 mm / 0.15 deg, plus one of a
// 0.1-0.8 mm marker offset, a 1-2 ms time offset, a 0.5-2e-4 scale error;
// --clean campaigns; target verdict `none`), `pair_castor_bumps` and
// `pair_time_gt` (both effects at the single ranges; both must be in
// verdict.effects), and the baseline-mode classes `base_*` (MakeBaselineCase:
// `diagnose --baseline` with the user's model one parameter off; base_ok
// has --clean campaigns).
//
// Usage: bench_diagnose [--per-class N] [--clean N] [--seed S] [--threads T]
//                       [--null-sims B] [--extended] [--classes a,b,...]
//                       [--json FILE] [--write-dir DIR] [--only-case I]
//                       [--pause S]  (standstill between motions, default 1 s)
//                       [--arc-fraction F]  (campaigns with figure-eights, default 0.5)
//                       [--hold-wheel-noise]  (diagnose --hold-wheel-noise)
// --write-dir also writes every campaign (manifest + CSV; truth.json beside,
// not inside) so the same cases can be diagnosed through the CLI.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "core/angles.hpp"
#include "diagnosis/pieces.hpp"
#include "diagnosis/diagnose.hpp"
#include "output/atomic_write.hpp"
#include "formats/campaign_writer.hpp"
#include "simulation/campaign_sim.hpp"
#include "simulation/effects.hpp"

using namespace umbmark;

namespace {

struct Args {
  int per_class = 20;
  int clean = 60;
  std::uint64_t seed = 2024;
  int threads = 2;
  int null_sims = 500;
  bool extended = false;
  std::vector<std::string> classes;
  std::string json;
  std::string write_dir;
  int only_case = -1;
  double pause_s = 1.0;
  double arc_fraction = 0.5;
  bool hold_wheel_noise = false;  ///< diagnose --hold-wheel-noise
};

Args Parse(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        fmt::print(stderr, "missing value after {}\n", k);
        std::exit(2);
      }
      return argv[++i];
    };
    if (k == "--per-class") a.per_class = std::stoi(next());
    else if (k == "--clean") a.clean = std::stoi(next());
    else if (k == "--seed") a.seed = std::stoull(next());
    else if (k == "--threads") a.threads = std::stoi(next());
    else if (k == "--null-sims") a.null_sims = std::stoi(next());
    else if (k == "--extended") a.extended = true;
    else if (k == "--hold-wheel-noise") a.hold_wheel_noise = true;
    else if (k == "--json") a.json = next();
    else if (k == "--write-dir") a.write_dir = next();
    else if (k == "--only-case") a.only_case = std::stoi(next());
    else if (k == "--pause") a.pause_s = std::stod(next());
    else if (k == "--arc-fraction") a.arc_fraction = std::stod(next());
    else if (k == "--classes") {
      std::string s = next();
      std::size_t p = 0;
      while (p <= s.size()) {
        const std::size_t q = s.find(',', p);
        a.classes.push_back(s.substr(p, q == std::string::npos ? std::string::npos : q - p));
        if (q == std::string::npos) break;
        p = q + 1;
      }
    } else {
      fmt::print(stderr, "unknown argument {}\n", k);
      std::exit(2);
    }
  }
  return a;
}

struct Case {
  std::string truth;  ///< "none", a contract effect, an outside effect, or a base_* class
  bool outside = false;
  /// Baseline-mode classes (`diagnose --baseline`): the given model, and
  /// what the verdict must name (`expected` empty: `none`).
  std::optional<diag::GivenModel> given;
  std::vector<std::string> expected;
  /// base_noise_left / base_noise_right: the wheel whose k is wrong ('L',
  /// 'R'); wheel_noise_error counts only with that wheel's ratio the one off.
  char wrong_wheel = 0;
  std::uint64_t seed = 0;
  sim::CampaignSimOptions sim;
  Manifest manifest;
  /// Design: a free experiment of figure-eights (arcs) or spot turns only.
  bool arcs = false;
  /// The right verdict for a single or outside effect (the truth; outside
  /// effects `unexplained`; turn_scrub without arcs `none` plus the note).
  std::string expected_verdict;
  bool expect_scrub_note = false;
};

/// The diagnosis' note that a turn scrub is inside the fitted wheelbase.
constexpr const char* kScrubNote = "turn_scrub is indistinguishable from the fitted wheelbase";

double U(std::mt19937_64& g, double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(g); }
double Sign(std::mt19937_64& g) { return U(g, 0.0, 1.0) < 0.5 ? -1.0 : 1.0; }
double LogU(std::mt19937_64& g, double lo, double hi) { return std::exp(U(g, std::log(lo), std::log(hi))); }

/// Baseline-mode classes: the user's model (CAL.json parameters and k_L,
/// k_R) is the true robot with one parameter wrong by a realistic amount --
///   base_ok                none wrong (target `none`)
///   base_wheelbase         wheelbase +-0.5-2 % (1-12 mm)
///   base_ratio             D_R/D_L +-1000-5000 ppm, mean diameter kept
///   base_noise             k_L, k_R both x2 or both x0.5
///   base_noise_left        k_L alone x2 or x0.5 (k_R right)
///   base_noise_right       k_R alone x2 or x0.5 (k_L right)
///   base_wheelbase_castor  base_wheelbase + castor_kick kappa +-0.005-0.02 rad
///   base_ratio_gt_offset   base_ratio + gt_offset |(dx, dy)| 0.01-0.05 m
/// -- and the verdict must name every wrong parameter and effect.
void MakeBaselineCase(std::mt19937_64& g, Case& c) {
  const sim::CampaignSimOptions& o = c.sim;
  const RobotParams& rec = c.manifest.robot;
  diag::GivenModel m;
  m.params = rec;
  m.params.wheelbase_m = rec.wheelbase_m * o.truth.E_b;
  m.params.wheel_diameter_left_m = rec.wheel_diameter_left_m * 2.0 / (o.truth.E_d + 1.0);
  m.params.wheel_diameter_right_m = rec.wheel_diameter_right_m * 2.0 * o.truth.E_d / (o.truth.E_d + 1.0);
  m.source = "CAL.json";
  m.noise_given = true;
  m.k_L = o.truth.k_L;
  m.k_R = o.truth.k_R;
  const std::string& t = c.truth;
  if (t == "base_wheelbase" || t == "base_wheelbase_castor") {
    m.params.wheelbase_m *= 1.0 + Sign(g) * U(g, 0.005, 0.02);
    c.expected.push_back("wheelbase_error");
  }
  if (t == "base_ratio" || t == "base_ratio_gt_offset") {
    const double e = Sign(g) * U(g, 1e-3, 5e-3);
    m.params.wheel_diameter_left_m *= 1.0 - 0.5 * e;
    m.params.wheel_diameter_right_m *= 1.0 + 0.5 * e;
    c.expected.push_back("diameter_ratio_error");
  }
  if (t == "base_noise") {
    const double f = U(g, 0.0, 1.0) < 0.5 ? 2.0 : 0.5;
    m.k_L *= f;
    m.k_R *= f;
    c.expected.push_back("wheel_noise_error");
  }
  if (t == "base_noise_left" || t == "base_noise_right") {
    const double f = U(g, 0.0, 1.0) < 0.5 ? 2.0 : 0.5;
    c.wrong_wheel = t == "base_noise_left" ? 'L' : 'R';
    (c.wrong_wheel == 'L' ? m.k_L : m.k_R) *= f;
    c.expected.push_back("wheel_noise_error");
  }
  sim::Effects& fx = c.sim.effects;
  if (t == "base_wheelbase_castor") {
    fx.castor_kappa = Sign(g) * U(g, 0.005, 0.02);
    c.expected.push_back("castor_kick");
  }
  if (t == "base_ratio_gt_offset") {
    const double r = U(g, 0.01, 0.05), a = U(g, 0.0, 2.0 * kPi);
    fx.gt_dx = r * std::cos(a);
    fx.gt_dy = r * std::sin(a);
    c.expected.push_back("gt_offset");
  }
  c.given = m;
}

Case MakeCase(const std::string& truth, std::uint64_t seed, double arc_fraction, double pause_s) {
  std::mt19937_64 g(seed);
  Case c;
  c.truth = truth;
  c.seed = seed;
  // The design from a stream of its own: the robot and effect draws below
  // are those of a campaign without the choice.
  std::mt19937_64 design(seed ^ 0x9E3779B97F4A7C15ull);
  c.arcs = U(design, 0.0, 1.0) < arc_fraction;
  RobotParams robot;
  robot.wheelbase_m = U(g, 0.2, 0.6);
  const double d = U(g, 0.06, 0.2);
  robot.wheel_diameter_left_m = robot.wheel_diameter_right_m = d;
  robot.ticks_per_rev = std::round(U(g, 500.0, 20000.0));
  GroundTruthNoise gt{U(g, 1e-4, 5e-4), U(g, 0.5e-3, 3e-3)};
  const bool negligible = truth == "negligible";
  if (negligible) {
    // A clean robot with coarse encoders, large wheel noise and a noisy
    // motion capture (0.8 mm, 0.15 deg), plus one mismatch too small to matter.
    robot.ticks_per_rev = 500.0;
    gt = GroundTruthNoise{8e-4, 0.15 * kPi / 180.0};
  }
  c.manifest = sim::StandardCampaignManifest(robot, U(g, 2.0, 4.0), U(g, 2.0, 5.0), gt);
  if (c.arcs) {
    Experiment fr;
    fr.kind = ExperimentKind::kFree;
    fr.file = fr.resolved_file = "figure_eight.csv";
    c.manifest.experiments.push_back(fr);
  }
  sim::CampaignSimOptions& o = c.sim;
  o.seed = seed;
  o.truth.E_d = 1.0 + Sign(g) * U(g, 0.0, 0.01);
  o.truth.E_b = 1.0 + Sign(g) * U(g, 0.0, 0.03);
  o.truth.k_L = LogU(g, 3e-4, 3e-3);
  o.truth.k_R = LogU(g, 3e-4, 3e-3);
  if (negligible) o.truth.k_L = o.truth.k_R = LogU(g, 2e-3, 5e-3);
  o.square_runs_per_direction = 10;
  o.back_and_forth_runs = 20;
  o.free_runs = 4;
  o.sample_rate_hz = std::round(U(g, 20.0, 50.0));
  o.speed_m_s = U(g, 0.2, 0.5);
  o.turn_rate_rad_s = U(g, 0.5, 1.5);
  o.pause_s = pause_s;
  o.free_radius_m = U(g, 0.8, 1.5);
  sim::Effects& fx = o.effects;
  if (negligible) {
    switch (static_cast<int>(U(g, 0.0, 3.0))) {
      case 0: {
        const double r = U(g, 1e-4, 8e-4), a = U(g, 0.0, 2.0 * kPi);
        fx.gt_dx = r * std::cos(a);
        fx.gt_dy = r * std::sin(a);
        break;
      }
      case 1: fx.time_tau = Sign(g) * U(g, 0.001, 0.002); break;
      default: fx.scale_s = Sign(g) * U(g, 5e-5, 2e-4); break;
    }
  }
  if (truth == "pair_castor_bumps") {
    fx.castor_kappa = Sign(g) * U(g, 0.005, 0.02);
    fx.bump_rate = U(g, 0.2, 1.0);
    fx.bump_sigma = U(g, 0.003, 0.01);
  }
  if (truth == "pair_time_gt") {
    fx.time_tau = Sign(g) * U(g, 0.02, 0.1);
    const double r = U(g, 0.01, 0.05), a = U(g, 0.0, 2.0 * kPi);
    fx.gt_dx = r * std::cos(a);
    fx.gt_dy = r * std::sin(a);
  }
  const auto kind = sim::EffectFromString(truth);
  if (kind) {
    c.outside = !sim::Describe(*kind).in_contract;
    switch (*kind) {
      case sim::EffectKind::kScaleError: fx.scale_s = Sign(g) * U(g, 0.005, 0.03); break;
      case sim::EffectKind::kTurnScrub: fx.scrub_k = U(g, 0.02, 0.10); break;
      case sim::EffectKind::kDirectionAsymmetry: fx.asymmetry_a = Sign(g) * U(g, 0.005, 0.03); break;
      case sim::EffectKind::kCastorKick: fx.castor_kappa = Sign(g) * U(g, 0.003, 0.02); break;
      case sim::EffectKind::kBumpOutliers:
        fx.bump_rate = U(g, 0.2, 1.0);
        fx.bump_sigma = U(g, 0.003, 0.01);
        break;
      case sim::EffectKind::kCorrelatedNoise: fx.noise_rho = Sign(g) * U(g, 0.5, 0.9); break;
      case sim::EffectKind::kParameterDrift: fx.drift_r = Sign(g) * U(g, 5e-5, 5e-4); break;
      case sim::EffectKind::kGtOffset: {
        const double r = U(g, 0.01, 0.05), a = U(g, 0.0, 2.0 * kPi);
        fx.gt_dx = r * std::cos(a);
        fx.gt_dy = r * std::sin(a);
        break;
      }
      case sim::EffectKind::kTimeOffset: fx.time_tau = Sign(g) * U(g, 0.02, 0.1); break;
      case sim::EffectKind::kStandstillMotion:
        fx.stand_sigma_xy = U(g, 0.002, 0.01);
        fx.stand_sigma_theta = U(g, 0.002, 0.01);
        break;
      case sim::EffectKind::kMotionNoiseFloor: fx.floor_sigma = U(g, 0.002, 0.01); break;
      case sim::EffectKind::kRunTimeOffset: fx.run_tau_sd = U(g, 0.02, 0.1); break;
      case sim::EffectKind::kStopSlide:
        fx.slide_d = U(g, 0.03, 0.12);
        fx.slide_a = U(g, 0.005, 0.02);
        break;
      case sim::EffectKind::kCastorSwivel: fx.swivel_kappa = Sign(g) * U(g, 0.003, 0.02); break;
      case sim::EffectKind::kGtYawMisalignment: fx.yaw_delta = Sign(g) * U(g, 0.005, 0.02); break;
      case sim::EffectKind::kFloorSlope:
        fx.slope_g = U(g, 0.002, 0.01);
        fx.slope_dir = U(g, 0.0, 2.0 * kPi);
        break;
      case sim::EffectKind::kWheelbaseError:
      case sim::EffectKind::kDiameterRatioError:
      case sim::EffectKind::kWheelNoiseError: break;  // baseline mode: the base_* classes
      case sim::EffectKind::kFirstRunTime: break;  // an effect added at run time: none here
    }
  }
  if (truth.rfind("base_", 0) == 0) MakeBaselineCase(g, c);
  c.expected_verdict = c.outside ? "unexplained" : truth;
  if (truth == "turn_scrub" && !c.arcs) {
    c.expected_verdict = "none";
    c.expect_scrub_note = true;
  }
  return c;
}

double Median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

/// The classes to run: --classes, else every simulated effect with the
/// clean, negligible, pair and baseline-mode classes.
std::vector<std::string> Classes(const Args& args) {
  std::vector<std::string> classes = args.classes;
  if (!classes.empty()) return classes;
  classes.push_back("none");
  // Issue 21's effects come last, so that every other class keeps its
  // campaigns (a case's seed follows its class index).
  const auto late = [](sim::EffectKind k) {
    return k == sim::EffectKind::kStopSlide || k == sim::EffectKind::kCastorSwivel;
  };
  for (const auto& d : sim::EffectCatalogue())
    if (d.simulated && !late(d.kind)) classes.emplace_back(d.name);
  for (const char* b : {"base_ok", "base_wheelbase", "base_ratio", "base_noise", "base_noise_left",
                        "base_noise_right", "base_wheelbase_castor", "base_ratio_gt_offset"})
    classes.emplace_back(b);
  for (const auto& d : sim::EffectCatalogue())
    if (late(d.kind)) classes.emplace_back(d.name);
  return classes;
}

/// --write-dir: the campaign, its truth beside it, and what the verdict
/// must be, so that the same case can be diagnosed through the CLI.
void WriteCase(const std::string& dir, const Case& c, const sim::SimulatedCampaign& campaign) {
  io::WriteCampaign(campaign.manifest, campaign.data, dir + "/campaign");
  nlohmann::json truth = sim::CampaignTruthJson(campaign, c.sim);
  truth["design"] = {{"figure_eights", c.arcs}};
  if (!c.expected_verdict.empty()) truth["expected_verdict"] = c.expected_verdict;
  io::WriteFileAtomically(dir + "/truth.json", truth.dump(2) + "\n");
  // The right verdict when it is not the truth's name (outside effects,
  // turn_scrub without arcs), and the note the diagnosis must give.
  if (!c.given && !c.expected_verdict.empty() && c.expected_verdict != c.truth)
    io::WriteFileAtomically(dir + "/expected_verdict.txt", c.expected_verdict + "\n");
  if (c.expect_scrub_note) io::WriteFileAtomically(dir + "/expected_note.txt", std::string(kScrubNote) + "\n");
  if (!c.given) return;
  // The user's model as `diagnose --baseline` reads it (a calibrate JSON's
  // `parameters`), and its k_L, k_R for --kl/--kr.
  const RobotParams& p = c.given->params;
  io::WriteFileAtomically(dir + "/given.json",
                          nlohmann::json{{"parameters",
                                          {{"wheelbase_m", p.wheelbase_m},
                                           {"wheel_diameter_left_m", p.wheel_diameter_left_m},
                                           {"wheel_diameter_right_m", p.wheel_diameter_right_m}}}}
                                  .dump(2) + "\n");
  io::WriteFileAtomically(dir + "/given_noise.txt", fmt::format("{:.17g} {:.17g}\n", c.given->k_L, c.given->k_R));
  // What the verdict must name (every word; none: `none`).
  io::WriteFileAtomically(dir + "/expected.txt",
                          (c.expected.empty() ? std::string("none") : fmt::format("{}", fmt::join(c.expected, " "))) +
                              "\n");
}

/// The scores over all cases.
struct Tally {
  std::map<std::string, std::map<std::string, int>> confusion;
  nlohmann::json records = nlohmann::json::array();
  std::vector<double> times, heldout_true, heldout_verdict;
  std::map<std::string, std::vector<double>> stage_times;
  int listed = 0, listed_right = 0, listed_no_scrub = 0, listed_no_scrub_right = 0;
  int clean = 0, false_alarms = 0, outside = 0, outside_unexplained = 0;
  int negligible = 0, negligible_none = 0, pairs = 0, pairs_both = 0;
  struct Rate {
    int n = 0, right = 0;
  };
  std::map<std::string, Rate> baseline;
  int base_wrong = 0, base_wrong_named = 0;
  // turn_scrub by design (false: spot turns only, expected `none` + note).
  struct ScrubTally {
    int n = 0, right = 0, noted = 0;
  };
  std::map<bool, ScrubTally> scrub;
  int with_arcs = 0;
};

/// Baseline mode: every wrong parameter and effect of the class named
/// (base_ok: `none`); one wheel's k wrong: the named wheel_noise_error must
/// put the error on that wheel (its ratio k_fit / k_given further from 1)
/// and find the other right (within 25 %, the size below which a noise
/// error is negligible).
void ScoreBaselineMode(const Case& c, const diag::DiagnoseSummary& s, Tally& t) {
  auto named = [&](const std::string& e) {
    return std::find(s.verdict_effects.begin(), s.verdict_effects.end(), e) != s.verdict_effects.end();
  };
  bool all = true;
  for (const auto& e : c.expected) all = all && named(e);
  if (c.wrong_wheel) {
    bool wheel = false;
    for (const auto& e : s.explanation) {
      if (e.effect != sim::EffectKind::kWheelNoiseError) continue;
      const double wrong = e.params.at(c.wrong_wheel == 'L' ? "ratio_L" : "ratio_R");
      const double other = e.params.at(c.wrong_wheel == 'L' ? "ratio_R" : "ratio_L");
      wheel = std::abs(std::log(wrong)) > std::abs(std::log(other)) && std::abs(other - 1.0) < 0.25;
    }
    all = all && wheel;
  }
  const bool ok = c.expected.empty() ? s.verdict == "none" : all;
  Tally::Rate& r = t.baseline[c.truth];
  ++r.n;
  r.right += ok;
  if (!c.expected.empty()) {
    ++t.base_wrong;
    t.base_wrong_named += c.wrong_wheel ? ok : named(c.expected.front());
  }
}

/// Scores one diagnosis into the tally; returns whether the verdict is right.
bool Score(const Case& c, const diag::DiagnoseSummary& s, Tally& t) {
  t.confusion[c.truth][s.verdict] += 1;
  const bool noted = std::any_of(s.notes.begin(), s.notes.end(),
                                 [](const std::string& n) { return n.find(kScrubNote) != std::string::npos; });
  // turn_scrub on spot turns only: `none` with the note, or the scrub
  // itself when its small footprint there (the turns' forward motion,
  // E_d far from 1) gave it held-out evidence.
  const bool right = (s.verdict == c.expected_verdict && (!c.expect_scrub_note || noted)) ||
                     (c.expect_scrub_note && s.verdict == c.truth);
  if (c.truth == "turn_scrub") {
    Tally::ScrubTally& sc = t.scrub[c.arcs];
    ++sc.n;
    sc.right += right;
    sc.noted += noted;
  }
  auto named = [&](const char* e) {
    return std::find(s.verdict_effects.begin(), s.verdict_effects.end(), e) != s.verdict_effects.end();
  };
  if (c.given) {
    ScoreBaselineMode(c, s, t);
  } else if (c.truth == "negligible") {
    ++t.negligible;
    t.negligible_none += s.verdict == "none";
  } else if (c.truth.rfind("pair_", 0) == 0) {
    ++t.pairs;
    t.pairs_both += c.truth == "pair_castor_bumps" ? named("castor_kick") && named("bump_outliers")
                                                   : named("time_offset") && named("gt_offset");
  } else if (c.truth == "none") {
    ++t.clean;
    if (s.verdict != "none") ++t.false_alarms;
  } else if (c.outside) {
    ++t.outside;
    if (right) ++t.outside_unexplained;
  } else {
    ++t.listed;
    t.listed_right += right;
    if (c.truth != "turn_scrub") {
      ++t.listed_no_scrub;
      t.listed_no_scrub_right += right;
    }
    for (const auto& cd : s.candidates) {
      if (sim::EffectToString(cd.effect) == c.truth) t.heldout_true.push_back(cd.heldout_shrink);
      if (sim::EffectToString(cd.effect) == s.verdict) t.heldout_verdict.push_back(cd.heldout_shrink);
    }
  }
  return right;
}

/// One case's record for --json.
nlohmann::json Record(std::size_t i, const Case& c, const sim::SimulatedCampaign& campaign,
                      const diag::DiagnoseSummary& s, bool right, double seconds) {
  nlohmann::json explanation = nlohmann::json::array();
  for (const auto& e : s.explanation)
    explanation.push_back({{"effect", sim::EffectToString(e.effect)}, {"params", e.params}, {"negligible", e.negligible}});
  return {{"case", i},
          {"truth", c.truth},
          {"verdict", s.verdict},
          {"verdict_effects", s.verdict_effects},
          {"figure_eights", c.arcs},
          {"expected_verdict", c.expected_verdict},
          {"right", right},
          {"expected", c.expected},
          {"explanation", explanation},
          {"p_value", s.p_value},
          {"score_p_value", s.score_p_value},
          {"tests_p_value", s.tests_p_value},
          {"gap_score", s.gap_score},
          {"seconds", seconds},
          {"robot",
           {{"wheelbase_m", c.manifest.robot.wheelbase_m},
            {"diameter_m", c.manifest.robot.wheel_diameter_left_m},
            {"ticks_per_rev", *c.manifest.robot.ticks_per_rev}}},
          {"sim_truth", sim::CampaignTruthJson(campaign, c.sim)},
          {"top", s.candidates.empty() ? nlohmann::json(nullptr)
                                       : nlohmann::json{{"effect", sim::EffectToString(s.candidates[0].effect)},
                                                        {"heldout_shrink", s.candidates[0].heldout_shrink},
                                                        {"evidence", s.candidates[0].evidence}}}};
}

double Pct(int a, int b) { return b > 0 ? 100.0 * a / b : std::nan(""); }

/// The confusion matrix and the rates.
void PrintSummary(const Args& args, const std::vector<std::string>& classes, std::size_t n_cases, Tally& t) {
  std::vector<std::string> verdict_names = {"none", "unexplained"};
  for (auto k : sim::ContractEffects()) verdict_names.emplace_back(sim::EffectToString(k));
  for (auto k : sim::ParameterErrorEffects()) verdict_names.emplace_back(sim::EffectToString(k));
  fmt::print("\nConfusion matrix (rows: truth, columns: verdict)\n{:<20}", "");
  for (const auto& v : verdict_names) fmt::print(" {:>6.6}", v);
  fmt::print("\n");
  for (const auto& c : classes) {
    fmt::print("{:<20}", c);
    for (const auto& v : verdict_names) fmt::print(" {:>6d}", t.confusion[c][v]);
    fmt::print("\n");
  }
  fmt::print("\ncampaign: standard{}; {} of {} with 4 figure-eight runs\n",
             args.extended ? " + 4 figure-eight runs (extended)" : "", t.with_arcs, n_cases);
  fmt::print("top-1 accuracy on listed effects:          {:5.1f}% ({}/{})\n", Pct(t.listed_right, t.listed),
             t.listed_right, t.listed);
  fmt::print("  without turn_scrub:                       {:5.1f}% ({}/{})\n",
             Pct(t.listed_no_scrub_right, t.listed_no_scrub), t.listed_no_scrub_right, t.listed_no_scrub);
  fmt::print("  turn_scrub with figure-eights (named):    {:5.1f}% ({}/{})\n", Pct(t.scrub[true].right, t.scrub[true].n),
             t.scrub[true].right, t.scrub[true].n);
  fmt::print("  turn_scrub, spot turns only (none + note): {:5.1f}% ({}/{}; note given {}/{})\n",
             Pct(t.scrub[false].right, t.scrub[false].n), t.scrub[false].right, t.scrub[false].n, t.scrub[false].noted,
             t.scrub[false].n);
  fmt::print("false alarms on clean campaigns:           {:5.1f}% ({}/{})\n", Pct(t.false_alarms, t.clean),
             t.false_alarms, t.clean);
  fmt::print("'unexplained' on outside effects:          {:5.1f}% ({}/{})\n", Pct(t.outside_unexplained, t.outside),
             t.outside_unexplained, t.outside);
  fmt::print("'none' on negligible-mismatch campaigns:   {:5.1f}% ({}/{})\n", Pct(t.negligible_none, t.negligible),
             t.negligible_none, t.negligible);
  fmt::print("both effects named on pair campaigns:      {:5.1f}% ({}/{})\n", Pct(t.pairs_both, t.pairs), t.pairs_both,
             t.pairs);
  fmt::print("baseline mode (--baseline CAL.json --kl --kr; all of the class's wrong parameters and effects named, "
             "base_ok: none):\n");
  for (const auto& [cls, r] : t.baseline) fmt::print("  {:<24} {:5.1f}% ({}/{})\n", cls, Pct(r.right, r.n), r.right, r.n);
  fmt::print("baseline mode, wrong parameter named:      {:5.1f}% ({}/{})\n", Pct(t.base_wrong_named, t.base_wrong),
             t.base_wrong_named, t.base_wrong);
  fmt::print("median heldout_shrink (true effect):       {:.3f}\n", Median(t.heldout_true));
  fmt::print("median heldout_shrink (verdict's effect):  {:.3f}\n", Median(t.heldout_verdict));
  fmt::print("time per diagnosis: median {:.2f} s, max {:.2f} s\n", Median(t.times),
             t.times.empty() ? 0.0 : *std::max_element(t.times.begin(), t.times.end()));
  for (const auto& [stage, v] : t.stage_times) fmt::print("  {:<42} median {:.3f} s\n", stage, Median(v));
}

void WriteJson(const Args& args, const Tally& t) {
  nlohmann::json summary = {{"extended", args.extended},
                            {"arc_fraction", args.extended ? 1.0 : args.arc_fraction},
                            {"seed", args.seed},
                            {"top1_listed", Pct(t.listed_right, t.listed) / 100.0},
                            {"top1_listed_without_turn_scrub", Pct(t.listed_no_scrub_right, t.listed_no_scrub) / 100.0},
                            {"false_alarm_rate", Pct(t.false_alarms, t.clean) / 100.0},
                            {"outside_unexplained_rate", Pct(t.outside_unexplained, t.outside) / 100.0},
                            {"negligible_none_rate", Pct(t.negligible_none, t.negligible) / 100.0},
                            {"pairs_both_named_rate", Pct(t.pairs_both, t.pairs) / 100.0},
                            {"baseline_wrong_parameter_named_rate", Pct(t.base_wrong_named, t.base_wrong) / 100.0},
                            {"median_heldout_shrink_true", Median(t.heldout_true)},
                            {"median_heldout_shrink_verdict", Median(t.heldout_verdict)},
                            {"median_seconds", Median(t.times)},
                            {"confusion", t.confusion},
                            {"cases", t.records}};
  io::WriteFileAtomically(args.json, summary.dump(1) + "\n");
}

}  // namespace

int main(int argc, char** argv) {
  const Args args = Parse(argc, argv);
  const std::vector<std::string> classes = Classes(args);
  std::vector<Case> cases;
  for (std::size_t ci = 0; ci < classes.size(); ++ci) {
    const int count =
        classes[ci] == "none" || classes[ci] == "negligible" || classes[ci] == "base_ok" ? args.clean : args.per_class;
    for (int i = 0; i < count; ++i)
      cases.push_back(MakeCase(classes[ci], args.seed * 1000003ull + ci * 10007ull + static_cast<std::uint64_t>(i),
                               args.extended ? 1.0 : args.arc_fraction, args.pause_s));
  }
  diag::DiagnoseOptions dopt;
  dopt.threads = args.threads;
  dopt.null_simulations = args.null_sims;
  if (args.hold_wheel_noise) dopt.baseline_fit.wheel = diag::WheelNoiseSource::kRepeats;
  Tally t;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const Case& c = cases[i];
    if (args.only_case >= 0 && static_cast<int>(i) != args.only_case) continue;
    const sim::SimulatedCampaign campaign = sim::SimulateCampaign(c.manifest, c.sim);
    t.with_arcs += c.arcs;
    if (!args.write_dir.empty()) WriteCase(fmt::format("{}/{:03d}_{}", args.write_dir, i, c.truth), c, campaign);
    // Blind: the diagnosis sees the manifest and the data only.
    const auto t0 = std::chrono::steady_clock::now();
    const diag::CampaignData data = diag::BuildCampaign(campaign.manifest, campaign.data, dopt.pieces);
    diag::DiagnoseOptions o = dopt;
    o.seed = c.seed;
    o.given = c.given;
    const diag::DiagnoseSummary s = diag::Diagnose(data, o);
    const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    t.times.push_back(dt);
    for (const auto& [stage, v] : s.timings) t.stage_times[stage].push_back(v);
    const bool right = Score(c, s, t);
    t.records.push_back(Record(i, c, campaign, s, right, dt));
    fmt::print("{:4d} {:<20} -> {:<20} p={:<7.4f} G={:<10.1f} {:.2f}s  effects: {}\n", i, c.truth, s.verdict,
               s.p_value, s.gap_score, dt, fmt::join(s.verdict_effects, " + "));
    std::fflush(stdout);
  }
  PrintSummary(args, classes, cases.size(), t);
  if (!args.json.empty()) WriteJson(args, t);
  return 0;
}
