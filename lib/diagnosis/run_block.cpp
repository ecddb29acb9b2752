// run_time_offset's per-run likelihood block (see run_block.hpp).
#include "diagnosis/run_block.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Dense>

#include "core/angles.hpp"

namespace umbmark::diag {

namespace {

constexpr double kLog2Pi = 1.8378770664093453;

/// log Phi(x), also far in the lower tail (Mills' ratio asymptote).
double LogPhi(double x) {
  if (x > -30.0) return std::log(0.5 * std::erfc(-x / std::sqrt(2.0)));
  return -0.5 * x * x - std::log(-x) - 0.5 * kLog2Pi;
}

bool Used(const std::vector<char>* use, std::size_t j) { return !use || use->empty() || (*use)[j] != 0; }

/// What one run contributes for a given tau_sd, from sums that do not
/// depend on it: sum_j log N(e_j; 0, C0_j) and, per side s (0: u > 0 with
/// the lead lever, 1: u < 0 with the lag lever), a_s and b_s.
struct RunSums {
  double ll0 = 0.0;
  double a[2] = {0.0, 0.0}, b[2] = {0.0, 0.0};
};

/// log p(e) of the run for tau_sd^2 = s2 (run_block.hpp).
double RunLogLik(const RunSums& r, double s2) {
  if (!(s2 > 0.0)) return r.ll0;
  double t[2];
  for (int s = 0; s < 2; ++s) {
    const double P = r.a[s] + 1.0 / s2;
    const double z = (s == 0 ? r.b[s] : -r.b[s]) / std::sqrt(P);
    t[s] = r.b[s] * r.b[s] / (2.0 * P) - 0.5 * std::log(s2 * P) + LogPhi(z);
  }
  const double mx = std::max(t[0], t[1]);
  return r.ll0 + mx + std::log(std::exp(t[0] - mx) + std::exp(t[1] - mx));
}

/// The sums of every run with a used piece (C0: the noise without tau_sd).
std::vector<RunSums> Sums(const std::vector<double>& eps, const std::vector<PieceBases>& bases,
                          const std::vector<Piece>& pieces, const NoiseParams& n, const std::vector<char>* use) {
  NoiseParams n0 = n;
  n0.run_tau2 = 0.0;
  std::vector<RunSums> out;
  int current = -1;
  for (std::size_t j = 0; j < pieces.size(); ++j) {
    if (!Used(use, j)) continue;
    if (pieces[j].run != current) {
      out.emplace_back();
      current = pieces[j].run;
    }
    RunSums& r = out.back();
    const int d = pieces[j].components;
    const PieceBases& B = bases[j];
    const Eigen::MatrixXd C = PieceCovariance(B, n0).topLeftCorner(d, d);
    const Eigen::LLT<Eigen::MatrixXd> llt(C);
    if (llt.info() != Eigen::Success) {
      r.ll0 += -1e300;
      continue;
    }
    const Eigen::VectorXd e = Eigen::Map<const Eigen::Vector3d>(&eps[3 * j]).head(d);
    const Eigen::VectorXd Ce = llt.solve(e);
    const Eigen::MatrixXd L = llt.matrixL();
    r.ll0 += -0.5 * (e.dot(Ce) + 2.0 * L.diagonal().array().log().sum() + d * kLog2Pi);
    // The residual at tau = 0 of a run whose offset is tau_i is
    // eps(tau_i) - tau_i J(tau_i side) = noise + u J: u > 0 is a lead
    // (tau_i < 0), whose slope is the lever below 0.
    const Eigen::VectorXd g[2] = {B.tau_lever_neg.head(d), B.tau_lever_pos.head(d)};
    for (int s = 0; s < 2; ++s) {
      r.a[s] += g[s].dot(llt.solve(g[s]));
      r.b[s] += g[s].dot(Ce);
    }
  }
  return out;
}

}  // namespace

bool HasRunBlocks(const NoiseParams& n) { return n.run_tau2 > 0.0 && !(n.bump_rate > 0.0 && n.bump_s2 > 0.0); }

double BlockLogLik(const std::vector<double>& eps, const std::vector<PieceBases>& bases,
                   const std::vector<Piece>& pieces, const NoiseParams& n, const std::vector<char>* use) {
  double ll = 0.0;
  if (!HasRunBlocks(n)) {
    for (std::size_t j = 0; j < pieces.size(); ++j)
      if (Used(use, j)) ll += PieceLogLik(&eps[3 * j], pieces[j].components, bases[j], n);
    return ll;
  }
  for (const RunSums& r : Sums(eps, bases, pieces, n, use)) ll += RunLogLik(r, n.run_tau2);
  return ll;
}

std::vector<Innovation> RunInnovations(const std::vector<double>& eps, const std::vector<PieceBases>& bases,
                                       const std::vector<Piece>& pieces, const NoiseParams& n) {
  std::vector<Innovation> out(pieces.size());
  const bool block = HasRunBlocks(n);
  NoiseParams n0 = n;
  if (block) n0.run_tau2 = 0.0;
  // Filter state over w = (u+, u-): mean m, covariance V (run_block.hpp).
  Eigen::Vector2d m = Eigen::Vector2d::Zero();
  Eigen::Matrix2d V = Eigen::Matrix2d::Zero();
  int current = -1;
  for (std::size_t j = 0; j < pieces.size(); ++j) {
    Innovation& in = out[j];
    in.v = Eigen::Map<const Eigen::Vector3d>(&eps[3 * j]);
    in.S = PieceCovariance(bases[j], n0);
    if (!block) continue;
    if (pieces[j].run != current) {
      // w = (max(u, 0), min(u, 0)) for u ~ N(0, tau_sd^2): mean
      // tau_sd / sqrt(2 pi) (1, -1), variances tau_sd^2 (1/2 - 1/(2 pi)),
      // covariance tau_sd^2 / (2 pi).
      current = pieces[j].run;
      const double s2 = n.run_tau2, c = 1.0 / (2.0 * kPi);
      m = std::sqrt(s2 * c) * Eigen::Vector2d(1.0, -1.0);
      V << s2 * (0.5 - c), s2 * c, s2 * c, s2 * (0.5 - c);
    }
    const int d = pieces[j].components;
    Eigen::Matrix<double, 3, 2> G;
    G.col(0) = bases[j].tau_lever_neg;
    G.col(1) = bases[j].tau_lever_pos;
    if (d == 2) G.row(2).setZero();
    in.v -= G * m;
    in.S += G * V * G.transpose();
    // Update on the piece's d components (the third of a 2-component piece
    // carries nothing).
    const Eigen::MatrixXd Sd = in.S.topLeftCorner(d, d);
    const Eigen::MatrixXd Gd = G.topRows(d);
    const Eigen::MatrixXd K = V * Gd.transpose() * Sd.ldlt().solve(Eigen::MatrixXd::Identity(d, d));
    m += K * in.v.head(d);
    V -= K * Gd * V;
    V = 0.5 * (V + V.transpose()).eval();
  }
  return out;
}

std::vector<PieceBases> RescaleTimeLevers(const MeanModel& model, const ParamVector& p, std::vector<PieceBases> bases,
                                          NoiseParams& n, const NoiseRefit& refit) {
  for (int pass = 0; pass < 2 && n.run_tau2 > 0.0; ++pass) {
    SetTimeOffsetLevers(model, p, std::sqrt(n.run_tau2), bases);
    n = refit(bases, n);
  }
  return bases;
}

}  // namespace umbmark::diag
