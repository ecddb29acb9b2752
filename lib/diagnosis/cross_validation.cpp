// Cross-validation over runs (see cross_validation.hpp).
#include "diagnosis/cross_validation.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Dense>

#include "diagnosis/mean_fit.hpp"
#include "diagnosis/run_block.hpp"

namespace umbmark::diag {

namespace {

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
    ll[idx[k]] = HasRunBlocks(n) ? 0.0 : PieceLogLik(&sub_e[3 * k], sub[k].components, sub_b[k], n);
  }
  // Folds hold whole runs, so run_time_offset's run blocks are complete:
  // the fold's block log-likelihood is booked on its first piece.
  if (HasRunBlocks(n) && !idx.empty()) ll[idx.front()] = BlockLogLik(sub_e, sub_b, sub, n);
}

}  // namespace

Folds MakeFolds(const CampaignData& c) {
  const std::size_t n = c.pieces.size();
  Folds folds;
  folds.train.assign(static_cast<std::size_t>(c.folds), std::vector<char>(n, 0));
  folds.test.assign(static_cast<std::size_t>(c.folds), std::vector<char>(n, 0));
  for (std::size_t j = 0; j < n; ++j)
    for (int f = 0; f < c.folds; ++f) {
      const bool held = c.pieces[j].fold == f;
      folds.test[f][j] = held;
      folds.train[f][j] = !held;
    }
  return folds;
}

CrossValidation CrossValidate(const CampaignData& c, const std::vector<PieceBases>& bases, const Folds& folds,
                              const std::vector<double>& eps, const Eigen::MatrixXd& D,
                              const std::vector<Eigen::Matrix3d>& W, const FoldNoiseFit& fit_noise) {
  const std::size_t n = c.pieces.size();
  CrossValidation out;
  out.scores.assign(n, Scores{});
  std::vector<double> ll(n, 0.0);
  Eigen::VectorXd rw;
  Eigen::MatrixXd Jw;
  Whiten(W, eps, D, rw, Jw);
  for (std::size_t f = 0; f < folds.train.size(); ++f) {
    std::vector<double> eps_f = eps;
    if (D.cols() > 0) {
      Eigen::MatrixXd A = Eigen::MatrixXd::Zero(D.cols(), D.cols());
      Eigen::VectorXd g = Eigen::VectorXd::Zero(D.cols());
      for (std::size_t j = 0; j < n; ++j) {
        if (!folds.train[f][j]) continue;
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
    const NoiseParams nf = fit_noise(eps_f, folds.train[f]);
    ScoresFor(eps_f, bases, c.pieces, nf, folds.test[f], out.scores, ll);
  }
  for (double v : ll) out.loglik += v;
  return out;
}

double TotalLogLik(const CampaignData& c, const std::vector<PieceBases>& bases, const std::vector<double>& eps,
                   const NoiseParams& n) {
  return BlockLogLik(eps, bases, c.pieces, n);
}

}  // namespace umbmark::diag
