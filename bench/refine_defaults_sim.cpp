// The refine's defaults on simulated campaigns from an INDEPENDENT
// generator (bench/indep_campaign.cpp; driven by bench/refine_defaults_sim.sh):
// several recording sessions of one robot, each with its own motion-capture
// frame error (yaw and origin), squares to calibrate, free paths and
// back-and-forth runs to test. Issue 30: does a constant frame yaw trade
// against E_d when every run starts in the same heading, and which start
// pose / heading weight predicts other sessions and shapes best?
//
// Usage: refine_defaults_sim TRUTH_E_D TRUTH_E_B TRUTH_SCALE SESSION_DIR...
//   (each SESSION_DIR holds campaign.toml; the true robot is the same in all)
// Prints one line per candidate and session: the fitted E_d, E_b, E_s minus
// the truth (relative to the campaign's recorded robot), and then, per
// candidate, the mean final position error [mm] of the calibration on
//   own:   the same session's free and back-and-forth runs (other shapes),
//   other: the other sessions' free and back-and-forth runs (other days),
// in machine-readable lines beginning with "row".
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "calibration/calibrate_job.hpp"
#include "calibration/refine.hpp"
#include "evaluation/trajectory_eval.hpp"
#include "formats/data_file.hpp"
#include "formats/manifest.hpp"

using namespace umbmark;

namespace {

struct Session {
  std::string dir;
  RobotParams robot;
  double side_m = 0.0;
  TrajectoryData squares;
  std::vector<TrajectoryData> tests;  // free paths, back-and-forth runs
};

Session Load(const std::string& dir) {
  const Manifest m = io::ReadManifest(dir + "/campaign.toml");
  Session s;
  s.dir = dir;
  s.robot = m.robot;
  for (const auto& e : m.experiments) {
    io::RunFile rf = io::ReadRunFile(e.resolved_file);
    auto* t = std::get_if<TrajectoryData>(&rf);
    if (!t) continue;
    if (e.kind == ExperimentKind::kSquare) {
      s.squares = std::move(*t);
      s.side_m = e.side_m;
    } else {
      s.tests.push_back(std::move(*t));
    }
  }
  return s;
}

double MeanFinal(const std::vector<TrajectoryData>& tests, const RobotParams& p, const RobotParams& recorded) {
  std::vector<RunEvaluation> all;
  for (const auto& d : tests) {
    auto r = EvaluateRuns(d, d.path, p, recorded, Integrator::kArc);
    all.insert(all.end(), r.begin(), r.end());
  }
  return Summarise(std::move(all)).mean_final_position_error_m;
}

struct Candidate {
  std::string name;
  std::function<RobotParams(const Session&)> fit;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc < 5) {
    fmt::print(stderr, "usage: refine_defaults_sim TRUTH_E_D TRUTH_E_B TRUTH_SCALE SESSION_DIR...\n");
    return 2;
  }
  const double Ed = std::atof(argv[1]), Eb = std::atof(argv[2]), Es = std::atof(argv[3]);
  std::vector<Session> sessions;
  for (int i = 4; i < argc; ++i) sessions.push_back(Load(argv[i]));
  auto refined = [](RefineOptions o) {
    return [o](const Session& s) { return RefineFromTrajectories({{s.robot, &s.squares}}, s.robot, o).refined; };
  };
  std::vector<Candidate> cands;
  cands.push_back({"umbmark_mean", [](const Session& s) {
                     const auto in = InputFromTrajectories(s.squares, s.robot, s.side_m, Integrator::kArc, s.dir);
                     return RunCalibrateJob(in, CalibrateJobOptions{}).umbmark.corrected;
                   }});
  cands.push_back({"plain_least_squares", refined(PlainLeastSquaresOptions())});
  for (StartPose sp : {StartPose::kSessionFrame, StartPose::kFirstSample, StartPose::kStandstillMean}) {
    for (double hw : {0.0, 1.0, 2.0, 4.0}) {
      RefineOptions o;
      o.start_pose = sp;
      o.heading_weight = hw;
      cands.push_back({fmt::format("{}_h{}", StartPoseToString(sp), hw), refined(o)});
    }
  }
  for (const auto& c : cands) {
    for (std::size_t s = 0; s < sessions.size(); ++s) {
      const Session& cal = sessions[s];
      RobotParams p;
      try {
        p = c.fit(cal);
      } catch (const std::exception& e) {
        fmt::print("row {} {} failed {}\n", c.name, s, e.what());
        continue;
      }
      const RobotParams& r = cal.robot;
      const double ed = (p.wheel_diameter_right_m / r.wheel_diameter_right_m) /
                        (p.wheel_diameter_left_m / r.wheel_diameter_left_m);
      const double eb = p.wheelbase_m / r.wheelbase_m;
      const double es = 0.5 * (p.wheel_diameter_left_m / r.wheel_diameter_left_m +
                               p.wheel_diameter_right_m / r.wheel_diameter_right_m);
      const double own = MeanFinal(cal.tests, p, r);
      double other = 0.0;
      int n = 0;
      for (std::size_t t = 0; t < sessions.size(); ++t) {
        if (t == s) continue;
        other += MeanFinal(sessions[t].tests, p, sessions[t].robot);
        ++n;
      }
      // row NAME SESSION dE_d dE_b dE_s own_mm other_mm
      fmt::print("row {} {} {:+.6f} {:+.6f} {:+.6f} {:.3f} {:.3f}\n", c.name, s, ed - Ed, eb - Eb, es - Es, 1e3 * own,
                 n ? 1e3 * other / n : std::nan(""));
    }
  }
  return 0;
}
