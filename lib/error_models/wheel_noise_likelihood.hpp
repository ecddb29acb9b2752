// The profiled likelihood of the wheel-noise model (wheel_noise_fit.hpp)
// and the searches on it, for FitWheelNoise:
//   theta = (log k_L, log k_R, eps),  eps = E_d - E_d0 (joint fit only),
// the group means profiled out by generalised least squares. One pass over
// the runs gives the negative log-likelihood, its gradient and the expected
// (Fisher) information I_jk = 1/2 sum_i tr(S_i^-1 dS_i/dj S_i^-1 dS_i/dk),
// so the maximum and every profile are found by Fisher scoring in a few
// passes (Jennrich & Sampson 1976 for variance components), and each end of
// a profile-likelihood interval by a safeguarded Newton search on the
// signed root r = sqrt(2 (NLL_profile - NLL_min)), which is close to linear
// in log k: four to six profiles per end, each warm-started from the last.
// A fixed k may be exactly 0 (theta_j = -inf).
#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "error_models/wheel_noise_fit.hpp"

namespace umbmark::noise_fit {

/// Group index of every run, in first-seen order.
struct Grouping {
  std::vector<int> of_run;
  std::vector<std::string> names;
  std::vector<int> count, count_theta;
  /// Plain mean error of each group (etheta over the runs that have it), a
  /// centre that keeps the one-pass sums free of cancellation.
  std::vector<Eigen::Vector3d> centre;
};

Grouping MakeGroups(const std::vector<WheelNoiseFitRun>& runs);

/// Everything one likelihood evaluation reads.
struct LikelihoodModel {
  const std::vector<WheelNoiseFitRun>* runs = nullptr;
  const Grouping* groups = nullptr;
  /// Per run, how its bases move with E_d; null: eps is not a parameter.
  const std::vector<WheelNoiseRunSensitivity>* sensitivity = nullptr;
  bool restricted = false;  ///< REML term
  /// Weak Gaussian prior on eps (joint fit): centre and sigma.
  double eps_prior_centre = 0.0, eps_prior_sigma = 0.02;
  /// Worker threads of a pass over more than 16384 runs (0: all hardware
  /// threads); the sums do not depend on it.
  int threads = 0;
  /// Likelihood passes so far (each Evaluate is one).
  mutable int passes = 0;

  int Dimension() const { return sensitivity ? 3 : 2; }
};

struct Evaluation {
  bool ok = false;  ///< false: some S_i not positive definite
  double nll = 0.0;
  Eigen::Vector3d gradient = Eigen::Vector3d::Zero();
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
};

/// One pass at theta (entry 2 ignored without sensitivity). `means`
/// receives the GLS group means when given.
Evaluation Evaluate(const LikelihoodModel& m, const Eigen::Vector3d& theta,
                    std::vector<Eigen::Vector3d>* means = nullptr);

/// S_i at (q_L, q_R, eps) (second-order and reference terms included).
PoseCovariance RunCovariance(const LikelihoodModel& m, std::size_t i, double qL, double qR, double eps);

struct Optimum {
  bool ok = false;
  Eigen::Vector3d theta = Eigen::Vector3d::Zero();
  Evaluation at;
  int iterations = 0;
};

/// Minimum of the NLL over the entries of theta marked free, from `start`,
/// by Fisher scoring with backtracking (Armijo), until twice the predicted
/// decrease is at most `min_decrement`. A k walking to its boundary 0 stops
/// once it is below e^-40 m^1/2.
Optimum Minimise(const LikelihoodModel& m, Eigen::Vector3d start, const std::array<bool, 3>& free,
                 int max_iterations, double min_decrement = 1e-7);

/// One end of the profile-likelihood interval of k_j (j = 0: k_L, 1: k_R):
/// the k on side +1 (above) or -1 (below) the optimum where the profile
/// NLL (minimised over the other free entries) exceeds the minimum by
/// `delta`. 0 when the profile at k = 0 stays within delta, +inf when no
/// finite k reaches it.
double IntervalEnd(const LikelihoodModel& m, const Optimum& best, int j, int side, double delta,
                   int max_iterations);

}  // namespace umbmark::noise_fit
