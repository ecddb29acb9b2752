// The diagnosis driver: baseline, gap and its null distribution, candidate
// effects with cross-validation, verdict (see diagnose.hpp).
#include "diagnosis/diagnose.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <stdexcept>
#include <thread>

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <ceres/ceres.h>
#include <fmt/format.h>

#include "calibration/refine.hpp"
#include "core/angles.hpp"
#include "core/errors.hpp"
#include "error_models/noise_fit.hpp"
#include "error_models/trajectory_covariance.hpp"
#include "kinematics/odometry.hpp"
#include "simulation/rng.hpp"

namespace umbmark::diag {

std::string DiagnoseOptions::Check() const {
  if (null_simulations < 20) return fmt::format("null_simulations = {} must be >= 20", null_simulations);
  if (!(alpha > 0.0 && alpha < 0.5)) return fmt::format("alpha = {} must be in (0, 0.5)", alpha);
  if (!(full_shrink >= min_heldout_shrink && full_shrink <= 1.0))
    return fmt::format("full_shrink = {} must be in [min_heldout_shrink, 1]", full_shrink);
  if (!(min_heldout_shrink > 0.0 && min_heldout_shrink <= 1.0))
    return fmt::format("min_heldout_shrink = {} must be in (0, 1]", min_heldout_shrink);
  if (!(complexity_penalty_nats >= 0.0))
    return fmt::format("complexity_penalty_nats = {} must be >= 0", complexity_penalty_nats);
  if (threads < 1) return fmt::format("threads = {} must be >= 1", threads);
  if (where_top < 0) return fmt::format("where_top = {} must be >= 0", where_top);
  if (auto e = pieces.Check(); !e.empty()) return "pieces: " + e;
  if (!(gap.threshold_se >= 0.0)) return fmt::format("gap.threshold_se = {} must be >= 0", gap.threshold_se);
  return {};
}

namespace {

using Clock = std::chrono::steady_clock;
double Seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

/// Inverse Cholesky factors W_j (scores = W_j eps_j, order heading, x, y) of
/// every piece's covariance (the mixture's mean covariance for bumps).
std::vector<Eigen::Matrix3d> Whiteners(const std::vector<PieceBases>& bases, const std::vector<Piece>& pieces,
                                       const NoiseParams& n) {
  std::vector<Eigen::Matrix3d> W(pieces.size(), Eigen::Matrix3d::Zero());
  for (std::size_t j = 0; j < pieces.size(); ++j) {
    Eigen::Matrix3d C = PieceCovariance(bases[j], n);
    if (n.bump_rate > 0.0 && n.bump_s2 > 0.0) {
      const BumpMixture m = PieceMixture(bases[j], n);
      C.setZero();
      for (int k = 0; k < m.components; ++k) C += m.weight[k] * m.cov[k];
    }
    if (pieces[j].components == 2) {
      const Eigen::Matrix2d L = C.topLeftCorner<2, 2>().llt().matrixL();
      const Eigen::Matrix2d Li = L.inverse();
      W[j].block<2, 2>(1, 0) = Li;
      continue;
    }
    // Permutation P: (x, y, theta) -> (theta, x, y).
    Eigen::Matrix3d P = Eigen::Matrix3d::Zero();
    P(0, 2) = P(1, 0) = P(2, 1) = 1.0;
    const Eigen::Matrix3d Cp = P * C * P.transpose();
    const Eigen::Matrix3d L = Cp.llt().matrixL();
    W[j] = L.inverse() * P;
  }
  return W;
}

/// Whitened residual vector and Jacobian (3 rows per piece).
void Whiten(const std::vector<Eigen::Matrix3d>& W, const std::vector<double>& eps, const Eigen::MatrixXd& D,
            Eigen::VectorXd& rw, Eigen::MatrixXd& Jw) {
  const std::size_t n = W.size();
  rw.resize(static_cast<Eigen::Index>(3 * n));
  Jw.resize(static_cast<Eigen::Index>(3 * n), D.cols());
  for (std::size_t j = 0; j < n; ++j) {
    const auto J3 = static_cast<Eigen::Index>(3 * j);
    rw.segment<3>(J3) = W[j] * Eigen::Vector3d(eps[3 * j], eps[3 * j + 1], eps[3 * j + 2]);
    if (D.cols() > 0) Jw.middleRows(J3, 3) = W[j] * D.middleRows(J3, 3);
  }
}

struct MeanFit {
  ParamVector p{};
  std::vector<double> eps;
  Eigen::MatrixXd D;         ///< d eps / d params at p (unwhitened)
  Eigen::MatrixXd cov;       ///< (Jw^T Jw)^-1 at p
  bool converged = false;
};

/// The whitened piece residuals W_j eps_j as one Ceres cost over the free
/// mean-model parameters `params` (the others held at `base`); the
/// Jacobian is the model's forward differences, whitened.
class WhitenedPieceCost final : public ceres::CostFunction {
 public:
  WhitenedPieceCost(const MeanModel& model, const ParamVector& base, const std::vector<int>& params,
                    const std::vector<Eigen::Matrix3d>& W)
      : model_(model), base_(base), params_(params), W_(W) {
    set_num_residuals(static_cast<int>(3 * W.size()));
    mutable_parameter_block_sizes()->push_back(static_cast<int>(params.size()));
  }

  bool Evaluate(double const* const* x, double* residuals, double** jacobians) const override {
    ParamVector p = base_;
    for (std::size_t k = 0; k < params_.size(); ++k) p[params_[k]] = x[0][k];
    std::vector<double> eps;
    model_.Residuals(p, eps);
    for (double v : eps)
      if (!std::isfinite(v)) return false;
    const std::size_t n = W_.size(), np = params_.size();
    for (std::size_t j = 0; j < n; ++j) {
      const Eigen::Vector3d r = W_[j] * Eigen::Vector3d(eps[3 * j], eps[3 * j + 1], eps[3 * j + 2]);
      for (int c = 0; c < 3; ++c) residuals[3 * j + static_cast<std::size_t>(c)] = r[c];
    }
    if (jacobians && jacobians[0]) {
      const Eigen::MatrixXd D = model_.Jacobian(p, params_, eps);
      if (!D.allFinite()) return false;
      for (std::size_t j = 0; j < n; ++j) {
        const Eigen::MatrixXd Jj = W_[j] * D.middleRows(static_cast<Eigen::Index>(3 * j), 3);
        for (int c = 0; c < 3; ++c)
          for (std::size_t k = 0; k < np; ++k)
            jacobians[0][(3 * j + static_cast<std::size_t>(c)) * np + k] = Jj(c, static_cast<Eigen::Index>(k));
      }
    }
    return true;
  }

 private:
  const MeanModel& model_;
  ParamVector base_;
  std::vector<int> params_;
  const std::vector<Eigen::Matrix3d>& W_;
};

/// Weighted least squares on the whitened piece residuals over `params`
/// (weights W), by Ceres' Levenberg-Marquardt (at most `iterations`
/// iterations; converged when the cost changes by less than 1e-10 of itself,
/// a step of about 1e-3 standard errors).
MeanFit FitMean(const MeanModel& model, const ParamVector& start, const std::vector<int>& params,
                const std::vector<Eigen::Matrix3d>& W, int iterations) {
  MeanFit f;
  f.p = start;
  if (!params.empty()) {
    std::vector<double> x(params.size());
    for (std::size_t k = 0; k < params.size(); ++k) x[k] = start[params[k]];
    ceres::Problem::Options po;
    po.cost_function_ownership = ceres::TAKE_OWNERSHIP;
    ceres::Problem problem(po);
    problem.AddResidualBlock(new WhitenedPieceCost(model, start, params, W), nullptr, x.data());
    ceres::Solver::Options so;
    so.linear_solver_type = ceres::DENSE_QR;
    so.max_num_iterations = iterations;
    so.function_tolerance = 1e-10;
    so.num_threads = 1;  // the candidates already run in parallel
    so.logging_type = ceres::SILENT;
    so.minimizer_progress_to_stdout = false;
    ceres::Solver::Summary summary;
    ceres::Solve(so, &problem, &summary);
    if (summary.IsSolutionUsable())
      for (std::size_t k = 0; k < params.size(); ++k) f.p[params[k]] = x[k];
    f.converged = summary.termination_type == ceres::CONVERGENCE;
  }
  model.Residuals(f.p, f.eps);
  if (params.empty()) return f;
  f.D = model.Jacobian(f.p, params, f.eps);
  Eigen::VectorXd rw;
  Eigen::MatrixXd Jw;
  Whiten(W, f.eps, f.D, rw, Jw);
  Eigen::MatrixXd A = Jw.transpose() * Jw;
  for (Eigen::Index k = 0; k < A.rows(); ++k) A(k, k) *= 1.0 + 1e-12;
  f.cov = A.ldlt().solve(Eigen::MatrixXd::Identity(A.rows(), A.cols()));
  return f;
}

std::vector<int> EffectParams(sim::EffectKind k) {
  switch (k) {
    case sim::EffectKind::kScaleError: return {kParamScale};
    case sim::EffectKind::kTurnScrub: return {kParamScrub};
    case sim::EffectKind::kDirectionAsymmetry: return {kParamAsym};
    case sim::EffectKind::kCastorKick: return {kParamKappa};
    case sim::EffectKind::kParameterDrift: return {kParamDrift};
    case sim::EffectKind::kGtOffset: return {kParamDx, kParamDy};
    case sim::EffectKind::kTimeOffset: return {kParamTau};
    default: return {};
  }
}

/// A typical size of each effect parameter (the realistic ranges of the
/// blind benchmark): an effect is distinguishable from E_d, E_b on a
/// campaign when such an effect would stand 3 standard errors out.
double TypicalMagnitude(int param) {
  switch (param) {
    case kParamScale: return 0.01;
    case kParamScrub: return 0.03;
    case kParamAsym: return 0.01;
    case kParamKappa: return 0.005;
    case kParamDrift: return 1e-4;
    case kParamDx:
    case kParamDy: return 0.01;
    case kParamTau: return 0.02;
    default: return 1.0;
  }
}

/// Contract parameter name of a mean-model parameter.
const char* ContractParamName(int index) { return ParamName(index); }

/// Scores of the pieces with mask[j] (others untouched).
void ScoresFor(const std::vector<double>& eps, const std::vector<PieceBases>& bases, const std::vector<Piece>& pieces,
               const NoiseParams& n, const std::vector<char>& mask, std::vector<Scores>& out, std::vector<double>& ll) {
  std::vector<Piece> sub;
  std::vector<PieceBases> sub_b;
  std::vector<double> sub_e;
  std::vector<std::size_t> idx;
  for (std::size_t j = 0; j < pieces.size(); ++j) {
    if (!mask[j]) continue;
    idx.push_back(j);
    sub.push_back(pieces[j]);
    sub_b.push_back(bases[j]);
    sub_e.insert(sub_e.end(), eps.begin() + static_cast<std::ptrdiff_t>(3 * j),
                 eps.begin() + static_cast<std::ptrdiff_t>(3 * j + 3));
  }
  const std::vector<Scores> s = PieceScores(sub_e, sub_b, sub, n);
  for (std::size_t k = 0; k < idx.size(); ++k) {
    out[idx[k]] = s[k];
    ll[idx[k]] = PieceLogLik(&sub_e[3 * k], sub[k].components, sub_b[k], n);
  }
}

/// Everything the candidate fits share.
struct Context {
  const CampaignData* c = nullptr;
  const MeanModel* model = nullptr;
  const DiagnoseOptions* options = nullptr;
  std::vector<PieceBases> bases;
  ParamVector p_base{};
  NoiseParams noise_base;
  std::vector<double> eps_base;
  std::vector<Eigen::Matrix3d> W_base;
  Eigen::MatrixXd D_base;  ///< d eps / d (E_d, E_b) at the baseline
  NoiseFitOptions noise_fit;
  double null_median = 0.0;
  std::vector<std::vector<char>> train;  ///< per fold: pieces used for fitting
  std::vector<std::vector<char>> test;
};

/// Cross-validated scores and log-likelihoods: the mean refitted linearly on
/// each fold's training pieces (Jacobian D at the full fit), the noise by
/// `fit_noise` on the same pieces.
void CrossValidate(const Context& ctx, const std::vector<double>& eps, const Eigen::MatrixXd& D,
                   const std::vector<Eigen::Matrix3d>& W, const std::function<NoiseParams(const std::vector<double>&,
                                                                                         const std::vector<char>&)>& fit_noise,
                   std::vector<Scores>& scores, double& loglik) {
  const std::size_t n = ctx.c->pieces.size();
  scores.assign(n, Scores{});
  std::vector<double> ll(n, 0.0);
  Eigen::VectorXd rw;
  Eigen::MatrixXd Jw;
  Whiten(W, eps, D, rw, Jw);
  for (std::size_t f = 0; f < ctx.train.size(); ++f) {
    std::vector<double> eps_f = eps;
    if (D.cols() > 0) {
      Eigen::MatrixXd A = Eigen::MatrixXd::Zero(D.cols(), D.cols());
      Eigen::VectorXd g = Eigen::VectorXd::Zero(D.cols());
      for (std::size_t j = 0; j < n; ++j) {
        if (!ctx.train[f][j]) continue;
        const auto rows = Jw.middleRows(static_cast<Eigen::Index>(3 * j), 3);
        A += rows.transpose() * rows;
        g += rows.transpose() * rw.segment<3>(static_cast<Eigen::Index>(3 * j));
      }
      for (Eigen::Index k = 0; k < A.rows(); ++k) A(k, k) *= 1.0 + 1e-12;
      const Eigen::VectorXd delta = -A.ldlt().solve(g);
      if (delta.allFinite()) {
        const Eigen::VectorXd shift = D * delta;
        for (std::size_t i = 0; i < eps_f.size(); ++i) eps_f[i] += shift[static_cast<Eigen::Index>(i)];
      }
    }
    const NoiseParams nf = fit_noise(eps_f, ctx.train[f]);
    ScoresFor(eps_f, ctx.bases, ctx.c->pieces, nf, ctx.test[f], scores, ll);
  }
  loglik = 0.0;
  for (double v : ll) loglik += v;
}

/// Gaussian log-likelihood of all pieces.
double TotalLogLik(const Context& ctx, const std::vector<double>& eps, const NoiseParams& n) {
  double ll = 0.0;
  for (std::size_t j = 0; j < ctx.c->pieces.size(); ++j)
    ll += PieceLogLik(&eps[3 * j], ctx.c->pieces[j].components, ctx.bases[j], n);
  return ll;
}

/// Upper tail of chi^2 with 1 or 2 degrees of freedom (the candidates have
/// at most two parameters).
double ChiSquareSurvival(double x, int df) {
  if (!(x > 0.0)) return 1.0;
  if (df == 1) return std::erfc(std::sqrt(0.5 * x));
  if (df == 2) return std::exp(-0.5 * x);
  throw std::logic_error("ChiSquareSurvival: df must be 1 or 2");
}

double Gap(const Context& ctx, double score) { return std::max(0.0, score - ctx.null_median); }

/// 1 - after / before, 0 without a gap, floored at -1 (an effect that makes
/// the gap more than twice as large is simply "much worse").
double Shrink(double after, double before) { return before > 0.0 ? std::max(-1.0, 1.0 - after / before) : 0.0; }

/// Per-piece data for simulating null campaigns.
struct NullPiece {
  Eigen::Matrix3d wheel_chol = Eigen::Matrix3d::Zero();
  double theta_a = 0.0;  ///< predicted heading at the start sample (run frame)
  double dx = 0.0, dy = 0.0;  ///< predicted relative motion
  bool moves_left = false, moves_right = false;
};

constexpr double kSqrt12 = 3.4641016151377544;

/// G of `count` null campaigns starting at replicate `first`.
void SimulateNull(const Context& ctx, const std::vector<NullPiece>& np, const Eigen::MatrixXd& K, int first, int count,
                  std::vector<double>& out) {
  const CampaignData& c = *ctx.c;
  const std::size_t n = c.pieces.size();
  const double sxy = std::sqrt(ctx.noise_base.sxy2), sth = std::sqrt(ctx.noise_base.sth2);
  std::vector<double> eps(3 * n);
  NoiseFitOptions nfo = ctx.noise_fit;
  nfo.line_search = false;
  nfo.max_iterations = 2;
  for (int rep = first; rep < first + count; ++rep) {
    sim::Xoshiro256pp gen(sim::StreamSeed(ctx.options->seed, static_cast<std::uint64_t>(rep), 201));
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
      nb.ql = draw_counts_left || !carry ? (gen.Uniform() - 0.5) * kSqrt12 * run.q_sd_left[lo] : carry->ql;
      nb.qr = draw_counts_right || !carry ? (gen.Uniform() - 0.5) * kSqrt12 * run.q_sd_right[lo] : carry->qr;
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
            ctx.W_base[j] * Eigen::Vector3d(eps[3 * j], eps[3 * j + 1], eps[3 * j + 2]);
      const Eigen::VectorXd delta = -K * rw;
      const Eigen::VectorXd shift = ctx.D_base * delta;
      for (std::size_t i = 0; i < eps.size(); ++i) eps[i] += shift[static_cast<Eigen::Index>(i)];
    }
    const NoiseParams nf = FitNoise(eps, ctx.bases, c.pieces, {}, ctx.noise_base, nfo);
    out[static_cast<std::size_t>(rep)] = ComputeGap(c, PieceScores(eps, ctx.bases, c.pieces, nf), ctx.options->gap).score;
  }
}

/// p-value of `g` against the sorted null sample: the empirical tail
/// (1 + #{G* >= g}) / (1 + B) while at least 10 simulations reach g; beyond
/// that an exponential tail fitted to the excesses over the null's 80 %
/// quantile (peaks over threshold with shape 0: G is a sum of squared
/// excesses, whose tail decays like a gamma's), so significance does not
/// depend on B being large.
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

void RunParallel(int threads, int count, const std::function<void(int, int)>& work) {
  threads = std::max(1, std::min(threads, count));
  if (threads == 1) {
    work(0, count);
    return;
  }
  std::vector<std::thread> pool;
  const int per = (count + threads - 1) / threads;
  for (int t = 0; t < threads; ++t) {
    const int first = t * per, n = std::min(per, count - first);
    if (n > 0) pool.emplace_back(work, first, n);
  }
  for (auto& th : pool) th.join();
}

std::string WhereComponent(const GapStatistic& s) {
  if (s.kind == StatKind::kCorrelation) return fmt::format("{} x {}", ComponentName(s.comp_a), ComponentName(s.comp_b));
  return ComponentName(s.comp_a);
}

}  // namespace

DiagnoseSummary Diagnose(const CampaignData& c, const DiagnoseOptions& options) {
  if (auto e = options.Check(); !e.empty()) throw InvalidOptions("diagnose: " + e);
  DiagnoseSummary out;
  out.alpha = options.alpha;
  out.seed = options.seed;
  for (std::size_t e = 0; e < c.experiments.size(); ++e)
    out.experiment_labels.push_back(
        fmt::format("{} ({}, {})", e + 1, ExperimentKindToString(c.experiments[e].kind), c.experiments[e].file));
  const auto t_start = Clock::now();
  MeanModel model(c);
  Context ctx;
  ctx.c = &c;
  ctx.model = &model;
  ctx.options = &options;
  const std::size_t n = c.pieces.size();

  // ---- 1. Baseline -------------------------------------------------------
  ParamVector p = NominalParams();
  out.baseline.start = "nominal (E_d = E_b = 1)";
  bool refined = false;
  if (options.use_refine) {
    try {
      RefineOptions ro;
      ro.scale = ScaleMode::kFixed;
      std::vector<TrajectoryRunSet> tsets;
      std::vector<SquareRunSet> ssets;
      for (std::size_t e = 0; e < c.experiments.size(); ++e) {
        if (const auto* t = std::get_if<TrajectoryData>(&c.files[e])) {
          tsets.push_back({c.robot, t});
        } else {
          SquareRunSet s;
          s.side_m = c.experiments[e].side_m;
          s.recorded = c.robot;
          s.source = c.experiments[e].file;
          for (const auto& r : std::get<EndpointData>(c.files[e]).runs) {
            ReturnError re;
            re.run = r.run;
            re.direction = r.direction;
            re.ex_m = r.ex_m;
            re.ey_m = r.ey_m;
            re.etheta_rad = r.etheta_rad;
            s.errors.push_back(re);
          }
          ssets.push_back(s);
        }
      }
      const RefineSummary rs = tsets.empty() ? RefineFromReturnErrors(ssets, c.robot, ro)
                                             : RefineFromTrajectories(tsets, c.robot, ro);
      if (std::isfinite(rs.E_d) && std::isfinite(rs.E_b) && rs.E_d > 0.5 && rs.E_d < 2.0 && rs.E_b > 0.5 &&
          rs.E_b < 2.0) {
        p[kParamEd] = rs.E_d;
        p[kParamEb] = rs.E_b;
        out.baseline.start = fmt::format("refined calibration ({}): E_d = {:.6f}, E_b = {:.6f}",
                                         tsets.empty() ? "return errors" : "trajectories", rs.E_d, rs.E_b);
        refined = true;
      }
    } catch (const std::exception& e) {
      out.notes.push_back(std::string("refined calibration unavailable, starting from the nominal robot: ") + e.what());
    }
  }
  const auto t_refine = Clock::now();
  const ParamVector start_p = p;

  NoiseParams noise;
  const bool gt_known = c.ground_truth.has_value();
  ctx.noise_fit.fit_ground_truth = !gt_known;
  // Floors: 1 micrometre / 1 microradian keep noise-free ground truth usable.
  noise.sxy2 = gt_known ? std::max(c.ground_truth->sigma_xy_m * c.ground_truth->sigma_xy_m, 1e-12) : 1e-8;
  noise.sth2 = gt_known ? std::max(c.ground_truth->sigma_theta_rad * c.ground_truth->sigma_theta_rad, 1e-12) : 1e-6;
  ctx.noise_fit.min_sigma_xy2 = 1e-12;
  ctx.noise_fit.min_sigma_theta2 = 1e-12;
  const std::vector<int> base_params = {kParamEd, kParamEb};
  std::vector<double> eps;
  model.Residuals(p, eps);
  ctx.bases = ComputeBases(c, model, p);
  noise = FitNoise(eps, ctx.bases, c.pieces, {}, noise, ctx.noise_fit);
  MeanFit base;
  for (int round = 0; round < 2; ++round) {
    base = FitMean(model, p, base_params, Whiteners(ctx.bases, c.pieces, noise), 10);
    p = base.p;
    if (round == 0) ctx.bases = ComputeBases(c, model, p);
    noise = FitNoise(base.eps, ctx.bases, c.pieces, {}, noise, ctx.noise_fit);
  }
  if (refined && base.cov.rows() == 2) {
    // The calibration and the model's best fit on the pieces should agree
    // when the model is right; far apart, systematic effects are at work.
    const ParamVector& p0 = start_p;
    const double zd = (p[kParamEd] - p0[kParamEd]) / std::sqrt(std::max(base.cov(0, 0), 1e-300));
    const double zb = (p[kParamEb] - p0[kParamEb]) / std::sqrt(std::max(base.cov(1, 1), 1e-300));
    if (std::max(std::abs(zd), std::abs(zb)) > 5.0)
      out.notes.push_back(fmt::format(
          "the refined calibration (E_d = {:.6f}, E_b = {:.6f}) and the baseline's best fit on the pieces (E_d = "
          "{:.6f}, E_b = {:.6f}) differ by {:.0f} and {:.0f} standard errors: the two weigh the runs differently, "
          "which matters only when the runs leave the model",
          p0[kParamEd], p0[kParamEb], p[kParamEd], p[kParamEb], zd, zb));
  }
  ctx.p_base = p;
  ctx.noise_base = noise;
  ctx.eps_base = base.eps;
  ctx.W_base = Whiteners(ctx.bases, c.pieces, noise);
  {
    // Jacobian at the final point for the null refits and cross-validation.
    ctx.D_base = model.Jacobian(p, base_params, ctx.eps_base);
  }
  const std::vector<Scores> scores_base = PieceScores(ctx.eps_base, ctx.bases, c.pieces, noise);
  const GapSummary gap_base = ComputeGap(c, scores_base, options.gap);

  BaselineSummary& bs = out.baseline;
  bs.E_d = p[kParamEd];
  bs.E_b = p[kParamEb];
  bs.k_L = std::sqrt(noise.kL2);
  bs.k_R = std::sqrt(noise.kR2);
  bs.sigma_xy_m = std::sqrt(noise.sxy2);
  bs.sigma_theta_rad = std::sqrt(noise.sth2);
  bs.ground_truth_estimated = !gt_known;
  bs.pieces = static_cast<int>(n);
  bs.runs = static_cast<int>(c.runs.size());
  // Return errors per experiment and direction: observed vs predicted.
  {
    std::vector<NoiseFitRun> fit_runs;
    std::map<std::pair<int, std::string>, std::vector<int>> groups;
    for (std::size_t r = 0; r < c.runs.size(); ++r) groups[{c.runs[r].experiment, c.runs[r].direction}].push_back(static_cast<int>(r));
    const WheelNoise wn{bs.k_L, bs.k_R};
    for (const auto& [key, runs] : groups) {
      ReturnPrediction rp;
      rp.experiment = key.first;
      rp.direction = key.second;
      std::vector<Eigen::Vector3d> obs;
      for (int ri : runs) {
        const DiagRun& r = c.runs[ri];
        std::size_t g0 = 0, g1 = 0;
        bool any = false;
        for (std::size_t i = 0; i < r.t.size(); ++i)
          if (r.has_gt[i]) {
            if (!any) g0 = i;
            any = true;
            g1 = i;
          }
        if (!any || g1 <= g0) continue;
        Pose2 odo;
        for (std::size_t i = g0; i < g1; ++i)
          odo = DiffDriveStep(odo, r.left[i + 1] - r.left[i], r.right[i + 1] - r.right[i], c.robot.wheelbase_m);
        const std::vector<Pose2> pred = model.PredictRun(ri, p);
        const Pose2 ro = RelativeTo(r.gt[g0], r.gt[g1]);
        const Pose2 rpd = RelativeTo(pred[g0], pred[g1]);
        const Eigen::Vector3d eo(ro.x - odo.x, ro.y - odo.y, r.endpoint && !r.has_heading ? 0.0 : WrapAngle(ro.theta - odo.theta));
        const Eigen::Vector3d ep(rpd.x - odo.x, rpd.y - odo.y, WrapAngle(rpd.theta - odo.theta));
        obs.push_back(eo);
        rp.predicted_mean += ep;
        // Predicted covariance: Kelly's propagation along the run's encoder
        // travel (error_models) plus the ground truth's noise at both ends.
        WheelTravel wt;
        wt.left_m.assign(r.left.begin() + static_cast<std::ptrdiff_t>(g0), r.left.begin() + static_cast<std::ptrdiff_t>(g1 + 1));
        wt.right_m.assign(r.right.begin() + static_cast<std::ptrdiff_t>(g0), r.right.begin() + static_cast<std::ptrdiff_t>(g1 + 1));
        const TrajectoryCovarianceSummary tc = TrajectoryCovariance(wt, c.robot.wheelbase_m * p[kParamEb]);
        NoiseFitRun fr;
        fr.group = fmt::format("exp{}:{}", r.experiment + 1, r.direction);
        fr.run = r.id;
        fr.error = eo;
        fr.has_theta = !r.endpoint || r.has_heading;
        fr.basis = tc.motion;
        fr.measurement = MeasurementCovariance(std::sqrt(noise.sxy2), std::sqrt(noise.sth2), ro);
        fit_runs.push_back(fr);
        Eigen::Matrix3d C = tc.motion.Evaluate(wn);
        C(0, 0) += 2.0 * noise.sxy2;
        C(1, 1) += 2.0 * noise.sxy2;
        C(2, 2) += 2.0 * noise.sth2;
        rp.predicted_cov += C;
      }
      rp.runs = static_cast<int>(obs.size());
      if (rp.runs == 0) continue;
      rp.predicted_mean /= rp.runs;
      rp.predicted_cov /= rp.runs;
      for (const auto& v : obs) rp.observed_mean += v;
      rp.observed_mean /= rp.runs;
      if (rp.runs > 1) {
        for (const auto& v : obs) rp.observed_cov += (v - rp.observed_mean) * (v - rp.observed_mean).transpose();
        rp.observed_cov /= rp.runs - 1;
      }
      bs.returns.push_back(rp);
    }
    try {
      const NoiseFitSummary nf = umbmark::FitNoise(fit_runs);
      bs.return_fit = true;
      bs.return_k_L = nf.k_L;
      bs.return_k_R = nf.k_R;
      bs.return_k_L_ci = nf.k_L_ci;
      bs.return_k_R_ci = nf.k_R_ci;
    } catch (const std::exception& e) {
      bs.return_fit_note = std::string("fit-noise on return errors not available: ") + e.what();
    }
    // Residual growth per segment type.
    for (PieceType t : {PieceType::kStraight, PieceType::kTurn, PieceType::kArc, PieceType::kStand, PieceType::kReturn}) {
      GrowthRow g;
      g.type = t;
      Eigen::Vector3d so = Eigen::Vector3d::Zero(), sp = Eigen::Vector3d::Zero();
      for (std::size_t j = 0; j < n; ++j) {
        if (c.pieces[j].type != t) continue;
        ++g.pieces;
        g.mean_travel_m += c.pieces[j].travel_m;
        const Eigen::Matrix3d C = PieceCovariance(ctx.bases[j], noise);
        for (int k = 0; k < 3; ++k) {
          so[k] += ctx.eps_base[3 * j + k] * ctx.eps_base[3 * j + k];
          sp[k] += C(k, k);
        }
      }
      if (g.pieces == 0) continue;
      g.mean_travel_m /= g.pieces;
      g.observed_rms = (so / g.pieces).cwiseSqrt();
      g.predicted_rms = (sp / g.pieces).cwiseSqrt();
      bs.growth.push_back(g);
    }
  }
  const auto t_baseline = Clock::now();

  // ---- 2. Where, and the gap's null distribution ---------------------------
  out.gap_score = gap_base.score;
  out.gap_by_kind = gap_base.by_kind;
  {
    std::vector<GapStatistic> sorted = gap_base.stats;
    std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return std::abs(a.z) > std::abs(b.z); });
    for (std::size_t i = 0; i < sorted.size() && static_cast<int>(i) < options.where_top; ++i) {
      const GapStatistic& s = sorted[i];
      WhereItem w;
      w.experiment = c.subsets[s.subset].experiment;
      w.subset = c.subsets[s.subset].name;
      if (s.kind == StatKind::kTrend) w.subset += " (early vs late runs)";
      w.statistic = s.kind;
      w.component = WhereComponent(s);
      w.z = s.z;
      w.n = s.n;
      out.where.push_back(w);
    }
  }
  {
    std::vector<NullPiece> np(n);
    const std::vector<Pose2> motion = model.PredictedPieceMotion(p);
    std::vector<std::vector<Pose2>> predicted(c.runs.size());
    for (std::size_t r = 0; r < c.runs.size(); ++r) predicted[r] = model.PredictRun(static_cast<int>(r), p);
    for (std::size_t j = 0; j < n; ++j) {
      const PieceBases& B = ctx.bases[j];
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
    Whiten(ctx.W_base, ctx.eps_base, ctx.D_base, rw, Jw);
    Eigen::MatrixXd A = Jw.transpose() * Jw;
    for (Eigen::Index k = 0; k < A.rows(); ++k) A(k, k) *= 1.0 + 1e-12;
    const Eigen::MatrixXd K = A.ldlt().solve(Jw.transpose());
    std::vector<double> null(static_cast<std::size_t>(options.null_simulations));
    RunParallel(options.threads, options.null_simulations,
                [&](int first, int count) { SimulateNull(ctx, np, K, first, count, null); });
    std::vector<double> sorted = null;
    std::sort(sorted.begin(), sorted.end());
    out.null_simulations = options.null_simulations;
    out.score_p_value = NullPValue(sorted, out.gap_score);
    out.p_value = out.score_p_value;
    out.null_median = sorted[sorted.size() / 2];
    out.null_quantile_alpha =
        sorted[std::min(sorted.size() - 1, static_cast<std::size_t>(std::floor((1.0 - options.alpha) * static_cast<double>(sorted.size()))))];
    ctx.null_median = out.null_median;
  }
  const auto t_null = Clock::now();

  // ---- 3. Which: candidate effects ----------------------------------------
  ctx.train.assign(static_cast<std::size_t>(c.folds), std::vector<char>(n, 0));
  ctx.test.assign(static_cast<std::size_t>(c.folds), std::vector<char>(n, 0));
  for (std::size_t j = 0; j < n; ++j)
    for (int f = 0; f < c.folds; ++f) {
      const bool held = c.pieces[j].fold == f;
      ctx.test[f][j] = held;
      ctx.train[f][j] = !held;
    }
  NoiseFitOptions fold_fit = ctx.noise_fit;
  fold_fit.line_search = false;
  fold_fit.max_iterations = 6;

  // Baseline, cross-validated.
  std::vector<Scores> cv_scores;
  double cv_ll_base = 0.0;
  CrossValidate(
      ctx, ctx.eps_base, ctx.D_base, ctx.W_base,
      [&](const std::vector<double>& e, const std::vector<char>& use) {
        return FitNoise(e, ctx.bases, c.pieces, use, ctx.noise_base, fold_fit);
      },
      cv_scores, cv_ll_base);
  const double gcv_base = ComputeGap(c, cv_scores, options.gap).score;
  const double gap_before = Gap(ctx, out.gap_score), gap_cv_before = Gap(ctx, gcv_base);

  const double ll_base = TotalLogLik(ctx, ctx.eps_base, ctx.noise_base);
  // Likelihood-ratio test of a fitted candidate against the baseline.
  auto lr_test = [&](Candidate& cd, double ll) {
    cd.tested = true;
    cd.loglik_gain = std::max(0.0, ll - ll_base);
    cd.lr_p_value = ChiSquareSurvival(2.0 * cd.loglik_gain, cd.parameters);
  };

  std::vector<sim::EffectKind> effects = options.effects.empty() ? sim::ContractEffects() : options.effects;
  // Whitened baseline columns, for identifiability.
  Eigen::VectorXd rw_b;
  Eigen::MatrixXd Jw_b;
  Whiten(ctx.W_base, ctx.eps_base, ctx.D_base, rw_b, Jw_b);
  const Eigen::MatrixXd Ab = Jw_b.transpose() * Jw_b;

  std::vector<Candidate> cands(effects.size());
  std::vector<Eigen::MatrixXd> projected(effects.size());  // effect columns orthogonal to the baseline's
  auto fit_one = [&](std::size_t ei) {
    const sim::EffectKind kind = effects[ei];
    Candidate& cd = cands[ei];
    cd.effect = kind;
    const std::vector<int> eparams = EffectParams(kind);
    if (!eparams.empty()) {
      cd.parameters = static_cast<int>(eparams.size());
      // Identifiability against E_d, E_b.
      const Eigen::MatrixXd De = model.Jacobian(p, eparams, ctx.eps_base);
      Eigen::VectorXd tmp;
      Eigen::MatrixXd Jw_e;
      Whiten(ctx.W_base, ctx.eps_base, De, tmp, Jw_e);
      const Eigen::MatrixXd proj = Jw_e - Jw_b * Ab.ldlt().solve(Jw_b.transpose() * Jw_e);
      projected[ei] = proj;
      // Distinguishable from E_d, E_b when the part of its footprint they
      // cannot absorb determines a typical-size effect to a third of its
      // size (standard error of the parameter with E_d, E_b free). Between
      // that and ten typical sizes it is weakly identifiable: fitted and
      // tested, named only on its own evidence (turn_scrub on squares and
      // straight runs: only the spot turns' small forward motion, (c_R -
      // c_L) b phi / 4 per turn, tells it from a wheelbase error, and only
      // when E_d is far from 1). Beyond that it is not identifiable: E_d,
      // E_b absorb it (the model would only be guessing).
      bool identifiable = true;
      int mimics = kParamEd;
      double weakest = std::numeric_limits<double>::infinity();  // typical size / se
      for (Eigen::Index k = 0; k < Jw_e.cols(); ++k) {
        const double raw = Jw_e.col(k).norm(), perp = proj.col(k).norm();
        const double se = perp > 0.0 ? 1.0 / perp : std::numeric_limits<double>::infinity();
        const double typical = TypicalMagnitude(eparams[static_cast<std::size_t>(k)]);
        weakest = std::min(weakest, typical / se);
        if (!(raw > 0.0) || !(se < 10.0 * typical)) identifiable = false;
        if (!(se < typical / 3.0)) {
          double best = -1.0;
          for (Eigen::Index b = 0; b < Jw_b.cols(); ++b) {
            const double nb = Jw_b.col(b).norm();
            const double cosv = raw > 0.0 && nb > 0.0 ? std::abs(Jw_b.col(b).dot(Jw_e.col(k))) / (raw * nb) : 0.0;
            if (cosv > best) {
              best = cosv;
              mimics = base_params[static_cast<std::size_t>(b)];
            }
          }
        }
      }
      if (!identifiable) {
        cd.identifiable = false;
        cd.note = !(Jw_e.norm() > 0.0) ? "not identifiable on these data: these experiments do not show it at all"
                                 : fmt::format("not identifiable on these data: indistinguishable from the baseline's {} "
                                               "(a {})",
                                               ParamName(mimics),
                                               mimics == kParamEb ? "wheelbase error" : "wheel-diameter ratio error");
        for (int k : eparams) cd.params[ContractParamName(k)] = 0.0;
        cd.E_d = p[kParamEd];
        cd.E_b = p[kParamEb];
        cd.gap_after = out.gap_score;
        cd.gap_by_kind = out.gap_by_kind;
        return;
      }
      if (weakest < 3.0) {
        cd.weak = true;
        cd.note = fmt::format(
            "weakly identifiable on these data: mostly absorbed by the baseline's {} (a {}); a typical-size effect "
            "stands only {:.1f} standard errors out",
            ParamName(mimics), mimics == kParamEb ? "wheelbase error" : "wheel-diameter ratio error", weakest);
      }
      std::vector<int> joint = base_params;
      joint.insert(joint.end(), eparams.begin(), eparams.end());
      MeanFit mf = FitMean(model, p, joint, ctx.W_base, 12);
      // turn_scrub also changes the noise's heading in spot turns relative
      // to straight motion: its covariance bases follow the fit.
      Context scrub_ctx;
      if (kind == sim::EffectKind::kTurnScrub) {
        scrub_ctx = ctx;
        scrub_ctx.bases = ComputeBases(c, model, mf.p);
      }
      const Context& cx = kind == sim::EffectKind::kTurnScrub ? scrub_ctx : ctx;
      NoiseParams ne = FitNoise(mf.eps, cx.bases, c.pieces, {}, ctx.noise_base, ctx.noise_fit);
      const std::vector<Eigen::Matrix3d> We = Whiteners(cx.bases, c.pieces, ne);
      // Parameter standard errors with the refitted noise.
      Eigen::VectorXd r2;
      Eigen::MatrixXd J2;
      Whiten(We, mf.eps, mf.D, r2, J2);
      const Eigen::MatrixXd cov = (J2.transpose() * J2).ldlt().solve(Eigen::MatrixXd::Identity(J2.cols(), J2.cols()));
      for (std::size_t k = 0; k < eparams.size(); ++k) {
        cd.params[ContractParamName(eparams[k])] = mf.p[eparams[k]];
        cd.param_se[ContractParamName(eparams[k])] =
            std::sqrt(std::max(0.0, cov(static_cast<Eigen::Index>(2 + k), static_cast<Eigen::Index>(2 + k))));
      }
      cd.E_d = mf.p[kParamEd];
      cd.E_b = mf.p[kParamEb];
      lr_test(cd, TotalLogLik(cx, mf.eps, ne));
      const GapSummary ga = ComputeGap(c, PieceScores(mf.eps, cx.bases, c.pieces, ne), options.gap);
      cd.gap_after = ga.score;
      cd.gap_by_kind = ga.by_kind;
      std::vector<Scores> cvs;
      double ll = 0.0;
      CrossValidate(
          cx, mf.eps, mf.D, We,
          [&](const std::vector<double>& e, const std::vector<char>& use) {
            return FitNoise(e, cx.bases, c.pieces, use, ne, fold_fit);
          },
          cvs, ll);
      cd.heldout_loglik_gain = ll - cv_ll_base;
      const double gcv = ComputeGap(c, cvs, options.gap).score;
      cd.heldout_shrink = Shrink(Gap(ctx, gcv), gap_cv_before);
    } else if (kind == sim::EffectKind::kCorrelatedNoise || kind == sim::EffectKind::kBumpOutliers) {
      const bool corr = kind == sim::EffectKind::kCorrelatedNoise;
      cd.parameters = corr ? 1 : 2;
      cd.E_d = p[kParamEd];
      cd.E_b = p[kParamEb];
      NoiseFitOptions cf = ctx.noise_fit;
      cf.correlated = true;
      NoiseFitOptions cf_fold = fold_fit;
      cf_fold.correlated = true;
      const NoiseParams ne = corr ? FitNoise(ctx.eps_base, ctx.bases, c.pieces, {}, ctx.noise_base, cf)
                                  : FitBumps(ctx.eps_base, ctx.bases, c.pieces, {}, ctx.noise_base);
      if (corr) {
        cd.params["rho"] = ne.rho();
        lr_test(cd, TotalLogLik(ctx, ctx.eps_base, ne));
      } else {
        cd.params["rate"] = ne.bump_rate;
        cd.params["sigma"] = std::sqrt(ne.bump_s2);
      }
      const GapSummary ga = ComputeGap(c, PieceScores(ctx.eps_base, ctx.bases, c.pieces, ne), options.gap);
      cd.gap_after = ga.score;
      cd.gap_by_kind = ga.by_kind;
      std::vector<Scores> cvs;
      double ll = 0.0;
      CrossValidate(
          ctx, ctx.eps_base, ctx.D_base, ctx.W_base,
          [&](const std::vector<double>& e, const std::vector<char>& use) {
            return corr ? FitNoise(e, ctx.bases, c.pieces, use, ne, cf_fold)
                        : FitBumps(e, ctx.bases, c.pieces, use, ne);
          },
          cvs, ll);
      cd.heldout_loglik_gain = ll - cv_ll_base;
      const double gcv = ComputeGap(c, cvs, options.gap).score;
      cd.heldout_shrink = Shrink(Gap(ctx, gcv), gap_cv_before);
    } else {
      cd.identifiable = false;
      cd.note = "not a contract effect; not fitted";
      return;
    }
    cd.shrink = Shrink(Gap(ctx, cd.gap_after), gap_before);
    cd.evidence = cd.heldout_loglik_gain - options.complexity_penalty_nats * cd.parameters;
  };
  {
    // Candidates are independent: spread them over the threads.
    std::vector<std::size_t> order(effects.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    const int threads = std::max(1, std::min<int>(options.threads, static_cast<int>(effects.size())));
    std::vector<std::thread> pool;
    std::atomic_size_t next{0};
    auto worker = [&]() {
      for (std::size_t i = next++; i < effects.size(); i = next++) fit_one(i);
    };
    for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
    worker();
    for (auto& th : pool) th.join();
  }
  const auto t_candidates = Clock::now();

  // ---- 4. Significance: G and the likelihood-ratio tests ------------------
  {
    double min_p = 1.0;
    out.tests = 0;
    for (const Candidate& cd : cands)
      if (cd.tested) {
        ++out.tests;
        min_p = std::min(min_p, cd.lr_p_value);
      }
    out.tests_p_value = std::min(1.0, out.tests * min_p);
    out.p_value = options.likelihood_tests && out.tests > 0
                      ? std::min(1.0, 2.0 * std::min(out.score_p_value, out.tests_p_value))
                      : out.score_p_value;
    out.significant = out.p_value < options.alpha;
  }
  // Level of each route: half of alpha each when both are combined.
  const double route_alpha = options.likelihood_tests && out.tests > 0 ? 0.5 * options.alpha : options.alpha;
  const bool found_by_tests = options.likelihood_tests && out.tests > 0 && out.tests_p_value < route_alpha;

  // ---- 5. Verdict -----------------------------------------------------------
  std::vector<std::size_t> rank(cands.size());
  for (std::size_t i = 0; i < rank.size(); ++i) rank[i] = i;
  // Best first: effects that close most of the held-out gap with positive
  // evidence, by evidence; then the others by evidence; unidentifiable last.
  // A winner must also leave no significant gap behind, unless it closes
  // nearly all of it (a tiny misfit of a huge effect still scores high).
  auto qualifies = [&](const Candidate& cd) {
    return cd.identifiable && cd.evidence > 0.0 && cd.heldout_shrink >= options.min_heldout_shrink &&
           (cd.gap_after <= out.null_quantile_alpha || cd.heldout_shrink >= options.full_shrink);
  };
  // Found by its own likelihood-ratio test (the gap G may be too diffuse to
  // see it): significant after Bonferroni, gains held out, and leaves no
  // significant G.
  auto found_alone = [&](const Candidate& cd) {
    return found_by_tests && cd.identifiable && cd.tested && out.tests * cd.lr_p_value < route_alpha &&
           cd.evidence > 0.0 && cd.gap_after <= out.null_quantile_alpha;
  };
  std::stable_sort(rank.begin(), rank.end(), [&](std::size_t a, std::size_t b) {
    if (cands[a].identifiable != cands[b].identifiable) return cands[a].identifiable;
    if (qualifies(cands[a]) != qualifies(cands[b])) return qualifies(cands[a]);
    return cands[a].evidence > cands[b].evidence;
  });
  if (out.significant && !rank.empty() && !qualifies(cands[rank.front()])) {
    // No candidate closes the gap G measures: the likelihood-ratio route.
    std::size_t best = rank.size();
    for (std::size_t k = 0; k < rank.size(); ++k)
      if (found_alone(cands[rank[k]]) && (best == rank.size() || cands[rank[k]].lr_p_value < cands[rank[best]].lr_p_value))
        best = k;
    if (best < rank.size()) std::rotate(rank.begin(), rank.begin() + static_cast<std::ptrdiff_t>(best),
                                        rank.begin() + static_cast<std::ptrdiff_t>(best) + 1);
  }
  for (std::size_t i : rank) out.candidates.push_back(cands[i]);
  const std::string p_text =
      options.likelihood_tests && out.tests > 0
          ? fmt::format("p = {:.3g}: gap score p = {:.3g}, likelihood-ratio tests p = {:.3g} (Bonferroni over {})",
                        out.p_value, out.score_p_value, out.tests_p_value, out.tests)
          : fmt::format("p = {:.3g}", out.p_value);
  if (!out.significant) {
    out.verdict = "none";
    out.verdict_reason = fmt::format("the gap is not significant ({} >= alpha = {})", p_text, options.alpha);
  } else {
    const Candidate* best = out.candidates.empty() || !out.candidates.front().identifiable ? nullptr : &out.candidates.front();
    if (best && qualifies(*best)) {
      out.verdict = sim::EffectToString(best->effect);
      out.verdict_reason = fmt::format(
          "{} closes {:.0f}% of the gap on held-out runs (held-out log-likelihood +{:.1f} nats over the baseline)",
          out.verdict, 100.0 * best->heldout_shrink, best->heldout_loglik_gain);
    } else if (best && found_alone(*best)) {
      out.verdict = sim::EffectToString(best->effect);
      out.verdict_reason = fmt::format(
          "{} is significant on its own likelihood-ratio test (+{:.1f} nats, p = {:.3g}, {} tests) and gains {:.1f} "
          "nats on held-out runs; the gap score alone (p = {:.3g}) spreads it over too many statistics to see it, "
          "and none remains with the effect (G = {:.1f} <= {:.1f})",
          out.verdict, best->loglik_gain, best->lr_p_value, out.tests, best->heldout_loglik_gain, out.score_p_value,
          best->gap_after, out.null_quantile_alpha);
    } else {
      out.verdict = "unexplained";
      out.verdict_reason =
          !best ? fmt::format("significant gap ({}) and no identifiable candidate", p_text)
          : best->heldout_shrink < options.min_heldout_shrink || best->evidence <= 0.0
              ? fmt::format("significant gap ({}); the best candidate, {}, closes only {:.0f}% of it on "
                            "held-out runs",
                            p_text, sim::EffectToString(best->effect), 100.0 * best->heldout_shrink)
              : fmt::format("significant gap ({}); the best candidate, {}, closes {:.0f}% of it on held-out "
                            "runs but leaves a significant gap (G = {:.1f} > {:.1f})",
                            p_text, sim::EffectToString(best->effect), 100.0 * best->heldout_shrink,
                            best->gap_after, out.null_quantile_alpha);
    }
  }
  // What the data cannot tell apart.
  for (const Candidate& cd : out.candidates)
    if (!cd.identifiable && cd.note.find("baseline") != std::string::npos)
      out.indistinguishable.push_back(fmt::format("{} cannot be told apart from the baseline with these experiments: {}",
                                                  sim::EffectToString(cd.effect),
                                                  cd.note.substr(cd.note.find("indistinguishable"))));
    else if (cd.weak && sim::EffectToString(cd.effect) != out.verdict)
      out.indistinguishable.push_back(
          fmt::format("{} can hardly be told apart from the baseline with these experiments: {}",
                      sim::EffectToString(cd.effect), cd.note.substr(cd.note.find("mostly"))));
  for (std::size_t a = 0; a < effects.size(); ++a)
    for (std::size_t b = a + 1; b < effects.size(); ++b) {
      if (!cands[a].identifiable || !cands[b].identifiable) continue;
      if (projected[a].size() == 0 || projected[b].size() == 0) continue;
      // Largest canonical correlation between the two effects' footprints
      // (after removing what E_d, E_b explain).
      const Eigen::HouseholderQR<Eigen::MatrixXd> qa(projected[a]), qb(projected[b]);
      const Eigen::MatrixXd Qa = qa.householderQ() * Eigen::MatrixXd::Identity(projected[a].rows(), projected[a].cols());
      const Eigen::MatrixXd Qb = qb.householderQ() * Eigen::MatrixXd::Identity(projected[b].rows(), projected[b].cols());
      const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Qa.transpose() * Qb);
      const double cc = svd.singularValues().size() > 0 ? svd.singularValues()[0] : 0.0;
      if (cc > 0.95)
        out.indistinguishable.push_back(fmt::format(
            "{} and {} leave nearly the same footprint on these data (canonical correlation {:.3f})",
            sim::EffectToString(effects[a]), sim::EffectToString(effects[b]), cc));
    }
  if (out.significant && !out.candidates.empty() && out.candidates.front().identifiable) {
    const Candidate& top = out.candidates.front();
    for (std::size_t i = 1; i < out.candidates.size(); ++i) {
      const Candidate& o = out.candidates[i];
      if (!o.identifiable || o.heldout_shrink < options.min_heldout_shrink) continue;
      if (top.evidence - o.evidence < 2.0)
        out.indistinguishable.push_back(fmt::format(
            "{} and {} explain the gap about equally well on held-out runs ({:.1f} vs {:.1f} nats)",
            sim::EffectToString(top.effect), sim::EffectToString(o.effect), top.evidence, o.evidence));
    }
  }
  const auto t_end = Clock::now();
  out.timings = {{"refined calibration (start)", Seconds(t_start, t_refine)},
                 {"baseline fit and predictions", Seconds(t_refine, t_baseline)},
                 {"gap null distribution", Seconds(t_baseline, t_null)},
                 {"candidate effects and cross-validation", Seconds(t_null, t_candidates)},
                 {"verdict", Seconds(t_candidates, t_end)},
                 {"total", Seconds(t_start, t_end)}};
  return out;
}

}  // namespace umbmark::diag
