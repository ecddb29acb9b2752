// Test helpers for the refined calibration: a seeded simulator of commanded
// UMBmark squares (return errors and full trajectories) with white wheel
// noise of variance k^2 |travel| per wheel (Chong & Kleeman), built on the
// exact commanded-square model.
#pragma once

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "core/robot.hpp"
#include "core/runs.hpp"
#include "evaluation/return_error.hpp"
#include "kinematics/diff_drive.hpp"
#include "model/commanded_square.hpp"

namespace umbmark::test {

/// The true robot relative to the recorded one.
struct TrueRobot {
  double E_b = 1.0, c_L = 1.0, c_R = 1.0;
};

/// c_L, c_R for E_d and E_s (eqs. 4.31, 4.32 times E_s).
inline TrueRobot FromFactors(double E_b, double E_d, double E_s = 1.0) {
  return {E_b, 2.0 * E_s / (E_d + 1.0), 2.0 * E_s * E_d / (E_d + 1.0)};
}

struct NoiseModel {
  double k_m_sqrt = 0.0;        ///< wheel noise k [m^1/2]: variance k^2 |travel| per wheel
  int partitions = 20;          ///< independent noise pieces per motion
  double gt_sigma_xy_m = 0.0;   ///< measurement noise of the final pose
  double gt_sigma_theta_rad = 0.0;
};

/// Executes one commanded square on the true robot with wheel noise; returns
/// the true final pose. The odometry's final pose is the noise-free nominal.
inline Pose2 RunNoisySquare(const std::vector<CommandedMotion>& motions, double b_rec, const TrueRobot& truth,
                            const NoiseModel& noise, std::mt19937_64& rng) {
  std::normal_distribution<double> n01(0.0, 1.0);
  Pose2 pose;
  const double b = truth.E_b * b_rec;
  for (const auto& m : motions) {
    const int P = noise.k_m_sqrt > 0.0 ? noise.partitions : 1;
    const double dl = truth.c_L * m.nominal_left_m / P, dr = truth.c_R * m.nominal_right_m / P;
    for (int p = 0; p < P; ++p) {
      const double nl = noise.k_m_sqrt * std::sqrt(std::abs(dl)) * n01(rng);
      const double nr = noise.k_m_sqrt * std::sqrt(std::abs(dr)) * n01(rng);
      pose = DiffDriveStep(pose, dl + nl, dr + nr, b);
    }
  }
  return pose;
}

/// Return errors of `runs` cw and `runs` ccw squares of side `side_m`.
inline std::vector<ReturnError> SimulateReturnErrors(double side_m, double b_rec, const TrueRobot& truth,
                                                     int runs, const NoiseModel& noise, std::mt19937_64& rng,
                                                     bool final_turn = true) {
  std::normal_distribution<double> n01(0.0, 1.0);
  std::vector<ReturnError> out;
  for (SquareDirection dir : {SquareDirection::kCw, SquareDirection::kCcw}) {
    const auto motions = CommandedSquare(dir, side_m, b_rec, final_turn);
    const Pose2 odo = OdometryOfCommanded(motions, b_rec);
    for (int i = 0; i < runs; ++i) {
      const Pose2 t = RunNoisySquare(motions, b_rec, truth, noise, rng);
      ReturnError e;
      e.run = std::to_string(out.size() + 1);
      e.direction = SquareDirectionToString(dir);
      e.ex_m = t.x - odo.x + noise.gt_sigma_xy_m * n01(rng);
      e.ey_m = t.y - odo.y + noise.gt_sigma_xy_m * n01(rng);
      e.etheta_rad = WrapAngle(t.theta - odo.theta + noise.gt_sigma_theta_rad * n01(rng));
      out.push_back(e);
    }
  }
  return out;
}

/// A square run as a trajectory: samples every `step_m` of nominal wheel
/// travel, cumulative nominal travel in dist_*_m (what the recorded odometry
/// measured), ground truth = true pose (wheel noise included, no GT noise).
inline TrajectoryRun SimulateSquareTrajectory(SquareDirection dir, double side_m, double b_rec,
                                              const TrueRobot& truth, double step_m, const NoiseModel& noise,
                                              std::mt19937_64& rng, const std::string& id) {
  std::normal_distribution<double> n01(0.0, 1.0);
  TrajectoryRun run;
  run.run = id;
  run.direction = SquareDirectionToString(dir);
  double t = 0.0, cl = 0.0, cr = 0.0;
  Pose2 pose;
  auto push = [&]() {
    run.t_s.push_back(t);
    run.dist_left_m.push_back(cl);
    run.dist_right_m.push_back(cr);
    run.gt_x_m.push_back(pose.x);
    run.gt_y_m.push_back(pose.y);
    run.gt_theta_rad.push_back(pose.theta);
    run.lines.push_back(run.lines.size() + 2);
  };
  push();
  const double b = truth.E_b * b_rec;
  for (const auto& m : CommandedSquare(dir, side_m, b_rec)) {
    const double longest = std::max(std::abs(m.nominal_left_m), std::abs(m.nominal_right_m));
    const int steps = std::max(1, static_cast<int>(std::ceil(longest / step_m)));
    const double nl = m.nominal_left_m / steps, nr = m.nominal_right_m / steps;
    for (int s = 0; s < steps; ++s) {
      const double dl = truth.c_L * nl, dr = truth.c_R * nr;
      const double wl = noise.k_m_sqrt * std::sqrt(std::abs(dl)) * n01(rng);
      const double wr = noise.k_m_sqrt * std::sqrt(std::abs(dr)) * n01(rng);
      pose = DiffDriveStep(pose, dl + wl, dr + wr, b);
      cl += nl;
      cr += nr;
      t += 0.05;
      push();
    }
  }
  return run;
}

}  // namespace umbmark::test
