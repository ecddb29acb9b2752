// Maximum-likelihood fit of k_L, k_R with profile-likelihood intervals and a
// goodness-of-fit table; see wheel_noise_fit.hpp.
#include "error_models/wheel_noise_fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "core/errors.hpp"
#include "stats/distributions.hpp"
#include "error_models/wheel_noise_likelihood.hpp"

namespace umbmark {

PoseCovariance MeasurementCovariance(double sigma_xy_m, double sigma_theta_rad, const Pose2& relative) {
  const double sxy2 = sigma_xy_m * sigma_xy_m, sth2 = sigma_theta_rad * sigma_theta_rad;
  PoseCovariance M = PoseCovariance::Zero();
  M.diagonal() << 2.0 * sxy2, 2.0 * sxy2, sth2;  // end-pose noise + start-position noise
  const Eigen::Vector3d u(relative.y, -relative.x, -1.0);  // start-heading noise lever arm
  M += sth2 * u * u.transpose();
  return M;
}

std::string WheelNoiseFitOptions::Check() const {
  if (!(confidence > 0.0 && confidence < 1.0)) return fmt::format("confidence = {} must be in (0, 1)", confidence);
  if (max_iterations < 10) return fmt::format("max_iterations = {} must be >= 10", max_iterations);
  if (threads < 0) return fmt::format("threads = {} must be >= 0 (0: all hardware threads)", threads);
  if (!(E_d_prior_sigma > 0.0) || !std::isfinite(E_d_prior_sigma))
    return fmt::format("E_d_prior_sigma = {} must be positive and finite", E_d_prior_sigma);
  if (!std::isfinite(E_d_prior_centre)) return fmt::format("E_d_prior_centre = {} must be finite", E_d_prior_centre);
  if (start && !start->allFinite())
    return fmt::format("start = ({}, {}, {}) must be finite", (*start)(0), (*start)(1), (*start)(2));
  return {};
}

namespace {

using noise_fit::Grouping;
using noise_fit::LikelihoodModel;
using noise_fit::Optimum;

/// Throws InputError, naming the run's file and line, when the data cannot
/// identify the model.
void CheckIdentifiable(const std::vector<WheelNoiseFitRun>& runs, const Grouping& grp,
                       const std::vector<std::string>& sources) {
  auto file = [&](int source) {
    return source >= 0 && static_cast<std::size_t>(source) < sources.size() ? sources[static_cast<std::size_t>(source)]
                                                                          : std::string();
  };
  const std::size_t n = runs.size(), G = grp.names.size();
  if (n < G + 2)
    throw InputError(runs.empty() ? std::string() : file(runs.front().source),
                     fmt::format("{} runs in {} groups: fit-noise needs at least groups + 2 runs", n, G));
  for (std::size_t i = 0; i < n; ++i) {
    const WheelNoiseFitRun& r = runs[i];
    if (grp.count[static_cast<std::size_t>(grp.of_run[i])] < 2)
      throw InputError(file(r.source), r.line, 0,
                       fmt::format("run {} is the only run of group '{}'; its systematic mean would absorb it (give "
                                   "every direction at least 2 runs)",
                                   r.run, r.group));
    if (!r.error.head<2>().allFinite() || (r.has_theta && !std::isfinite(r.error(2))))
      throw InputError(file(r.source), r.line, 0, fmt::format("run {}: return error is not finite", r.run));
  }
}

/// Starting point (log k_L, log k_R): method of moments on the pooled
/// residual covariance about the plain group means.
Eigen::Vector2d StartingPoint(const std::vector<WheelNoiseFitRun>& runs, const Grouping& grp) {
  PoseCovariance So = PoseCovariance::Zero(), SL = So, SR = So, SM = So;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    Eigen::Vector3d r = runs[i].error - runs[i].systematic - grp.centre[static_cast<std::size_t>(grp.of_run[i])];
    if (!runs[i].has_theta) r(2) = 0.0;
    So += r * r.transpose();
    SL += runs[i].basis.A_L;
    SR += runs[i].basis.A_R;
    SM += runs[i].measurement;
  }
  Eigen::Matrix<double, 6, 2> A;
  Eigen::Matrix<double, 6, 1> y;
  int row = 0;
  for (int a = 0; a < 3; ++a)
    for (int b = a; b < 3; ++b, ++row) {
      const double w = 1.0 / std::sqrt(std::max(So(a, a) * So(b, b), 1e-300));
      A(row, 0) = w * SL(a, b);
      A(row, 1) = w * SR(a, b);
      y(row) = w * (So(a, b) - SM(a, b));
    }
  Eigen::Vector2d q = A.colPivHouseholderQr().solve(y);
  const double qmax = std::max({q(0), q(1), 1e-16});
  q = q.cwiseMax(0.01 * qmax);
  return {0.5 * std::log(q(0)), 0.5 * std::log(q(1))};
}

/// Each of the six covariance elements of the residuals at the fit (pooled
/// over runs, N - G degrees of freedom) against the model's average S_i;
/// also fills the residuals and S_i per run.
void GoodnessOfFit(const LikelihoodModel& model, const Eigen::Vector3d& theta, WheelNoiseFitSummary& out) {
  const std::vector<WheelNoiseFitRun>& runs = *model.runs;
  const Grouping& grp = *model.groups;
  const double qL = std::exp(2.0 * theta(0)), qR = std::exp(2.0 * theta(1));
  const double eps = model.Dimension() == 3 ? theta(2) : 0.0;
  const char* names[6] = {"xx", "yy", "thth", "xy", "xth", "yth"};
  const int ia[6] = {0, 1, 2, 0, 0, 1}, ib[6] = {0, 1, 2, 1, 2, 2};
  std::array<double, 6> obs{}, pred{}, var{};
  std::array<int, 6> cnt{};
  std::array<std::vector<int>, 6> groups_seen;
  const std::vector<Eigen::Vector3d>& mu = out.group_means;
  out.residuals.reserve(runs.size());
  out.predicted_run_covariance.reserve(runs.size());
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const WheelNoiseFitRun& r = runs[i];
    const PoseCovariance S = noise_fit::RunCovariance(model, i, qL, qR, eps);
    Eigen::Vector3d res = r.error - r.systematic - mu[static_cast<std::size_t>(grp.of_run[i])];
    if (!r.has_theta) res(2) = std::numeric_limits<double>::quiet_NaN();
    out.residuals.push_back(res);
    out.predicted_run_covariance.push_back(S);
    for (int e = 0; e < 6; ++e) {
      if (!r.has_theta && (ia[e] == 2 || ib[e] == 2)) continue;
      const auto k = static_cast<std::size_t>(e);
      obs[k] += res(ia[e]) * res(ib[e]);
      pred[k] += S(ia[e], ib[e]);
      var[k] += S(ia[e], ia[e]) * S(ib[e], ib[e]) + S(ia[e], ib[e]) * S(ia[e], ib[e]);
      ++cnt[k];
      auto& seen = groups_seen[k];
      if (std::find(seen.begin(), seen.end(), grp.of_run[i]) == seen.end()) seen.push_back(grp.of_run[i]);
    }
  }
  for (int e = 0; e < 6; ++e) {
    const auto k = static_cast<std::size_t>(e);
    CovarianceElementCheck c;
    c.element = names[e];
    c.runs = cnt[k];
    const double dof = static_cast<double>(cnt[k]) - static_cast<double>(groups_seen[k].size());
    if (cnt[k] > 0 && dof > 0) {
      c.observed = obs[k] / dof;
      c.predicted = pred[k] / cnt[k];
      c.standard_error = std::sqrt(var[k]) / dof;
      c.z = c.standard_error > 0 ? (c.observed - c.predicted) / c.standard_error : 0.0;
    }
    out.goodness_of_fit.push_back(c);
    out.observed_covariance(ia[e], ib[e]) = out.observed_covariance(ib[e], ia[e]) = c.observed;
    out.predicted_covariance(ia[e], ib[e]) = out.predicted_covariance(ib[e], ia[e]) = c.predicted;
  }
}

}  // namespace

double WheelNoiseNegLogLikelihood(const std::vector<WheelNoiseFitRun>& runs, double k_L, double k_R) {
  const Grouping grp = noise_fit::MakeGroups(runs);
  const LikelihoodModel model{&runs, &grp};
  const noise_fit::Evaluation e = noise_fit::Evaluate(model, Eigen::Vector3d(std::log(k_L), std::log(k_R), 0.0));
  return e.ok ? e.nll : std::numeric_limits<double>::infinity();
}

std::string WheelNoiseFitSummary::BriefReport() const {
  return fmt::format("k_L = {:.4g} m^1/2 [{:.4g}, {:.4g}], k_R = {:.4g} m^1/2 [{:.4g}, {:.4g}] ({:.0f}% profile "
                     "likelihood), {} runs in {} groups",
                     k_L, k_L_ci[0], k_L_ci[1], k_R, k_R_ci[0], k_R_ci[1], 100 * confidence, runs, groups.size());
}

WheelNoiseFitSummary FitWheelNoise(const std::vector<WheelNoiseFitRun>& runs, const WheelNoiseFitOptions& options,
                                   const std::vector<WheelNoiseRunSensitivity>* E_d_sensitivity) {
  if (auto e = options.Check(); !e.empty()) throw InvalidOptions(e);
  if (E_d_sensitivity && E_d_sensitivity->size() != runs.size())
    throw InvalidOptions(fmt::format("E_d_sensitivity has {} entries for {} runs", E_d_sensitivity->size(), runs.size()));
  // 1. Groups; check the data can identify the model.
  const Grouping grp = noise_fit::MakeGroups(runs);
  CheckIdentifiable(runs, grp, options.sources);
  LikelihoodModel model{&runs, &grp, E_d_sensitivity, options.restricted, options.E_d_prior_centre,
                        options.E_d_prior_sigma};
  model.threads = options.threads;
  // 2. Maximum likelihood from the method-of-moments start.
  const Eigen::Vector2d start = StartingPoint(runs, grp);
  Eigen::Vector3d theta0(start(0), start(1), 0.0);  // eps = 0: the value the bases were built at
  ProgressCounter progress(options.progress, options.intervals ? 3.0 : 1.0);
  Optimum best;
  if (options.start) best = noise_fit::Minimise(model, *options.start, {true, true, true}, options.max_iterations);
  if (!best.ok) {  // no warm start, or a singular run covariance there
    best = noise_fit::Minimise(model, theta0, {true, true, true}, options.max_iterations);
    if (!best.ok) throw QualityGateError("fit-noise: the starting point has a singular run covariance");
  }
  progress.Add();
  if (!best.ok || !std::isfinite(best.at.nll))
    throw QualityGateError("fit-noise: the maximum-likelihood search failed (a run covariance became singular)");
  WheelNoiseFitSummary out;
  out.k_L = std::exp(best.theta(0));
  out.k_R = std::exp(best.theta(1));
  out.neg_log_likelihood = best.at.nll;
  out.iterations = best.iterations;
  out.solver_message = "Fisher scoring";
  out.confidence = options.confidence;
  out.runs = static_cast<int>(runs.size());
  out.groups = grp.names;
  out.group_of_run = grp.of_run;
  if (E_d_sensitivity) {
    out.E_d_offset = best.theta(2);
    const Eigen::Matrix3d Iinv = best.at.information.inverse();
    out.E_d_offset_se = std::sqrt(std::max(Iinv(2, 2), 0.0));
  }
  // 3. Profile-likelihood intervals (k_L, then k_R; below, then above).
  if (options.intervals) {
    const double dof = static_cast<double>(runs.size()) - static_cast<double>(grp.names.size()) - model.Dimension();
    const double t = StudentTQuantile(0.5 + 0.5 * options.confidence, std::max(dof, 1.0));
    const double delta = options.small_sample ? 0.5 * t * t : 0.5 * ChiSquareQuantile(options.confidence, 1.0);
    for (int j = 0; j < 2; ++j) {
      std::array<double, 2>& ci = j == 0 ? out.k_L_ci : out.k_R_ci;
      ci = {noise_fit::IntervalEnd(model, best, j, -1, delta, options.max_iterations),
            noise_fit::IntervalEnd(model, best, j, +1, delta, options.max_iterations)};
      progress.Add();
    }
  } else {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    out.k_L_ci = out.k_R_ci = {nan, nan};
  }
  // 4. Group means, residuals and goodness of fit at the optimum.
  noise_fit::Evaluate(model, best.theta, &out.group_means);
  GoodnessOfFit(model, best.theta, out);
  // Report each group's mean return error: mu_g plus its runs' average
  // predicted systematic error.
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const auto g = static_cast<std::size_t>(grp.of_run[i]);
    out.group_means[g].head<2>() += runs[i].systematic.head<2>() / grp.count[g];
    if (runs[i].has_theta) out.group_means[g](2) += runs[i].systematic(2) / grp.count_theta[g];
  }
  out.likelihood_passes = model.passes;
  return out;
}

}  // namespace umbmark
