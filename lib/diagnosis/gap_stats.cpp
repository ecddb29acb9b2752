// Piece scores and gap statistics (see gap_stats.hpp).
#include "diagnosis/gap_stats.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>
#include <Eigen/Dense>

#include "diagnosis/run_block.hpp"
#include "stats/distributions.hpp"

namespace umbmark::diag {

const char* StatKindToString(StatKind k) {
  switch (k) {
    case StatKind::kMean: return "mean";
    case StatKind::kVariance: return "variance";
    case StatKind::kCorrelation: return "correlation";
    case StatKind::kTail: return "tail";
    case StatKind::kTrend: return "trend";
  }
  return "?";
}

const char* ComponentName(int c) {
  static const char* names[3] = {"heading", "along-track", "lateral"};
  return c >= 0 && c < 3 ? names[c] : "?";
}

namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

/// Permutation (x, y, theta) -> (theta, x, y) of a covariance.
Eigen::Matrix3d Permute(const Eigen::Matrix3d& C) {
  static const int idx[3] = {2, 0, 1};
  Eigen::Matrix3d P;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) P(i, j) = C(idx[i], idx[j]);
  return P;
}

/// Standard normal quantile as a score: clamped to |z| <= 38 (p = 0 or 1,
/// or a tail below the smallest double, gives -38 or 38).
double ScoreQuantile(double p) {
  if (!(p > 0.0)) return -38.0;
  if (!(p < 1.0)) return 38.0;
  return std::clamp(NormalQuantile(p), -38.0, 38.0);
}

}  // namespace

std::vector<Scores> PieceScores(const std::vector<double>& eps, const std::vector<PieceBases>& bases,
                                const std::vector<Piece>& pieces, const NoiseParams& noise) {
  std::vector<Scores> out(pieces.size());
  const bool bumps = noise.bump_rate > 0.0 && noise.bump_s2 > 0.0;
  // run_time_offset: each piece given the earlier pieces of its run.
  const bool block = HasRunBlocks(noise);
  const std::vector<Innovation> innovations =
      block ? RunInnovations(eps, bases, pieces, noise) : std::vector<Innovation>{};
  for (std::size_t j = 0; j < pieces.size(); ++j) {
    const double* e = block ? innovations[j].v.data() : &eps[3 * j];
    const Eigen::Matrix3d C = block ? innovations[j].S : PieceCovariance(bases[j], noise);
    if (pieces[j].components == 2) {
      Eigen::LLT<Eigen::Matrix2d> llt(C.topLeftCorner<2, 2>());
      const Eigen::Vector2d w = llt.matrixL().solve(Eigen::Vector2d(e[0], e[1]));
      out[j] = {kNan, w[0], w[1]};
      continue;
    }
    const Eigen::Vector3d ep(e[2], e[0], e[1]);
    if (!bumps) {
      Eigen::LLT<Eigen::Matrix3d> llt(Permute(C));
      const Eigen::Vector3d w = llt.matrixL().solve(ep);
      out[j] = {w[0], w[1], w[2]};
      continue;
    }
    const BumpMixture m = PieceMixture(bases[j], noise);
    Eigen::Matrix3d mean = Eigen::Matrix3d::Zero();
    for (int k = 0; k < m.components; ++k) mean += m.weight[k] * m.cov[k];
    Eigen::LLT<Eigen::Matrix3d> llt(Permute(mean));
    const Eigen::Matrix3d Linv = llt.matrixL().solve(Eigen::Matrix3d::Identity());
    const Eigen::Vector3d w = Linv * ep;
    double sd[kMaxBumpsPerPiece + 1][3];
    for (int k = 0; k < m.components; ++k) {
      const Eigen::Matrix3d S = Linv * Permute(m.cov[k]) * Linv.transpose();
      for (int c = 0; c < 3; ++c) sd[k][c] = std::sqrt(std::max(S(c, c), 1e-300));
    }
    for (int c = 0; c < 3; ++c) {
      // Smaller tail for precision: z = -Phi^-1(P(W beyond |w|, same side)).
      double tail = 0.0;
      for (int k = 0; k < m.components; ++k) tail += m.weight[k] * NormalCdf(-std::abs(w[c]) / sd[k][c]);
      const double z = -ScoreQuantile(std::max(tail, 1e-300));
      out[j][c] = w[c] >= 0.0 ? z : -z;
    }
  }
  return out;
}

// Longer than 80 lines on purpose: one pass over the pieces fills every
// subset's accumulator (means, variances, tails, cross-products, run means),
// and the second turns the same accumulators into the standardized
// departures G sums; split, the two halves would hand the accumulators back
// and forth (106 lines, lambdas counted).
GapSummary ComputeGap(const CampaignData& campaign, const std::vector<Scores>& scores, const GapOptions& options,
                      const std::vector<char>* use) {
  const std::size_t S = campaign.subsets.size();
  struct Acc {
    int n[3] = {0, 0, 0};
    double sum[3] = {0, 0, 0}, sq[3] = {0, 0, 0};
    int tail[3] = {0, 0, 0};
    double prod[3] = {0, 0, 0};  // (0,1), (0,2), (1,2)
    int nprod[3] = {0, 0, 0};
    std::vector<std::array<double, 6>> per_run;  // sum[3], count[3] by run index in experiment
  };
  std::vector<Acc> acc(S);
  // Run indices as the runs carry them: a campaign without its faulty runs
  // (run_faults.hpp) keeps every other run's index, so there are gaps.
  std::vector<std::size_t> runs_in(campaign.experiments.size(), 0);
  std::size_t runs_all = 0;
  for (const DiagRun& r : campaign.runs) {
    auto& n = runs_in[static_cast<std::size_t>(r.experiment)];
    n = std::max(n, static_cast<std::size_t>(r.index_in_experiment) + 1);
    runs_all = std::max(runs_all, static_cast<std::size_t>(r.campaign_index) + 1);
  }
  for (std::size_t s = 0; s < S; ++s) {
    const int e = campaign.subsets[s].experiment;
    acc[s].per_run.assign(e >= 0 ? runs_in[static_cast<std::size_t>(e)] : runs_all, {0, 0, 0, 0, 0, 0});
  }
  static const int pa[3] = {0, 0, 1}, pb[3] = {1, 2, 2};
  for (std::size_t j = 0; j < campaign.pieces.size(); ++j) {
    if (use && !(*use)[j]) continue;
    const Piece& p = campaign.pieces[j];
    const Scores& z = scores[j];
    const DiagRun& run = campaign.runs[p.run];
    for (int member : {p.subset, p.pooled_subset, p.campaign_subset}) {
      if (member < 0) continue;
      Acc& a = acc[member];
      const int ri = campaign.subsets[member].experiment >= 0 ? run.index_in_experiment : run.campaign_index;
      for (int c = 0; c < 3; ++c) {
        if (std::isnan(z[c])) continue;
        a.n[c] += 1;
        a.sum[c] += z[c];
        a.sq[c] += z[c] * z[c];
        if (std::abs(z[c]) > options.tail_z) a.tail[c] += 1;
        a.per_run[ri][c] += z[c];
        a.per_run[ri][3 + c] += 1.0;
      }
      for (int k = 0; k < 3; ++k) {
        if (std::isnan(z[pa[k]]) || std::isnan(z[pb[k]])) continue;
        a.prod[k] += z[pa[k]] * z[pb[k]];
        a.nprod[k] += 1;
      }
    }
  }
  GapSummary g;
  const double p_tail = 2.0 * NormalCdf(-options.tail_z);
  auto add = [&](int subset, StatKind kind, int ca, int cb, double z, int n) {
    GapStatistic st;
    st.subset = subset;
    st.kind = kind;
    st.comp_a = ca;
    st.comp_b = cb;
    st.z = z;
    st.n = n;
    g.stats.push_back(st);
    const double excess = std::max(0.0, std::abs(z) - options.threshold_se);
    g.score += excess * excess;
    g.by_kind[static_cast<int>(kind)] += excess * excess;
  };
  for (std::size_t s = 0; s < S; ++s) {
    const Acc& a = acc[s];
    const int subset = static_cast<int>(s);
    for (int c = 0; c < 3; ++c) {
      const int n = a.n[c];
      if (n < options.min_pieces) continue;
      add(subset, StatKind::kMean, c, -1, a.sum[c] / std::sqrt(n), n);
      add(subset, StatKind::kVariance, c, -1, (a.sq[c] / n - 1.0) / std::sqrt(2.0 / n), n);
      const double tail = BinomialUpperTail(a.tail[c], n, p_tail);
      add(subset, StatKind::kTail, c, -1, tail < 0.5 ? -ScoreQuantile(tail) : 0.0, n);
      // Trend over runs: weighted least squares of the run means on the run index.
      double W = 0.0, Wi = 0.0, Wm = 0.0;
      int runs = 0;
      for (std::size_t r = 0; r < a.per_run.size(); ++r) {
        const double cnt = a.per_run[r][3 + c];
        if (cnt <= 0.0) continue;
        ++runs;
        W += cnt;
        Wi += cnt * static_cast<double>(r);
        Wm += a.per_run[r][c];
      }
      if (runs >= 3) {
        const double ibar = Wi / W, mbar = Wm / W;
        double sxx = 0.0, sxy = 0.0;
        for (std::size_t r = 0; r < a.per_run.size(); ++r) {
          const double cnt = a.per_run[r][3 + c];
          if (cnt <= 0.0) continue;
          const double di = static_cast<double>(r) - ibar;
          sxx += cnt * di * di;
          sxy += di * (a.per_run[r][c] - cnt * mbar);
        }
        // Run means have variance 1/cnt: slope SE = 1/sqrt(sxx).
        if (sxx > 0.0) add(subset, StatKind::kTrend, c, -1, sxy / std::sqrt(sxx), runs);
      }
    }
    for (int k = 0; k < 3; ++k) {
      if (a.nprod[k] < options.min_pieces) continue;
      add(subset, StatKind::kCorrelation, pa[k], pb[k], a.prod[k] / std::sqrt(a.nprod[k]), a.nprod[k]);
    }
  }
  return g;
}

}  // namespace umbmark::diag
