// Null distribution of the gap score (see null_distribution.hpp).
#include "diagnosis/null_distribution.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include <Eigen/Cholesky>
#include <Eigen/Dense>

#include "diagnosis/mean_fit.hpp"
#include "diagnosis/stop_model.hpp"
#include "core/parallel_for.hpp"
#include "simulation/rng.hpp"

namespace umbmark::diag {

namespace {

/// Per-piece data for simulating null campaigns.
struct NullPiece {
  Eigen::Matrix3d wheel_chol = Eigen::Matrix3d::Zero();
  double theta_a = 0.0;  ///< predicted heading at the start sample (run frame)
  double dx = 0.0, dy = 0.0;  ///< predicted relative motion
  bool moves_left = false, moves_right = false;
};

constexpr double kSqrt12 = 3.4641016151377544;

/// G of null campaign `rep` (one function: the boundary draws, the piece
/// residuals and the refit share its generator, in this order).
double SimulateNull(const CampaignData& c, const BaselineFit& ctx, const NullOptions& options,
                    const std::vector<NullPiece>& np, const Eigen::MatrixXd& K, int rep) {
  const std::size_t n = c.pieces.size();
  const double sxy = std::sqrt(ctx.noise.sxy2), sth = std::sqrt(ctx.noise.sth2);
  std::vector<double> eps(3 * n);
  PieceNoiseFitOptions nfo = ctx.noise_fit;
  nfo.line_search = false;
  nfo.max_iterations = 2;
  {
    sim::Xoshiro256pp gen(sim::StreamSeed(options.seed, static_cast<std::uint64_t>(rep), 201));
    double spare = 0.0;
    bool has_spare = false;
    auto normal = [&]() {
      if (has_spare) {
        has_spare = false;
        return spare;
      }
      double z0, z1;
      const std::uint64_t a = gen.Next(), b = gen.Next();
      sim::NormalPairFromBits(a, b, z0, z1);
      spare = z1;
      has_spare = true;
      return z0;
    };
    // Boundary noise (world-frame ground truth averaged over the boundary's
    // samples, count errors), drawn once per boundary of a run and shared by
    // the pieces that meet there.
    struct Boundary {
      double x, y, t, ql, qr;
    };
    std::map<std::pair<std::size_t, std::size_t>, Boundary> boundaries;
    int boundary_run = -1;
    auto boundary = [&](const Piece& p, std::size_t lo, std::size_t hi, double weight, bool draw_counts_left,
                        bool draw_counts_right, const Boundary* carry) {
      const DiagRun& run = c.runs[p.run];
      if (p.run != boundary_run) {
        boundaries.clear();
        boundary_run = p.run;
      }
      const auto key = std::make_pair(lo, hi);
      if (const auto it = boundaries.find(key); it != boundaries.end()) return it->second;
      const double sw = std::sqrt(weight);
      Boundary nb;
      nb.x = sw * sxy * normal();
      nb.y = sw * sxy * normal();
      nb.t = sw * sth * normal();
      if (run.q_cov_lr[lo] != 0.0) {
        // A joint stop in the body reading: the two wheels' rests are drawn
        // together (stop_model.hpp); q is minus the travel error (e -= quant_end q).
        const double coin = gen.Uniform(), u = gen.Uniform();
        const auto [el, er] =
            DrawBodyStop(coin, u, run.stop_dir_left[lo], run.stop_dir_right[lo], c.tick_left_m, c.tick_right_m);
        nb.ql = draw_counts_left || !carry ? -el : carry->ql;
        nb.qr = draw_counts_right || !carry ? -er : carry->qr;
      } else {
        nb.ql = draw_counts_left || !carry ? (gen.Uniform() - 0.5) * kSqrt12 * run.q_sd_left[lo] : carry->ql;
        nb.qr = draw_counts_right || !carry ? (gen.Uniform() - 0.5) * kSqrt12 * run.q_sd_right[lo] : carry->qr;
      }
      boundaries.emplace(key, nb);
      return nb;
    };
    for (std::size_t j = 0; j < n; ++j) {
      const Piece& p = c.pieces[j];
      const Boundary ba = boundary(p, p.a_lo, p.a_hi, p.a_weight, true, true, nullptr);
      const Boundary bb = boundary(p, p.b_lo, p.b_hi, p.b_weight, np[j].moves_left, np[j].moves_right, &ba);
      const double na_x = ba.x, na_y = ba.y, na_t = ba.t, qa_l = ba.ql, qa_r = ba.qr;
      const double nb_x = bb.x, nb_y = bb.y, nb_t = bb.t, qb_l = bb.ql, qb_r = bb.qr;
      const Eigen::Vector3d z(normal(), normal(), normal());
      Eigen::Vector3d e = np[j].wheel_chol * z;
      const double ct = std::cos(np[j].theta_a), st = std::sin(np[j].theta_a);
      const double wx = nb_x - na_x, wy = nb_y - na_y;
      e[0] += ct * wx + st * wy + np[j].dy * na_t;
      e[1] += -st * wx + ct * wy - np[j].dx * na_t;
      e[2] += nb_t - na_t;
      if (!c.runs[p.run].endpoint) {
        const PieceBases& B = ctx.bases[j];
        e -= B.quant_end * Eigen::Vector2d(qb_l, qb_r);
        e += B.quant_start * Eigen::Vector2d(qa_l, qa_r);
      }
      if (p.components == 2) e[2] = 0.0;
      eps[3 * j] = e[0];
      eps[3 * j + 1] = e[1];
      eps[3 * j + 2] = e[2];
    }
    // Refit the baseline's E_d, E_b (linearised) and noise, like the data.
    if (K.rows() > 0) {
      Eigen::VectorXd rw(static_cast<Eigen::Index>(3 * n));
      for (std::size_t j = 0; j < n; ++j)
        rw.segment<3>(static_cast<Eigen::Index>(3 * j)) =
            ctx.W[j] * Eigen::Vector3d(eps[3 * j], eps[3 * j + 1], eps[3 * j + 2]);
      const Eigen::VectorXd delta = -K * rw;
      const Eigen::VectorXd shift = ctx.D * delta;
      for (std::size_t i = 0; i < eps.size(); ++i) eps[i] += shift[static_cast<Eigen::Index>(i)];
    }
    const NoiseParams nf = FitPieceNoise(eps, ctx.bases, c.pieces, {}, ctx.noise, nfo);
    return ComputeGap(c, PieceScores(eps, ctx.bases, c.pieces, nf), options.gap).score;
  }
}

}  // namespace

NullDistribution SimulateNullDistribution(const CampaignData& c, const MeanModel& model, const BaselineFit& b,
                                          const NullOptions& options) {
  const std::size_t n = c.pieces.size();
  const ParamVector& p = b.p;
  const NoiseParams& noise = b.noise;
  std::vector<NullPiece> np(n);
  const std::vector<Pose2> motion = model.PredictedPieceMotion(p);
  std::vector<std::vector<Pose2>> predicted(c.runs.size());
  for (std::size_t r = 0; r < c.runs.size(); ++r) predicted[r] = model.PredictRun(static_cast<int>(r), p);
  for (std::size_t j = 0; j < n; ++j) {
    const PieceBases& B = b.bases[j];
    const Eigen::Matrix3d U = noise.kL2 * B.A_L + noise.kR2 * B.A_R;
    Eigen::LDLT<Eigen::Matrix3d> ldlt(U);
    Eigen::Matrix3d L = Eigen::Matrix3d::Zero();
    if (U.trace() > 0.0) {
      // U = P^T L D L^T P -> factor P^T L sqrt(D).
      const Eigen::Vector3d d = ldlt.vectorD().cwiseMax(0.0).cwiseSqrt();
      const Eigen::Matrix3d Lm = ldlt.matrixL();
      L = ldlt.transpositionsP().transpose() * (Lm * d.asDiagonal());
    }
    np[j].wheel_chol = L;
    np[j].theta_a = predicted[c.pieces[j].run][c.pieces[j].a].theta;
    np[j].dx = motion[j].x;
    np[j].dy = motion[j].y;
    np[j].moves_left = B.travel_left_m > 0.0;
    np[j].moves_right = B.travel_right_m > 0.0;
  }
  Eigen::VectorXd rw;
  Eigen::MatrixXd Jw;
  Whiten(b.W, b.eps, b.D, rw, Jw);
  Eigen::MatrixXd A = Jw.transpose() * Jw;
  for (Eigen::Index k = 0; k < A.rows(); ++k) A(k, k) *= 1.0 + 1e-12;
  const Eigen::MatrixXd K = A.ldlt().solve(Jw.transpose());
  std::vector<double> null(static_cast<std::size_t>(options.simulations));
  ProgressCounter progress(options.progress, options.simulations);
  ParallelFor(options.threads, options.simulations, [&](int rep) {
    null[static_cast<std::size_t>(rep)] = SimulateNull(c, b, options, np, K, rep);
    progress.Add();
  });
  NullDistribution out;
  out.sorted = null;
  std::sort(out.sorted.begin(), out.sorted.end());
  const std::vector<double>& sorted = out.sorted;
  out.median = sorted[sorted.size() / 2];
  out.quantile_alpha = sorted[std::min(
      sorted.size() - 1, static_cast<std::size_t>(std::floor((1.0 - options.alpha) * static_cast<double>(sorted.size()))))];
  return out;
}

double NullPValue(const std::vector<double>& sorted, double g) {
  const double B = static_cast<double>(sorted.size());
  const auto first_at_or_above = std::lower_bound(sorted.begin(), sorted.end(), g);
  const double above = static_cast<double>(sorted.end() - first_at_or_above);
  if (above >= 10.0) return (1.0 + above) / (1.0 + B);
  const std::size_t iu = static_cast<std::size_t>(std::floor(0.8 * B));
  const double u = sorted[std::min(iu, sorted.size() - 1)];
  double excess = 0.0;
  int n_u = 0;
  for (double v : sorted)
    if (v > u) {
      excess += v - u;
      ++n_u;
    }
  if (n_u == 0 || !(excess > 0.0)) return (1.0 + above) / (1.0 + B);
  const double beta = excess / n_u;
  const double p = (static_cast<double>(n_u) / B) * std::exp(-(g - u) / beta);
  return std::clamp(p, 1e-300, (1.0 + above) / (1.0 + B));
}

}  // namespace umbmark::diag
