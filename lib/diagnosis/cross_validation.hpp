// Stage "cross-validation" of the diagnosis: k-fold cross-validation over
// runs (each piece carries its run's fold, pieces.hpp). A fitted model
// (mean residuals eps with Jacobian D, whiteners W, a noise fit) is refitted
// on each fold's training pieces -- the mean linearly, the noise by the
// caller's `fit_noise` -- and scored on the fold's held-out pieces.
#pragma once

#include <functional>
#include <vector>

#include <Eigen/Core>

#include "diagnosis/gap_stats.hpp"
#include "diagnosis/piece_noise.hpp"
#include "diagnosis/pieces.hpp"

namespace umbmark::diag {

/// Per fold: the pieces used for fitting (train) and scoring (test).
struct Folds {
  std::vector<std::vector<char>> train, test;
};
Folds MakeFolds(const CampaignData& c);

/// Noise refit on the pieces with use[j], from residuals eps.
using FoldNoiseFit = std::function<NoiseParams(const std::vector<double>& eps, const std::vector<char>& use)>;

struct CrossValidation {
  std::vector<Scores> scores;  ///< every piece's held-out scores
  double loglik = 0.0;         ///< held-out log-likelihood, summed over pieces
};

CrossValidation CrossValidate(const CampaignData& c, const std::vector<PieceBases>& bases, const Folds& folds,
                              const std::vector<double>& eps, const Eigen::MatrixXd& D,
                              const std::vector<Eigen::Matrix3d>& W, const FoldNoiseFit& fit_noise);

/// Gaussian (or bump-mixture) log-likelihood of all pieces.
double TotalLogLik(const CampaignData& c, const std::vector<PieceBases>& bases, const std::vector<double>& eps,
                   const NoiseParams& n);

}  // namespace umbmark::diag
