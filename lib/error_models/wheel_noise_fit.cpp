// Maximum-likelihood fit of k_L, k_R with profile-likelihood intervals and a
// goodness-of-fit table; see wheel_noise_fit.hpp.
#include "error_models/wheel_noise_fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include <ceres/first_order_function.h>
#include <ceres/jet.h>
#include <ceres/gradient_problem.h>
#include <ceres/gradient_problem_solver.h>
#include <Eigen/Dense>
#include <fmt/format.h>

#include "core/errors.hpp"
#include "stats/distributions.hpp"
#include "stats/optimize.hpp"

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
  return {};
}

namespace {

/// Group index of every run, in first-seen order.
struct Grouping {
  std::vector<int> of_run;
  std::vector<std::string> names;
  std::vector<int> count, count_theta;
  /// Plain mean error of each group (etheta over the runs that have it), a
  /// centre that keeps ProfiledNll's one-pass sums free of cancellation.
  std::vector<Eigen::Vector3d> centre;
};

Grouping MakeGroups(const std::vector<WheelNoiseFitRun>& runs) {
  Grouping g;
  std::map<std::string, int> index;
  for (const WheelNoiseFitRun& r : runs) {
    auto [it, inserted] = index.emplace(r.group, static_cast<int>(g.names.size()));
    if (inserted) {
      g.names.push_back(r.group);
      g.count.push_back(0);
      g.count_theta.push_back(0);
    }
    g.of_run.push_back(it->second);
    ++g.count[static_cast<std::size_t>(it->second)];
    if (r.has_theta) ++g.count_theta[static_cast<std::size_t>(it->second)];
  }
  g.centre.assign(g.names.size(), Eigen::Vector3d::Zero());
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const auto k = static_cast<std::size_t>(g.of_run[i]);
    g.centre[k].head<2>() += runs[i].error.head<2>() / g.count[k];
    if (runs[i].has_theta) g.centre[k](2) += runs[i].error(2) / g.count_theta[k];
  }
  return g;
}

/// Profiled negative log-likelihood (group means by GLS) for k_L^2 = qL,
/// k_R^2 = qR. Returns false when some S_i is not positive definite.
/// One pass over the runs, storing nothing per run (a fit evaluates this a
/// few thousand times, so with 10^6 runs its memory traffic is the cost):
/// with d_i = e_i - c_g (c_g the group's centre) and b_g = sum S_i^-1 d_i,
///   sum_i (d_i - m_g)^T S_i^-1 (d_i - m_g) = sum_i d_i^T S_i^-1 d_i - b_g^T m_g
/// at the GLS mean m_g = W_g^-1 b_g, W_g = sum S_i^-1.
template <typename T>
bool ProfiledNll(const std::vector<WheelNoiseFitRun>& runs, const Grouping& grp, const T& qL, const T& qR, T* nll,
                 std::vector<Eigen::Matrix<T, 3, 1>>* means = nullptr, bool restricted = false) {
  using M3 = Eigen::Matrix<T, 3, 3>;
  using V3 = Eigen::Matrix<T, 3, 1>;
  const std::size_t n = runs.size(), G = grp.names.size();
  std::vector<M3> W(G, M3::Zero());
  std::vector<V3> b(G, V3::Zero());
  T total(0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const WheelNoiseFitRun& r = runs[i];
    const SecondOrderBasis& q2 = r.second_order;
    const M3 S = qL * r.basis.A_L.cast<T>() + qR * r.basis.A_R.cast<T>() + (qL * qL) * q2.LL.cast<T>() +
                 (qL * qR) * q2.LR.cast<T>() + (qR * qR) * q2.RR.cast<T>() + r.measurement.cast<T>();
    // Positive definiteness by leading principal minors (Sylvester).
    const T m1 = S(0, 0), m2 = S(0, 0) * S(1, 1) - S(0, 1) * S(1, 0);
    if (!(m1 > T(0.0)) || !(m2 > T(0.0))) return false;
    M3 Si = M3::Zero();
    T logdet;
    if (r.has_theta) {
      const T det = S.determinant();
      if (!(det > T(0.0))) return false;
      Si = S.inverse();
      logdet = log(det);
    } else {
      const Eigen::Matrix<T, 2, 2> S2 = S.template topLeftCorner<2, 2>();
      Si.template topLeftCorner<2, 2>() = S2.inverse();
      logdet = log(m2);
    }
    const auto g = static_cast<std::size_t>(grp.of_run[i]);
    const V3 d = (r.error - grp.centre[g]).cast<T>();  // d(2) meets only zeros of Si without etheta
    const V3 Sd = Si * d;
    W[g] += Si;
    b[g] += Sd;
    total += T(0.5) * (d.dot(Sd) + logdet);
  }
  std::vector<V3> mu(G, V3::Zero());
  for (std::size_t g = 0; g < G; ++g) {
    V3 m = V3::Zero();
    if (grp.count_theta[g] > 0) {
      m = W[g].inverse() * b[g];
      if (restricted) total += T(0.5) * log(W[g].determinant());
    } else {
      const Eigen::Matrix<T, 2, 2> W2 = W[g].template topLeftCorner<2, 2>();
      const Eigen::Matrix<T, 2, 1> m2 = W2.inverse() * b[g].template head<2>();
      m << m2(0), m2(1), T(0.0);
      if (restricted) total += T(0.5) * log(W2.determinant());
    }
    total -= T(0.5) * b[g].dot(m);
    mu[g] = m + grp.centre[g].cast<T>();  // centre(2) is 0 in a group without etheta
  }
  *nll = total;
  if (means) *means = mu;
  return true;
}

/// NLL as a function of (log k_L, log k_R).
struct NllCost {
  const std::vector<WheelNoiseFitRun>* runs;
  const Grouping* grp;
  bool restricted = false;  ///< REML (see WheelNoiseFitOptions::restricted)

  template <typename T>
  bool operator()(const T* p, T* cost) const {
    const T qL = exp(T(2.0) * p[0]), qR = exp(T(2.0) * p[1]);
    return ProfiledNll<T>(*runs, *grp, qL, qR, cost, nullptr, restricted);
  }
};

/// Automatic first derivatives of NllCost (a minimal stand-in for
/// ceres::AutoDiffFirstOrderFunction that keeps the Jets on the stack).
class NllFunction final : public ceres::FirstOrderFunction {
 public:
  explicit NllFunction(const NllCost& cost) : cost_(cost) {}
  bool Evaluate(const double* parameters, double* cost, double* gradient) const override {
    if (gradient == nullptr) return cost_(parameters, cost);
    using J = ceres::Jet<double, 2>;
    const J p[2] = {J(parameters[0], 0), J(parameters[1], 1)};
    J out(0.0);
    if (!cost_(p, &out)) return false;
    *cost = out.a;
    gradient[0] = out.v[0];
    gradient[1] = out.v[1];
    return true;
  }
  int NumParameters() const override { return 2; }

 private:
  NllCost cost_;
};

struct Minimum {
  bool ok = false;
  double nll = std::numeric_limits<double>::infinity();
  std::vector<double> params;
  int iterations = 0;
  std::string message;
};

ceres::GradientProblemSolver::Options SolverOptions(int max_iterations) {
  ceres::GradientProblemSolver::Options o;
  o.line_search_direction_type = ceres::LBFGS;
  o.max_num_iterations = max_iterations;
  o.function_tolerance = 1e-13;
  o.gradient_tolerance = 1e-9;
  o.parameter_tolerance = 1e-12;
  o.logging_type = ceres::SILENT;
  return o;
}

Minimum Minimise(const NllCost& cost, std::vector<double> start, int max_iterations) {
  Minimum m;
  ceres::GradientProblemSolver::Summary summary;
  ceres::GradientProblem problem(new NllFunction(cost));
  ceres::Solve(SolverOptions(max_iterations), problem, start.data(), &summary);
  m.ok = summary.termination_type == ceres::CONVERGENCE && std::isfinite(summary.final_cost);
  m.nll = summary.final_cost;
  m.params = start;
  m.iterations = static_cast<int>(summary.iterations.size());
  m.message = summary.message;
  return m;
}

}  // namespace

double WheelNoiseNegLogLikelihood(const std::vector<WheelNoiseFitRun>& runs, double k_L, double k_R) {
  const Grouping grp = MakeGroups(runs);
  double nll = 0.0;
  if (!ProfiledNll(runs, grp, k_L * k_L, k_R * k_R, &nll)) return std::numeric_limits<double>::infinity();
  return nll;
}

std::string WheelNoiseFitSummary::BriefReport() const {
  return fmt::format("k_L = {:.4g} m^1/2 [{:.4g}, {:.4g}], k_R = {:.4g} m^1/2 [{:.4g}, {:.4g}] ({:.0f}% profile "
                     "likelihood), {} runs in {} groups",
                     k_L, k_L_ci[0], k_L_ci[1], k_R, k_R_ci[0], k_R_ci[1], 100 * confidence, runs, groups.size());
}

// ~150 lines: grouping, the maximum-likelihood fit, both profile-likelihood
// intervals and the goodness-of-fit table share one set of per-group sums;
// splitting it into stages is follow-up work (issue 11).
WheelNoiseFitSummary FitWheelNoise(const std::vector<WheelNoiseFitRun>& runs, const WheelNoiseFitOptions& options) {
  if (auto e = options.Check(); !e.empty()) throw InvalidOptions(e);
  // 1. Check the data can identify the model.
  const Grouping grp = MakeGroups(runs);
  const std::size_t n = runs.size(), G = grp.names.size();
  if (n < G + 2) throw InputError("", fmt::format("{} runs in {} groups: fit-noise needs at least groups + 2 runs", n, G));
  for (std::size_t g = 0; g < G; ++g)
    if (grp.count[g] < 2)
      throw InputError("", fmt::format("group '{}' has a single run; its systematic mean would absorb it", grp.names[g]));
  for (const WheelNoiseFitRun& r : runs) {
    if (!r.error.head<2>().allFinite() || (r.has_theta && !std::isfinite(r.error(2))))
      throw InputError("", fmt::format("run {}: return error is not finite", r.run));
  }

  // 2. Starting point: method of moments on the pooled residual covariance.
  Eigen::Vector3d mean_all = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> gm(G, Eigen::Vector3d::Zero());
  for (std::size_t i = 0; i < n; ++i) gm[static_cast<std::size_t>(grp.of_run[i])] += runs[i].error;
  for (std::size_t g = 0; g < G; ++g) gm[g] /= grp.count[g];
  PoseCovariance So = PoseCovariance::Zero(), SL = So, SR = So, SM = So;
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::Vector3d r = runs[i].error - gm[static_cast<std::size_t>(grp.of_run[i])];
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
  std::vector<double> start{0.5 * std::log(q(0)), 0.5 * std::log(q(1))};
  (void)mean_all;

  // 3. Maximum likelihood over (log k_L, log k_R).
  NllCost cost{&runs, &grp, options.restricted};
  double nll0 = 0.0;
  if (!ProfiledNll(runs, grp, q(0), q(1), &nll0))
    throw QualityGateError("fit-noise: the starting point has a singular run covariance");
  ProgressCounter progress(options.progress, options.intervals ? 3.0 : 1.0);
  const Minimum best = Minimise(cost, start, options.max_iterations);
  progress.Add();
  if (!best.ok)
    throw QualityGateError(fmt::format("fit-noise: the maximum-likelihood solver did not converge ({})", best.message));

  WheelNoiseFitSummary out;
  out.k_L = std::exp(best.params[0]);
  out.k_R = std::exp(best.params[1]);
  out.neg_log_likelihood = best.nll;
  out.iterations = best.iterations;
  out.solver_message = best.message;
  out.confidence = options.confidence;
  out.runs = static_cast<int>(n);
  out.groups = grp.names;

  // 4. Profile-likelihood intervals.
  const double delta = 0.5 * ChiSquareQuantile(options.confidence, 1.0);
  // Profile NLL: with one k fixed, minimise over the other by Brent's method
  // in log k (one-dimensional and robust where the likelihood is flat, e.g.
  // when the other k is at its boundary 0), also trying the other k = 0.
  auto nll_at = [&](int which, double k_fixed, double k_other) {
    double v = 0.0;
    const double qf = k_fixed * k_fixed, qo = k_other * k_other;
    const bool ok = which == 0 ? ProfiledNll<double>(runs, grp, qf, qo, &v, nullptr, options.restricted)
                               : ProfiledNll<double>(runs, grp, qo, qf, &v, nullptr, options.restricted);
    return ok ? v : std::numeric_limits<double>::infinity();
  };
  auto profile = [&](int which, double k, double other_log_start) {
    // 28 bits: |log k| <= ~15, so ~1e-7 in log k, as precise as the NLL is flat.
    const ScalarMinimum m = MinimizeBrent([&](double u) { return nll_at(which, k, std::exp(u)); },
                                          other_log_start - 15.0, other_log_start + 5.0, 28);
    return std::min(m.f, nll_at(which, k, 0.0));
  };
  auto interval = [&](int which) -> std::array<double, 2> {
    const double khat = which == 0 ? out.k_L : out.k_R;
    const double other = which == 0 ? best.params[1] : best.params[0];
    auto g = [&](double k) { return profile(which, k, other) - best.nll - delta; };
    // Root of g between khat (g <= 0, the optimum) and b (g > 0).
    auto bisect = [&](double a, double b) { return FindRoot(g, a, b, 1e-6 * khat); };
    std::array<double, 2> ci{0.0, std::numeric_limits<double>::infinity()};
    if (g(0.0) > 0.0) ci[0] = bisect(khat, 0.0);
    double hi = khat * 1.25 + 1e-12;
    for (int it = 0; it < 60; ++it, hi *= 2.0) {
      if (g(hi) > 0.0) {
        ci[1] = bisect(khat, hi);
        break;
      }
    }
    return ci;
  };
  if (options.intervals) {
    out.k_L_ci = interval(0);
    progress.Add();
    out.k_R_ci = interval(1);
    progress.Add();
  } else {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    out.k_L_ci = out.k_R_ci = {nan, nan};
  }

  // 5. Residuals and goodness of fit at the optimum.
  std::vector<Eigen::Vector3d> mu;
  double nll_check = 0.0;
  ProfiledNll(runs, grp, out.k_L * out.k_L, out.k_R * out.k_R, &nll_check, &mu);
  out.group_means = mu;
  const WheelNoise fitted{out.k_L, out.k_R};
  const char* names[6] = {"xx", "yy", "thth", "xy", "xth", "yth"};
  const int ia[6] = {0, 1, 2, 0, 0, 1}, ib[6] = {0, 1, 2, 1, 2, 2};
  std::array<double, 6> obs{}, pred{}, var{};
  std::array<int, 6> cnt{};
  std::array<std::vector<int>, 6> groups_seen;
  for (std::size_t i = 0; i < n; ++i) {
    const WheelNoiseFitRun& r = runs[i];
    const PoseCovariance S = r.basis.Evaluate(fitted) + r.second_order.Covariance(fitted) + r.measurement;
    Eigen::Vector3d res = r.error - mu[static_cast<std::size_t>(grp.of_run[i])];
    if (!r.has_theta) res(2) = std::numeric_limits<double>::quiet_NaN();
    out.residuals.push_back(res);
    out.predicted_run_covariance.push_back(S);
    for (int e = 0; e < 6; ++e) {
      if (!r.has_theta && (ia[e] == 2 || ib[e] == 2)) continue;
      obs[static_cast<std::size_t>(e)] += res(ia[e]) * res(ib[e]);
      pred[static_cast<std::size_t>(e)] += S(ia[e], ib[e]);
      var[static_cast<std::size_t>(e)] += S(ia[e], ia[e]) * S(ib[e], ib[e]) + S(ia[e], ib[e]) * S(ia[e], ib[e]);
      ++cnt[static_cast<std::size_t>(e)];
      auto& seen = groups_seen[static_cast<std::size_t>(e)];
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
  return out;
}

}  // namespace umbmark
