// The profiled wheel-noise likelihood, Fisher scoring and the
// profile-interval search; see wheel_noise_likelihood.hpp.
#include "error_models/wheel_noise_likelihood.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include <Eigen/Dense>

#include "core/parallel_for.hpp"

namespace umbmark::noise_fit {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
/// log k below which a free k counts as having reached its boundary 0.
constexpr double kBoundaryLog = -40.0;
/// Twice the predicted decrease below which a profile's minimisation stops:
/// the interval search needs the profile NLL to 1e-4 (2e-4 on its signed
/// root near 2), and a Newton step below 1e-6 leaves an error of ~1e-12.
constexpr double kProfileDecrement = 1e-6;

using Bases = std::array<const PoseCovariance*, 5>;

/// The five matrices S_i is linear in, with coefficients
/// (q_L, q_R, q_L^2, q_L q_R, q_R^2): first-order bases, second-order terms.
Bases BasesOf(const CovarianceBasis& a, const SecondOrderTerms& q) { return {&a.A_L, &a.A_R, &q.LL, &q.LR, &q.RR}; }

/// The five matrices at eps, and their derivative in eps.
void BasesAt(const LikelihoodModel& m, std::size_t i, double eps, std::array<PoseCovariance, 5>& B,
             std::array<PoseCovariance, 5>* dB) {
  const WheelNoiseFitRun& r = (*m.runs)[i];
  const Bases b0 = BasesOf(r.basis, r.second_order);
  if (!m.sensitivity) {
    for (std::size_t k = 0; k < 5; ++k) B[k] = *b0[k];
    return;
  }
  const WheelNoiseRunSensitivity& s = (*m.sensitivity)[i];
  const std::array<PoseCovariance, 2> b1{s.d1_L.cast<double>(), s.d1_R.cast<double>()};
  const std::array<PoseCovariance, 2> b2{s.d2_L.cast<double>(), s.d2_R.cast<double>()};
  for (std::size_t k = 0; k < 5; ++k) {
    if (k < 2) {
      B[k] = *b0[k] + eps * b1[k] + (eps * eps) * b2[k];
      if (dB) (*dB)[k] = b1[k] + (2.0 * eps) * b2[k];
    } else {  // second-order terms: fixed at E_d0 (WheelNoiseRunSensitivity)
      B[k] = *b0[k];
      if (dB) (*dB)[k].setZero();
    }
  }
}

/// Per-group sums of the one-pass likelihood and their derivatives.
struct GroupSums {
  Eigen::Matrix3d W = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  std::array<Eigen::Matrix3d, 3> dW{Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero()};
  std::array<Eigen::Vector3d, 3> db{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
};

/// S^-1 (zero-padded to the x-y block without a heading) and log det S;
/// false when S is not positive definite (leading minors, Sylvester).
bool InverseAndLogDet(const PoseCovariance& S, bool has_theta, Eigen::Matrix3d& Si, double& logdet) {
  const double m1 = S(0, 0), m2 = S(0, 0) * S(1, 1) - S(0, 1) * S(1, 0);
  if (!(m1 > 0.0) || !(m2 > 0.0)) return false;
  Si.setZero();
  if (has_theta) {
    const double det = S.determinant();
    if (!(det > 0.0)) return false;
    Si = S.inverse();
    logdet = std::log(det);
  } else {
    Si.topLeftCorner<2, 2>() = S.topLeftCorner<2, 2>().inverse();
    logdet = std::log(m2);
  }
  return true;
}

}  // namespace

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
    const Eigen::Vector3d e = runs[i].error - runs[i].systematic;
    g.centre[k].head<2>() += e.head<2>() / g.count[k];
    if (runs[i].has_theta) g.centre[k](2) += e(2) / g.count_theta[k];
  }
  return g;
}

PoseCovariance RunCovariance(const LikelihoodModel& m, std::size_t i, double qL, double qR, double eps) {
  std::array<PoseCovariance, 5> B;
  BasesAt(m, i, eps, B, nullptr);
  const std::array<double, 5> c{qL, qR, qL * qL, qL * qR, qR * qR};
  PoseCovariance S = (*m.runs)[i].measurement;
  for (std::size_t k = 0; k < 5; ++k) S += c[k] * B[k];
  return S;
}

namespace {

/// The per-run sums of one pass over runs [begin, end): the NLL terms,
/// gradient and information terms and the groups' sums.
struct PassSums {
  bool ok = true;
  double total = 0.0;
  Eigen::Vector3d gradient = Eigen::Vector3d::Zero();
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  std::vector<GroupSums> groups;
};

/// Runs per block of a parallel pass; a pass over fewer runs is one block.
/// The blocks depend on the run count only, and their sums are added in
/// block order, so the result does not depend on the threads.
constexpr std::size_t kPassBlock = 1 << 14;

void AccumulateRuns(const LikelihoodModel& m, const Eigen::Vector3d& theta, std::size_t begin, std::size_t end,
                    PassSums& out) {
  const std::vector<WheelNoiseFitRun>& runs = *m.runs;
  const Grouping& grp = *m.groups;
  const int P = m.Dimension();
  const double qL = std::exp(2.0 * theta(0)), qR = std::exp(2.0 * theta(1));
  const double eps = P == 3 ? theta(2) : 0.0;
  const std::array<double, 5> c{qL, qR, qL * qL, qL * qR, qR * qR};
  // d c / d log k_L and d c / d log k_R.
  const std::array<std::array<double, 5>, 2> dc{{{2.0 * qL, 0.0, 4.0 * qL * qL, 2.0 * qL * qR, 0.0},
                                                 {0.0, 2.0 * qR, 0.0, 2.0 * qL * qR, 4.0 * qR * qR}}};
  out.groups.assign(grp.names.size(), GroupSums{});
  std::array<Eigen::Matrix3d, 3> D, E;
  for (std::size_t i = begin; i < end; ++i) {
    const WheelNoiseFitRun& r = runs[i];
    // S and its derivatives straight from the stored bases (no copies: this
    // loop is most of fit-noise's time with many runs). The first-order
    // bases move with eps (WheelNoiseRunSensitivity), the second-order ones
    // do not.
    PoseCovariance A_L = r.basis.A_L, A_R = r.basis.A_R;
    if (P == 3) {
      const WheelNoiseRunSensitivity& sn = (*m.sensitivity)[i];
      const PoseCovariance d1L = sn.d1_L.cast<double>(), d1R = sn.d1_R.cast<double>();
      const PoseCovariance d2L = sn.d2_L.cast<double>(), d2R = sn.d2_R.cast<double>();
      A_L += eps * d1L + (eps * eps) * d2L;
      A_R += eps * d1R + (eps * eps) * d2R;
      D[2] = c[0] * (d1L + (2.0 * eps) * d2L) + c[1] * (d1R + (2.0 * eps) * d2R);
    }
    const SecondOrderTerms& q = r.second_order;
    const PoseCovariance S = r.measurement + c[0] * A_L + c[1] * A_R + c[2] * q.LL + c[3] * q.LR + c[4] * q.RR;
    D[0] = dc[0][0] * A_L + dc[0][2] * q.LL + dc[0][3] * q.LR;
    D[1] = dc[1][1] * A_R + dc[1][3] * q.LR + dc[1][4] * q.RR;
    Eigen::Matrix3d Si;
    double logdet = 0.0;
    if (!InverseAndLogDet(S, r.has_theta, Si, logdet)) {
      out.ok = false;
      return;
    }
    const auto g = static_cast<std::size_t>(grp.of_run[i]);
    const Eigen::Vector3d d = r.error - r.systematic - grp.centre[g];  // d(2) meets only zeros of Si without etheta
    const Eigen::Vector3d Sd = Si * d;
    GroupSums& gs = out.groups[g];
    gs.W += Si;
    gs.b += Sd;
    out.total += 0.5 * (d.dot(Sd) + logdet);
    for (int j = 0; j < P; ++j) {
      const auto u = static_cast<std::size_t>(j);
      E[u] = Si * D[u];
      out.gradient(j) += 0.5 * (E[u].trace() - Sd.dot(D[u] * Sd));
      const Eigen::Matrix3d SiDSi = E[u] * Si;
      gs.dW[u] -= SiDSi;
      gs.db[u] -= SiDSi * d;
    }
    for (int j = 0; j < P; ++j)
      for (int k = j; k < P; ++k) {
        const double v = 0.5 * E[static_cast<std::size_t>(j)].cwiseProduct(E[static_cast<std::size_t>(k)].transpose()).sum();
        out.information(j, k) += v;
        if (k != j) out.information(k, j) += v;
      }
  }
}

}  // namespace

// One pass, storing nothing per run: with d_i = e_i - c_g (c_g the group's
// centre), b_g = sum S_i^-1 d_i and W_g = sum S_i^-1,
//   sum_i (d_i - m_g)^T S_i^-1 (d_i - m_g) = sum_i d_i^T S_i^-1 d_i - b_g^T m_g
// at the GLS mean m_g = W_g^-1 b_g; the derivatives follow from
// dS^-1 = -S^-1 dS S^-1 and, for the profiled means, the envelope theorem.
// The runs are summed in blocks (in parallel with m.threads).
Evaluation Evaluate(const LikelihoodModel& m, const Eigen::Vector3d& theta, std::vector<Eigen::Vector3d>* means) {
  ++m.passes;
  const std::vector<WheelNoiseFitRun>& runs = *m.runs;
  const Grouping& grp = *m.groups;
  const int P = m.Dimension();
  const double eps = P == 3 ? theta(2) : 0.0;
  const std::size_t blocks = (runs.size() + kPassBlock - 1) / kPassBlock;
  std::vector<PassSums> part(std::max<std::size_t>(blocks, 1));
  ParallelFor(blocks > 1 ? ResolveThreads(m.threads) : 1, part.size(), [&](std::size_t k) {
    AccumulateRuns(m, theta, k * kPassBlock, std::min(runs.size(), (k + 1) * kPassBlock), part[k]);
  });
  Evaluation ev;
  double total = 0.0;
  std::vector<GroupSums> sums(grp.names.size());
  for (const PassSums& p : part) {
    if (!p.ok) return ev;
    total += p.total;
    ev.gradient += p.gradient;
    ev.information += p.information;
    for (std::size_t g = 0; g < sums.size(); ++g) {
      sums[g].W += p.groups[g].W;
      sums[g].b += p.groups[g].b;
      for (std::size_t u = 0; u < 3; ++u) {
        sums[g].dW[u] += p.groups[g].dW[u];
        sums[g].db[u] += p.groups[g].db[u];
      }
    }
  }
  if (means) means->assign(grp.names.size(), Eigen::Vector3d::Zero());
  for (std::size_t g = 0; g < grp.names.size(); ++g) {
    const GroupSums& gs = sums[g];
    Eigen::Matrix3d Winv = Eigen::Matrix3d::Zero();
    double logdetW = 0.0;
    if (grp.count_theta[g] > 0) {
      Winv = gs.W.inverse();
      logdetW = std::log(gs.W.determinant());
    } else {
      Winv.topLeftCorner<2, 2>() = gs.W.topLeftCorner<2, 2>().inverse();
      logdetW = std::log(gs.W.topLeftCorner<2, 2>().determinant());
    }
    const Eigen::Vector3d mg = Winv * gs.b;
    total -= 0.5 * gs.b.dot(mg);
    if (m.restricted) total += 0.5 * logdetW;
    for (int j = 0; j < P; ++j) {
      const auto u = static_cast<std::size_t>(j);
      ev.gradient(j) += -mg.dot(gs.db[u]) + 0.5 * mg.dot(gs.dW[u] * mg);
      if (m.restricted) ev.gradient(j) += 0.5 * (Winv * gs.dW[u]).trace();
    }
    if (means) (*means)[g] = mg + grp.centre[g];  // centre(2) is 0 in a group without etheta
  }
  if (P == 3) {
    const double z = (eps - m.eps_prior_centre) / m.eps_prior_sigma;
    total += 0.5 * z * z;
    ev.gradient(2) += z / m.eps_prior_sigma;
    ev.information(2, 2) += 1.0 / (m.eps_prior_sigma * m.eps_prior_sigma);
  }
  ev.nll = total;
  ev.ok = std::isfinite(total) && ev.gradient.allFinite();
  return ev;
}

Optimum Minimise(const LikelihoodModel& m, Eigen::Vector3d start, const std::array<bool, 3>& free,
                 int max_iterations, double min_decrement) {
  Optimum o;
  o.theta = start;
  o.at = Evaluate(m, start);
  if (!o.at.ok) return o;
  o.ok = true;
  const int P = m.Dimension();
  for (int it = 0; it < max_iterations; ++it) {
    o.iterations = it;
    std::vector<int> act;  // free entries still moving (a k at its boundary 0 stops)
    for (int j = 0; j < P; ++j)
      if (free[static_cast<std::size_t>(j)] && !(j < 2 && o.theta(j) < kBoundaryLog)) act.push_back(j);
    if (act.empty()) break;
    const auto n = static_cast<Eigen::Index>(act.size());
    Eigen::VectorXd g(n);
    Eigen::MatrixXd I(n, n);
    for (Eigen::Index a = 0; a < n; ++a) {
      g(a) = o.at.gradient(act[static_cast<std::size_t>(a)]);
      for (Eigen::Index b = 0; b < n; ++b)
        I(a, b) = o.at.information(act[static_cast<std::size_t>(a)], act[static_cast<std::size_t>(b)]);
    }
    I.diagonal().array() += 1e-12 * I.diagonal().maxCoeff() + 1e-300;
    Eigen::VectorXd step = -I.ldlt().solve(g);
    if (!step.allFinite()) break;
    // Twice the predicted decrease: below 1e-7 the NLL is as good as its
    // rounding with 10^6 runs, and far inside the interval search's
    // tolerance (2e-4 on the signed root, about 4e-4 in NLL).
    const double decrement = -g.dot(step);
    if (!(decrement > min_decrement)) break;
    // Trust caps: a factor e^3 in k, 0.01 in E_d per step.
    double scale = 1.0;
    for (Eigen::Index a = 0; a < n; ++a) {
      const double cap = act[static_cast<std::size_t>(a)] < 2 ? 3.0 : 0.01;
      if (std::abs(step(a)) > cap) scale = std::min(scale, cap / std::abs(step(a)));
    }
    step *= scale;
    bool accepted = false;
    double lambda = 1.0;
    for (int ls = 0; ls < 8 && !accepted; ++ls, lambda *= 0.5) {
      Eigen::Vector3d trial = o.theta;
      for (Eigen::Index a = 0; a < n; ++a) trial(act[static_cast<std::size_t>(a)]) += lambda * step(a);
      const Evaluation e = Evaluate(m, trial);
      if (e.ok && e.nll <= o.at.nll + 1e-4 * lambda * g.dot(step)) {
        o.theta = trial;
        o.at = e;
        accepted = true;
      }
    }
    if (!accepted) break;
  }
  return o;
}

namespace {

/// How the other entries of theta move along the profile of entry j, per
/// unit of theta_j: -I_oo^-1 I_oj (the conditional mean of a quadratic
/// NLL with information I); each profile starts there, a pass or two from
/// its minimum. Zero where I is singular.
Eigen::Vector3d RidgeSlope(const Eigen::MatrixXd& I, int j) {
  Eigen::Vector3d ridge = Eigen::Vector3d::Zero();
  std::vector<int> other;
  for (int k = 0; k < static_cast<int>(I.rows()); ++k)
    if (k != j) other.push_back(k);
  const auto n = static_cast<Eigen::Index>(other.size());
  Eigen::MatrixXd Ioo(n, n);
  Eigen::VectorXd Ioj(n);
  for (Eigen::Index a = 0; a < n; ++a) {
    Ioj(a) = I(other[static_cast<std::size_t>(a)], j);
    for (Eigen::Index b = 0; b < n; ++b) Ioo(a, b) = I(other[static_cast<std::size_t>(a)], other[static_cast<std::size_t>(b)]);
  }
  const Eigen::VectorXd slope = -Ioo.ldlt().solve(Ioj);
  if (slope.allFinite())
    for (Eigen::Index a = 0; a < n; ++a) ridge(other[static_cast<std::size_t>(a)]) = slope(a);
  return ridge;
}

}  // namespace

double IntervalEnd(const LikelihoodModel& m, const Optimum& best, int j, int side, double delta, int max_iterations) {
  const double target = std::sqrt(2.0 * delta);
  const int P = m.Dimension();
  std::array<bool, 3> free{true, true, P == 3};
  free[static_cast<std::size_t>(j)] = false;
  const double uhat = best.theta(j);
  // Standard error of log k_j from the information: the first step.
  const Eigen::MatrixXd I = best.at.information.topLeftCorner(P, P);
  const Eigen::MatrixXd Iinv = I.ldlt().solve(Eigen::MatrixXd::Identity(P, P));
  double se = std::sqrt(Iinv(j, j));
  if (!std::isfinite(se) || se <= 0.0) se = 1.0;
  se = std::min(se, 5.0);
  Eigen::Vector3d warm = best.theta;
  const Eigen::Vector3d ridge = RidgeSlope(I, j);
  // Signed root r and dr/ds at s = side (log k - log k_hat) >= 0.
  struct Point {
    double r = kInf, drds = std::numeric_limits<double>::quiet_NaN();
  };
  auto profile = [&](double u) {
    Eigen::Vector3d t = warm;
    if (std::isfinite(u) && std::isfinite(warm(j))) t += (u - warm(j)) * ridge;
    t(j) = u;
    Optimum o = Minimise(m, t, free, max_iterations, kProfileDecrement);
    if (!o.ok && t != warm) {  // the prediction left the valid region: from the last profile
      t = warm;
      t(j) = u;
      o = Minimise(m, t, free, max_iterations, kProfileDecrement);
    }
    Point p;
    if (!o.ok) return p;
    warm = o.theta;
    p.r = std::sqrt(2.0 * std::max(o.at.nll - best.at.nll, 0.0));
    p.drds = side * o.at.gradient(j) / std::max(p.r, 1e-12);  // envelope: dP/du is the partial derivative
    return p;
  };
  // Below the optimum, whether the profile at k = 0 stays within delta (the
  // end is 0) is asked only once a profile short of the target says the end
  // lies beyond the first guess (with many runs it never does: no pass at
  // k = 0, whose minimum is also a poor warm start).
  bool zero_checked = side > 0;
  constexpr double kMaxS = 60.0;  // a factor e^60: unbounded
  double s_in = 0.0, s_out = kInf, s = target * se;
  for (int it = 0; it < 40; ++it) {
    const Point p = profile(uhat + side * s);
    if (std::isfinite(p.r) && std::abs(p.r - target) < 2e-4) return std::exp(uhat + side * s);
    if (std::isfinite(p.r) && p.r < target) {
      s_in = std::max(s_in, s);
      if (!zero_checked) {
        zero_checked = true;
        const Eigen::Vector3d keep = warm;
        if (!(profile(-kInf).r > target)) return 0.0;
        warm = keep;
      }
    } else {
      s_out = std::min(s_out, s);
    }
    double next = std::isfinite(p.r) && p.drds > 0.0 ? s + (target - p.r) / p.drds : kInf;
    if (!(next > s_in && next < s_out)) next = std::isfinite(s_out) ? 0.5 * (s_in + s_out) : 2.0 * s_in + se;
    if (next > kMaxS) return side > 0 ? kInf : 0.0;
    if (s_out - s_in < 1e-10) break;
    s = next;
  }
  return std::exp(uhat + side * s);
}

}  // namespace umbmark::noise_fit
