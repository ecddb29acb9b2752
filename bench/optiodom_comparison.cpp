// Calibration quality on real data: for each OptiOdom square dataset,
// calibrate with classic UMBmark (x and mean estimators) and with the refined
// fit (endpoint return errors and full trajectories), then evaluate every
// calibration on all circular and ivanjko runs of the same June 2020 folder
// (paths the calibration never saw). The published OptiOdom parameters
// (`optiodom` rows of published-results.csv for the same square datasets)
// are evaluated the same way beside them.
//
// Usage: optiodom_comparison [--choices | --sessions] [DATA_DIR]   (default: data/optiodom-2020-06)
// Prints a Markdown table: mean final / mean max / worst final position
// error over the held-out runs, in mm.
//
// --sessions: the evidence behind the defaults: every recording session of
// the folder calibrates in turn and every other session tests (see
// Sessions below), including what `calibrate` writes for --ros2.
//
// --choices: one setting of the refined fit varied at a time around the
// defaults, on squares -> 25 June pairs. Every cross-recording pair (one
// square recording's runs to calibrate, one circular or ivanjko recording's runs to evaluate: 4 x 10
// pairs) gives the mean final position error of that recording's runs; for
// each choice (heading weight, robust loss scale, poses per run, start pose)
// one table varies it around the defaults and compares every row with plain
// least squares (position-only residual at every sample, no robust loss,
// wheelbase and both diameters free) pair by pair.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <optional>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "calibration/calibrate_job.hpp"
#include "calibration/heldout.hpp"
#include "calibration/refine.hpp"
#include "evaluation/trajectory_eval.hpp"
#include "import/optiodom.hpp"

using namespace umbmark;
namespace fs = std::filesystem;

namespace {

struct HeldOut {
  std::vector<io::OptiOdomDataset> sets;
};

EvaluationSummary EvaluateOn(const HeldOut& h, const RobotParams& params) {
  std::vector<RunEvaluation> all;
  for (const auto& ds : h.sets) {
    auto runs = EvaluateRuns(ds.runs, ds.category + "/" + ds.id, params, ds.robot, Integrator::kArc);
    all.insert(all.end(), runs.begin(), runs.end());
  }
  return Summarise(std::move(all));
}

std::map<std::string, RobotParams> PublishedOptiOdom(const fs::path& csv) {
  std::map<std::string, RobotParams> out;
  std::ifstream f(csv);
  std::string line;
  std::getline(f, line);
  while (std::getline(f, line)) {
    std::erase(line, '\r');
    std::vector<std::string> c;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) c.push_back(cell);
    if (c.size() < 12 || c[0] != "optiodom" || c[1].rfind("square/", 0) != 0) continue;
    RobotParams p;
    p.wheelbase_m = std::stod(c[9]);
    p.wheel_diameter_right_m = std::stod(c[10]);
    p.wheel_diameter_left_m = std::stod(c[11]);
    p.ticks_per_rev = 43.7 * 64;
    out[c[1].substr(7)] = p;
  }
  return out;
}

/// Mean final position error [m] of each held-out recording's runs.
std::vector<double> PerRecording(const HeldOut& h, const RobotParams& params) {
  std::vector<double> out;
  for (const auto& ds : h.sets) {
    out.push_back(Summarise(EvaluateRuns(ds.runs, ds.id, params, ds.robot, Integrator::kArc)).mean_final_position_error_m);
  }
  return out;
}

struct Candidate {
  std::string label;
  RefineOptions options;
};

int Choices(const HeldOut& held, const std::vector<fs::path>& squares) {
  std::vector<io::OptiOdomDataset> cal;
  for (const auto& sq : squares) cal.push_back(io::ImportOptiOdom(sq.string()));
  // errors[square][held-out recording] for one set of options.
  auto pairs = [&](const RefineOptions& o) {
    std::vector<std::vector<double>> e;
    for (const auto& ds : cal) {
      const auto r = RefineFromTrajectories({{ds.robot, &ds.runs}}, ds.robot, o);
      e.push_back(PerRecording(held, r.refined));
    }
    return e;
  };
  const auto plain = pairs(PlainLeastSquaresOptions());
  std::vector<std::vector<double>> classic;
  for (const auto& ds : cal) {
    const auto in = InputFromTrajectories(ds.runs, ds.robot, ds.experiment.side_m, Integrator::kArc, ds.id);
    CalibrateJobOptions o;
    o.umbmark.estimator = UmbmarkEstimator::kX;
    classic.push_back(PerRecording(held, RunCalibrateJob(in, o).umbmark.corrected));
  }
  auto table = [&](const std::string& title, const std::vector<Candidate>& cands) {
    fmt::print("\n### {}\n\n", title);
    fmt::print("| candidate | mean over 40 pairs [mm] |");
    for (const auto& ds : cal) fmt::print(" {} [mm] |", ds.id);
    fmt::print(" minus plain LS, mean [mm] | pairs <= plain LS | worst pair vs plain LS [mm] |\n|---|---|");
    for (std::size_t i = 0; i < cal.size(); ++i) fmt::print("---|");
    fmt::print("---|---|---|\n");
    auto print = [&](const std::string& label, const std::vector<std::vector<double>>& e) {
      double sum = 0.0, diff = 0.0, worst = -1e9;
      int n = 0, better = 0;
      std::vector<double> per_square;
      for (std::size_t i = 0; i < e.size(); ++i) {
        double s = 0.0;
        for (std::size_t j = 0; j < e[i].size(); ++j) {
          s += e[i][j];
          const double d = e[i][j] - plain[i][j];
          diff += d;
          worst = std::max(worst, d);
          better += d <= 1e-12 ? 1 : 0;
          ++n;
        }
        sum += s;
        per_square.push_back(s / static_cast<double>(e[i].size()));
      }
      fmt::print("| {} | {:.2f} |", label, 1e3 * sum / n);
      for (double v : per_square) fmt::print(" {:.2f} |", 1e3 * v);
      fmt::print(" {:+.2f} | {}/{} | {:+.2f} |\n", 1e3 * diff / n, better, n, 1e3 * worst);
    };
    print("UMBmark (x), for reference", classic);
    print("plain least squares", plain);
    for (const auto& c : cands) {
      try {
        print(c.label, pairs(c.options));
      } catch (const QualityGateError& e) {
        fmt::print("| {} | quality gate failed: {} |\n", c.label, e.what());
      }
    }
  };
  const RefineOptions base;  // the library defaults
  auto vary = [&](auto&& set, std::initializer_list<double> values, const char* fmtstr) {
    std::vector<Candidate> c;
    for (double v : values) {
      RefineOptions o = base;
      set(o, v);
      c.push_back({fmt::format(fmt::runtime(fmtstr), v), o});
    }
    return c;
  };
  fmt::print("Defaults: heading weight {}, loss {} {} m, sampling {} ({} per run), start pose {}.\n",
             base.heading_weight, RobustLossToString(base.loss), base.loss_scale_m, PoseSamplingToString(base.sampling),
             base.samples_per_run, StartPoseToString(base.start_pose));
  table("Heading term weight (times the wheelbase, metres per radian)",
        vary([](RefineOptions& o, double v) { o.heading_weight = v; }, {0.0, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0}, "heading weight {}"));
  {
    auto c = vary([](RefineOptions& o, double v) { o.loss_scale_m = v; }, {0.002, 0.005, 0.01, 0.02, 0.05},
                  "Huber, scale {} m");
    RefineOptions none = base;
    none.loss = RobustLoss::kNone;
    c.push_back({"no robust loss", none});
    RefineOptions cauchy = base;
    cauchy.loss = RobustLoss::kCauchy;
    c.push_back({"Cauchy, scale 0.02 m", cauchy});
    table("Robust loss", c);
  }
  {
    auto c = vary([](RefineOptions& o, double v) { o.samples_per_run = static_cast<int>(v); }, {25, 100, 400},
                  "{} poses per run");
    RefineOptions every = base;
    every.sampling = PoseSampling::kEverySample;
    c.push_back({"every sample", every});
    table("Poses per run", c);
  }
  {
    std::vector<Candidate> c;
    for (StartPose sp : {StartPose::kFirstSample, StartPose::kStandstillMean, StartPose::kFitted,
                          StartPose::kSessionFrame}) {
      RefineOptions o = base;
      o.start_pose = sp;
      c.push_back({StartPoseToString(sp), o});
    }
    table("Start pose of each run", c);
  }
  {
    std::vector<Candidate> c;
    RefineOptions fixed = base;
    fixed.scale = ScaleMode::kFixed;
    c.push_back({"scale held (E_s = 1)", fixed});
    c.push_back({"scale free (default: auto)", base});
    table("Overall scale", c);
  }
  return 0;
}

/// One cross-session candidate: parameters from one recording set (nullopt
/// when it cannot calibrate from it, e.g. UMBmark from circles).
struct SessionCandidate {
  std::string label;
  std::function<std::optional<RobotParams>(const io::OptiOdomDataset&)> fit;
};

/// What `calibrate` writes for --ros2 (outputs_use) on one square set,
/// with or without --refine: the held-out recommendation's parameters.
RobotParams CalibrateWrites(const io::OptiOdomDataset& ds, bool refine, const std::vector<TrajectoryData>* unseen) {
  CalibrateInput in = InputFromTrajectories(ds.runs, ds.robot, ds.experiment.side_m, Integrator::kArc, ds.id);
  if (unseen) in.unseen = *unseen;
  CalibrateJobOptions o;
  if (refine) o.refine = RefineOptions{};
  o.keep_classic_on_refine_failure = true;
  const CalibrateJobResult r = RunCalibrateJob(in, o);
  const HeldoutComparison h = CompareMethodsHeldout(in, o, r);
  const MethodHeldout* m = h.Find(h.recommended);
  fmt::print(stderr, "  {} {}: recommended {} ({}; scheme {})\n", ds.id, refine ? "--refine" : "defaults",
             h.recommended, h.why, h.scheme);
  return m ? m->parameters : r.umbmark.corrected;
}

/// --sessions, second part: what `calibrate` recommends when the input
/// itself holds several sessions or other shapes, tested on 25 June
/// sessions it did not see. (a) The square sessions recorded with the same
/// robot parameters pooled (leave-one-session-out); (b) each square session with one circle session
/// as unseen paths (unseen_paths), tested on the 9 other 25 June sessions.
void SelectionSchemes(const std::vector<io::OptiOdomDataset>& sets) {
  auto input = [](const io::OptiOdomDataset& ds) {
    return InputFromTrajectories(ds.runs, ds.robot, ds.experiment.side_m, Integrator::kArc, ds.id);
  };
  auto tested = [&](const RobotParams& p, const std::vector<std::size_t>& skip) {
    double sum = 0.0;
    int n = 0;
    for (std::size_t t = 0; t < sets.size(); ++t) {
      if (sets[t].category == "square" || std::find(skip.begin(), skip.end(), t) != skip.end()) continue;
      sum += Summarise(EvaluateRuns(sets[t].runs, sets[t].id, p, sets[t].robot, Integrator::kArc))
                 .mean_final_position_error_m;
      ++n;
    }
    return 1e3 * sum / n;
  };
  auto report = [&](const std::string& what, const CalibrateInput& in, bool refine,
                    const std::vector<std::size_t>& skip) {
    CalibrateJobOptions o;
    if (refine) o.refine = RefineOptions{};
    o.keep_classic_on_refine_failure = true;
    const CalibrateJobResult r = RunCalibrateJob(in, o);
    const HeldoutComparison h = CompareMethodsHeldout(in, o, r);
    fmt::print("| {}{} | {} | {} | {:.2f} +- {:.2f} | {:.2f} | {:.2f} | {:.2f} |\n", what, refine ? " --refine" : "",
               h.scheme, h.recommended, 1e3 * h.expected_error_m, 1e3 * h.expected_error_sem_m,
               tested(h.Find(h.recommended)->parameters, skip), tested(h.Find("plain_least_squares")->parameters, skip),
               tested(h.Find("refined")->parameters, skip));
  };
  fmt::print("\n| input | scheme | recommended | expected error [mm] | tested: recommended [mm] | plain LS [mm] | "
             "refined [mm] |\n|---|---|---|---|---|---|---|\n");
  std::vector<CalibrateInput> squares;
  std::vector<std::string> tags;
  std::size_t circle = sets.size();
  for (std::size_t s = 0; s < sets.size(); ++s) {
    if (sets[s].category == "square") {
      squares.push_back(input(sets[s]));
      tags.push_back(std::to_string(squares.size()));
    } else if (sets[s].category == "circular" && circle == sets.size()) {
      circle = s;
    }
  }
  // Pooling needs one recorded robot: the square sessions recorded with the
  // first one's parameters (230620202042 and 230620202317: 0.2 m, 84 mm).
  std::vector<CalibrateInput> same;
  std::vector<std::string> same_tags;
  for (std::size_t k = 0; k < squares.size(); ++k) {
    const RobotParams& a = squares[k].recorded;
    const RobotParams& b = squares.front().recorded;
    if (a.wheelbase_m == b.wheelbase_m && a.wheel_diameter_left_m == b.wheel_diameter_left_m &&
        a.wheel_diameter_right_m == b.wheel_diameter_right_m) {
      same.push_back(squares[k]);
      same_tags.push_back(tags[k]);
    }
  }
  for (bool refine : {false, true}) {
    report(fmt::format("{} square sessions pooled", same.size()), PoolInputs(same, same_tags, "pooled"), refine, {});
  }
  for (std::size_t k = 0; k < squares.size(); ++k) {
    CalibrateInput in = squares[k];
    in.unseen = {sets[circle].runs};
    for (bool refine : {false, true}) {
      report(fmt::format("{} + circles {} as unseen", in.label, sets[circle].id), in, refine, {circle});
    }
  }
}

/// The calibrations --sessions compares, in the order of its table (plain
/// least squares third: the reference column).
std::vector<SessionCandidate> SessionCandidates() {
  auto refined = [](RefineOptions o) {
    return [o](const io::OptiOdomDataset& ds) -> std::optional<RobotParams> {
      return RefineFromTrajectories({{ds.robot, &ds.runs}}, ds.robot, o).refined;
    };
  };
  auto with = [](StartPose sp, double hw) {
    RefineOptions o;
    o.start_pose = sp;
    o.heading_weight = hw;
    return o;
  };
  std::vector<SessionCandidate> cands;
  cands.push_back({"recorded (no calibration)", [](const io::OptiOdomDataset& ds) -> std::optional<RobotParams> {
                     return ds.robot;
                   }});
  cands.push_back({"UMBmark (mean)", [](const io::OptiOdomDataset& ds) -> std::optional<RobotParams> {
                     if (ds.category != "square") return std::nullopt;
                     const auto in = InputFromTrajectories(ds.runs, ds.robot, ds.experiment.side_m, Integrator::kArc, ds.id);
                     return RunCalibrateJob(in, CalibrateJobOptions{}).umbmark.corrected;
                   }});
  cands.push_back({"plain least squares", refined(PlainLeastSquaresOptions())});
  for (double hw : {0.0, 1.0, 2.0, 4.0}) {
    cands.push_back({fmt::format("refined, first_sample, heading {}", hw), refined(with(StartPose::kFirstSample, hw))});
  }
  for (double hw : {0.0, 1.0, 2.0, 4.0}) {
    cands.push_back(
        {fmt::format("refined, standstill_mean, heading {}", hw), refined(with(StartPose::kStandstillMean, hw))});
  }
  for (double hw : {1.0, 4.0}) {
    cands.push_back({fmt::format("refined, fitted, heading {}", hw), refined(with(StartPose::kFitted, hw))});
  }
  for (double hw : {0.0, 0.5, 1.0, 2.0, 4.0}) {
    cands.push_back({fmt::format("refined, session_frame, heading {}", hw), refined(with(StartPose::kSessionFrame, hw))});
  }
  cands.push_back({"calibrate --ros2 (defaults)", [](const io::OptiOdomDataset& ds) -> std::optional<RobotParams> {
                     if (ds.category != "square") return std::nullopt;
                     return CalibrateWrites(ds, false, nullptr);
                   }});
  cands.push_back({"calibrate --ros2 --refine", [](const io::OptiOdomDataset& ds) -> std::optional<RobotParams> {
                     if (ds.category != "square") return std::nullopt;
                     return CalibrateWrites(ds, true, nullptr);
                   }});
  return cands;
}

/// --sessions: every recording set of the folder (4 square, 6 circular, 4
/// ivanjko sessions) calibrates in turn; each calibration is tested on
/// every OTHER set's runs (mean final position error, odometry from the
/// first ground-truth pose: the OptiOdom protocol). Columns split the
/// pairs by what calibrated and what was tested.
int Sessions(const fs::path& root) {
  std::vector<io::OptiOdomDataset> sets;
  for (const char* cat : {"square", "circular", "ivanjko"}) {
    std::vector<fs::path> dirs;
    for (const auto& e : fs::directory_iterator(root / cat)) dirs.push_back(e.path());
    std::sort(dirs.begin(), dirs.end());
    for (const auto& d : dirs) sets.push_back(io::ImportOptiOdom(d.string()));
  }
  const std::vector<SessionCandidate> cands = SessionCandidates();
  // err[candidate][source][target] (NaN: not computed).
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<std::vector<std::vector<double>>> err(cands.size());
  for (std::size_t c = 0; c < cands.size(); ++c) {
    err[c].assign(sets.size(), std::vector<double>(sets.size(), nan));
    for (std::size_t s = 0; s < sets.size(); ++s) {
      std::optional<RobotParams> p;
      try {
        p = cands[c].fit(sets[s]);
      } catch (const std::exception& e) {
        fmt::print(stderr, "{} on {}: {}\n", cands[c].label, sets[s].id, e.what());
      }
      if (!p) continue;
      for (std::size_t t = 0; t < sets.size(); ++t) {
        if (t == s) continue;
        err[c][s][t] = Summarise(EvaluateRuns(sets[t].runs, sets[t].id, *p, sets[t].robot, Integrator::kArc))
                           .mean_final_position_error_m;
      }
    }
  }
  const std::size_t plain = 2;
  // Mean over the pairs (source category, target category) where plain
  // least squares is defined (it cannot calibrate from the ivanjko sets:
  // straight runs and spins do not determine the wheelbase from positions).
  auto cell = [&](std::size_t c, const char* src, const char* dst, int* count = nullptr) {
    double sum = 0.0;
    int n = 0;
    for (std::size_t s = 0; s < sets.size(); ++s) {
      if (src && sets[s].category != src) continue;
      for (std::size_t t = 0; t < sets.size(); ++t) {
        if (t == s || (dst && sets[t].category != dst) || !std::isfinite(err[plain][s][t])) continue;
        if (!std::isfinite(err[c][s][t])) return std::string("-");
        sum += err[c][s][t];
        ++n;
      }
    }
    if (count) *count = n;
    return n ? fmt::format("{:.2f}", 1e3 * sum / n) : std::string("-");
  };
  int n_sq = 0, n_circ = 0, n_all = 0;
  cell(plain, "square", nullptr, &n_sq);
  cell(plain, "circular", nullptr, &n_circ);
  cell(plain, nullptr, nullptr, &n_all);
  fmt::print("Cross-session evidence: {} recording sets (4 square sessions of 23 June, 6 circular and 4 ivanjko "
             "sessions of 25 June); each calibrates in turn, every OTHER set tests: mean final position error of its "
             "runs [mm], odometry from each run's first ground-truth pose. Pairs where plain least squares is "
             "defined.\n\n",
             sets.size());
  fmt::print("| method | squares -> circles (24) | squares -> ivanjko (16) | squares -> other squares (12) | square "
             "sources, all ({}) | circle sources -> other sets ({}) | all pairs ({}) | pairs <= plain LS | worst pair "
             "vs plain LS [mm] |\n|---|---|---|---|---|---|---|---|---|\n",
             n_sq, n_circ, n_all);
  for (std::size_t c = 0; c < cands.size(); ++c) {
    int better = 0, n = 0;
    double worst = -1e9;
    for (std::size_t s = 0; s < sets.size(); ++s) {
      for (std::size_t t = 0; t < sets.size(); ++t) {
        if (!std::isfinite(err[c][s][t]) || !std::isfinite(err[plain][s][t])) continue;
        const double d = err[c][s][t] - err[plain][s][t];
        better += d <= 1e-12 ? 1 : 0;
        worst = std::max(worst, d);
        ++n;
      }
    }
    fmt::print("| {} | {} | {} | {} | {} | {} | {} | {}/{} | {:+.2f} |\n", cands[c].label,
               cell(c, "square", "circular"), cell(c, "square", "ivanjko"), cell(c, "square", "square"),
               cell(c, "square", nullptr), cell(c, "circular", nullptr), cell(c, nullptr, nullptr), better, n,
               1e3 * worst);
  }
  SelectionSchemes(sets);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  bool choices = false, sessions = false;
  if (argc > 1 && std::string(argv[1]) == "--choices") {
    choices = true;
    --argc;
    ++argv;
  } else if (argc > 1 && std::string(argv[1]) == "--sessions") {
    sessions = true;
    --argc;
    ++argv;
  }
  const fs::path root = argc > 1 ? fs::path(argv[1]) : fs::path("data/optiodom-2020-06");
  if (sessions) return Sessions(root);
  HeldOut held;
  std::size_t held_runs = 0;
  for (const char* cat : {"circular", "ivanjko"}) {
    std::vector<fs::path> dirs;
    for (const auto& e : fs::directory_iterator(root / cat)) dirs.push_back(e.path());
    std::sort(dirs.begin(), dirs.end());
    for (const auto& d : dirs) {
      held.sets.push_back(io::ImportOptiOdom(d.string()));
      held_runs += held.sets.back().runs.runs.size();
    }
  }
  const auto published = PublishedOptiOdom(root / "published-results.csv");
  std::vector<fs::path> squares;
  for (const auto& e : fs::directory_iterator(root / "square")) squares.push_back(e.path());
  std::sort(squares.begin(), squares.end());
  if (choices) return Choices(held, squares);

  fmt::print("Held-out evaluation on {} circular + ivanjko runs ({} datasets), odometry with the exact arc.\n\n",
             held_runs, held.sets.size());
  fmt::print("| square dataset | method | wheelbase [m] | D_R [m] | D_L [m] | mean final [mm] | (its SE) | mean max [mm] | worst final [mm] |\n");
  fmt::print("|---|---|---|---|---|---|---|---|---|\n");
  auto row = [&](const std::string& ds, const std::string& method, const RobotParams& p) {
    const auto s = EvaluateOn(held, p);
    // Standard error of the mean final error over the held-out runs.
    double ss = 0.0;
    for (const auto& r : s.runs) ss += std::pow(r.final_position_error_m - s.mean_final_position_error_m, 2);
    const double n = static_cast<double>(s.runs.size());
    const double se = std::sqrt(ss / (n - 1.0) / n);
    fmt::print("| {} | {} | {:.6f} | {:.6f} | {:.6f} | {:.2f} | {:.2f} | {:.2f} | {:.2f} |\n", ds, method, p.wheelbase_m,
               p.wheel_diameter_right_m, p.wheel_diameter_left_m, s.mean_final_position_error_m * 1e3, se * 1e3,
               s.mean_max_position_error_m * 1e3, s.max_final_position_error_m * 1e3);
    return s;
  };
  std::map<std::string, std::vector<double>> mean_final;
  for (const auto& sq : squares) {
    const auto ds = io::ImportOptiOdom(sq.string());
    const auto in = InputFromTrajectories(ds.runs, ds.robot, ds.experiment.side_m, Integrator::kArc, ds.id);
    mean_final["recorded (no calibration)"].push_back(row(ds.id, "recorded (no calibration)", ds.robot).mean_final_position_error_m);
    for (auto est : {UmbmarkEstimator::kX, UmbmarkEstimator::kMean}) {
      CalibrateJobOptions o;
      o.umbmark.estimator = est;
      const auto r = RunCalibrateJob(in, o);
      const std::string m = fmt::format("UMBmark ({})", UmbmarkEstimatorToString(est));
      mean_final[m].push_back(row(ds.id, m, r.umbmark.corrected).mean_final_position_error_m);
    }
    {
      CalibrateJobOptions o;
      o.refine = RefineOptions{};
      const auto r = RunCalibrateJob(in, o);
      mean_final["refined (trajectories)"].push_back(
          row(ds.id, "refined (trajectories)", r.refined->refined).mean_final_position_error_m);
    }
    {
      CalibrateJobOptions o;
      o.refine = PlainLeastSquaresOptions();
      const auto r = RunCalibrateJob(in, o);
      mean_final["plain least squares (trajectories)"].push_back(
          row(ds.id, "plain least squares (trajectories)", r.refined->refined).mean_final_position_error_m);
    }
    {
      // Refined from the return errors alone (what an endpoint CSV gives).
      CalibrateInput only_errors = in;
      only_errors.trajectories.reset();
      CalibrateJobOptions o;
      o.refine = RefineOptions{};
      try {
        const auto r = RunCalibrateJob(only_errors, o);
        mean_final["refined (return errors)"].push_back(
            row(ds.id, "refined (return errors)", r.refined->refined).mean_final_position_error_m);
      } catch (const QualityGateError& e) {
        fmt::print("| {} | refined (return errors) | quality gate failed: {} |||||\n", ds.id, e.what());
      }
    }
    if (auto it = published.find(ds.id); it != published.end())
      mean_final["published OptiOdom"].push_back(row(ds.id, "published OptiOdom", it->second).mean_final_position_error_m);
  }
  fmt::print("\nAverage of the mean final position error over the four square datasets:\n\n");
  for (const auto& [m, v] : mean_final) {
    double s = 0;
    for (double x : v) s += x;
    fmt::print("- {}: {:.2f} mm\n", m, 1e3 * s / static_cast<double>(v.size()));
  }
  return 0;
}
