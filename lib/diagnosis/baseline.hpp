// Stage "baseline" of the diagnosis: the model the runs are compared with.
// E_d, E_b start from the refined calibration (calibration/refine.hpp,
// scale fixed) and are polished on the whitened piece residuals
// (mean_fit.hpp); k_L, k_R (and the ground truth's sigmas when the manifest
// does not state them) by maximum likelihood (piece_noise.hpp), alternating
// twice.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "diagnosis/mean_fit.hpp"
#include "diagnosis/model.hpp"
#include "diagnosis/piece_noise.hpp"
#include "diagnosis/pieces.hpp"

namespace umbmark::diag {

/// The baseline's free mean parameters: E_d, E_b.
const std::vector<int>& BaselineParams();

/// Where E_d, E_b start.
struct BaselineStart {
  ParamVector p{};
  bool refined = false;
  std::string description;  ///< "refined calibration (...)" or "nominal (...)"
  std::vector<std::string> notes;
};

/// The refined calibration of the campaign's runs (use_refine) or the
/// nominal robot (E_d = E_b = 1) when that is off or fails.
BaselineStart StartBaseline(const CampaignData& c, bool use_refine);

struct BaselineFitOptions {
  /// Alternations of mean fit and noise fit. Default 2.
  int rounds = 2;
  MeanFitOptions mean;
};

/// The fitted baseline and what every later stage needs of it.
struct BaselineFit {
  ParamVector p{};
  /// Mean parameters fitted in the baseline (BaselineParams(); none for a
  /// given model, baseline_given.hpp). Candidates are fitted jointly with these.
  std::vector<int> free = BaselineParams();
  /// The user's model (`diagnose --baseline`), not one fitted to the runs.
  bool given = false;
  NoiseParams noise;
  /// Noise-fit options of this campaign (ground-truth sigmas fitted when the
  /// manifest does not state them); later stages refit noise with these.
  PieceNoiseFitOptions noise_fit;
  bool ground_truth_known = false;
  std::vector<PieceBases> bases;
  std::vector<double> eps;            ///< piece residuals at p
  std::vector<Eigen::Matrix3d> W;     ///< whiteners at `noise`
  Eigen::MatrixXd D;                  ///< d eps / d free at p (no columns for a given model)
  Eigen::MatrixXd cov;                ///< covariance of the free parameters
  std::vector<std::string> notes;
};

BaselineFit FitBaseline(const CampaignData& c, const MeanModel& model, const BaselineStart& start,
                        const BaselineFitOptions& options);

}  // namespace umbmark::diag
