// The diagnosis' model of a campaign: the baseline (the seeds' model:
// systematic E_d, E_b; white wheel noise k_L, k_R; encoder quantisation;
// ground-truth noise) plus the contract's effects, evaluated on the
// recorded encoder travel of every run.
//
// Mean (MeanModel): the true path is replayed from the recorded nominal
// wheel travel exactly as the simulator defines the effects (campaign_run.hpp):
//   true travel  l = dL c_L (1 + s) [(1 + a) if dL < 0]
//                r = dR c_R (1 + s) (1 + r_drift i) [(1 + a) if dR < 0]
//   heading      (r - l) / (E_b b), times (1 - k) inside spot turns
//   castor kick  +-kappa at the first interval of every non-turn motion
//                that starts from standstill
//   swivel       kappa_s x the preceding spot turn's sign at the first
//                interval of a straight or arc motion after a turn
//   stop slide   at the end of a motion's last interval when a stop follows:
//                d v|v| along the heading (straight, arc; v the true speed
//                of the axle midpoint at the end) or a w|w| in heading
//                (spot turn; w the true rate); after an arc the heading
//                turns on by arc w/v times the distance coasted, and a
//                backward coast is (1 + back) times as long
//   predicted ground truth  the pose at t - tau, reported at (dx, dy)
// with c_L = 2/(E_d + 1), c_R = 2/(1/E_d + 1). A piece's residual is
//   eps = Rel(GT_a, GT_b) - Rel(P_a, P_b)        ([x, y, theta], start frame of the piece)
// (theta wrapped), whose mean is zero when the model is right.
//
// Covariance (PieceBases): under the baseline eps is zero-mean with
//   Cov(eps) = k_L^2 A_L + k_R^2 A_R + rho k_L k_R A_LR      (wheel noise, eq. 4 with correlation rho)
//            + sigma_xy^2 G_xy + sigma_theta^2 G_theta        (ground-truth noise at both ends)
//            + Q                                               (encoder quantisation at both ends)
// A_* by Kelly's recursion P <- F P F^T + G_u S G_u^T over the piece's
// encoder intervals (each an exact arc, G_u its Jacobian in the wheel
// travels; heading (r - l) / (E_b b), times (1 - k) in spot turns), G_xy = diag(2, 2, 0), G_theta = j j^T + e3 e3^T with
// j = (dy, -dx, -1) (heading noise at the start rotates the piece), each
// end's term times 1 / samples averaged there (Piece::a_weight, b_weight), and
// Q from a uniform +-half-tick error of each wheel's count at both ends
// (zero for a standstill, whose counts do not change).
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

#include "diagnosis/pieces.hpp"
#include "effects/effect.hpp"

namespace umbmark::diag {

/// Mean-model parameters: the baseline's and every mean effect's (the
/// values of effects::MeanTerm, in which the effects name theirs).
enum ParamIndex : int {
  kParamEd = effects::kTermEd,   ///< E_d
  kParamEb = effects::kTermEb,       ///< E_b
  kParamScale = effects::kTermScale,    ///< scale_error.s
  kParamScrub = effects::kTermScrub,    ///< turn_scrub.k
  kParamAsym = effects::kTermAsym,     ///< direction_asymmetry.a
  kParamKappa = effects::kTermKappa,    ///< castor_kick.kappa [rad]
  kParamDrift = effects::kTermDrift,    ///< parameter_drift.r [1/run]
  kParamDx = effects::kTermDx,       ///< gt_offset.dx [m]
  kParamDy = effects::kTermDy,       ///< gt_offset.dy [m]
  kParamTau = effects::kTermTau,      ///< time_offset.tau [s]
  kParamSwivel = effects::kTermSwivel,   ///< castor_swivel.kappa [rad]
  kParamSlideD = effects::kTermSlideD,   ///< stop_slide.d [s^2/m]
  kParamSlideA = effects::kTermSlideA,   ///< stop_slide.a [s^2/rad]
  /// stop_slide's shape beyond the contract's d, a (what a physics engine
  /// shows; 0 is the contract's slide): how far the heading turns on after
  /// an arc (arc w/v times the distance coasted; 1: along the arc, 2: at
  /// the arc's rate through the coast, as two locked wheels sliding forward
  /// do), and a backward coast's extra length (d
  /// (1 + back) v^2 backwards: braking shifts load off the driven wheels
  /// onto a castor).
  kParamSlideArc = effects::kTermSlideArc,
  kParamSlideBack = effects::kTermSlideBack,
  /// The values of the effects that predict through the interface
  /// (effects::Effect::PredictsMean: an effect added at run time), in
  /// catalogue order, each taking as many slots as it has parameters
  /// (RunTimeParams); an effect that finds no slots left is not fitted.
  kParamRunTime0 = effects::kNumMeanTerms,
  kNumParams = kParamRunTime0 + 6
};
using ParamVector = std::array<double, kNumParams>;

/// E_d = E_b = 1, every effect zero.
ParamVector NominalParams();
/// A mean parameter's name: the contract's parameter name of its effect
/// (the baseline's E_d, E_b); "?" for an index out of range or a run-time
/// slot no effect takes.
const char* ParamName(int index);

/// An effect that predicts through the interface and its slots
/// [first, first + count) in ParamVector.
struct RunTimeSlots {
  const effects::Effect* effect = nullptr;
  int first = 0, count = 0;
};
/// The effects that predict through the interface (Effect::PredictsMean)
/// and their slots, in catalogue order (those that fit in the slots).
std::vector<RunTimeSlots> RunTimeEffects();
/// The mean-model slots of `effect` (empty when it does not predict
/// through the interface or finds no slots left).
std::vector<int> RunTimeParams(const effects::Effect& effect);

/// Residuals of every piece, flattened: eps[3 j + c] (c: x, y, theta).
class MeanModel {
 public:
  explicit MeanModel(const CampaignData& campaign);

  /// Residuals for `p` (size 3 * pieces).
  void Residuals(const ParamVector& p, std::vector<double>& eps) const;

  /// Residuals for `p` with time_offset.tau set to each of `taus` in turn
  /// (eps[k] for taus[k], each as Residuals gives them): the runs are
  /// replayed once, since tau moves only the samples the ground truth is
  /// read at (a scan of the clock, FitMean).
  void ResidualsAtClocks(const ParamVector& p, const std::vector<double>& taus,
                         std::vector<std::vector<double>>& eps) const;

  /// d eps / d p_k for k in `params` (forward differences), as a
  /// (3 * pieces) x params.size() matrix, at `p` whose residuals are `eps0`.
  Eigen::MatrixXd Jacobian(const ParamVector& p, const std::vector<int>& params, const std::vector<double>& eps0) const;

  /// Predicted relative motion of every piece (Rel(P_a, P_b)) for `p`.
  std::vector<Pose2> PredictedPieceMotion(const ParamVector& p) const;

  /// Predicted ground-truth pose at every sample of run `run` (start at
  /// the true start pose (0, 0, 0)), for reports.
  std::vector<Pose2> PredictRun(int run, const ParamVector& p) const;

  /// Observed relative motion Rel(GT_a, GT_b) of every piece.
  const std::vector<Pose2>& ObservedPieceMotion() const { return observed_; }

  const CampaignData& campaign() const { return campaign_; }

 private:
  void ReplayRun(int run, const ParamVector& p, std::vector<Pose2>& poses) const;
  Pose2 PoseAt(int run, const ParamVector& p, const std::vector<Pose2>& poses, double t) const;
  /// The left and right wheel factors of run `run` at `p`: parameter_drift
  /// on the right wheel, times each run-time effect's PredictWheels.
  void RunWheels(int run, const ParamVector& p, double& left, double& right) const;

  const CampaignData& campaign_;
  std::vector<RunTimeSlots> run_time_;
  std::vector<Pose2> observed_;
  std::vector<std::vector<int>> pieces_of_run_;
};

/// Covariance bases of one piece (see file comment).
struct PieceBases {
  Eigen::Matrix3d A_L = Eigen::Matrix3d::Zero(), A_R = Eigen::Matrix3d::Zero(), A_LR = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d G_xy = Eigen::Matrix3d::Zero(), G_theta = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d Q = Eigen::Matrix3d::Zero();
  /// Effect on the piece's end pose (start frame) of one metre of extra
  /// recorded travel of each wheel at the piece's start / end sample (the
  /// quantisation error's lever arms; Q sums their squares x tick^2 / 12).
  Eigen::Matrix<double, 3, 2> quant_start = Eigen::Matrix<double, 3, 2>::Zero();
  Eigen::Matrix<double, 3, 2> quant_end = Eigen::Matrix<double, 3, 2>::Zero();
  double travel_left_m = 0.0, travel_right_m = 0.0;  ///< sum of |wheel travel| (bumps)
  /// motion_noise_floor: sigma^2 F is the covariance of a motion's start /
  /// stop slip (half the variance at each end) on this piece.
  Eigen::Matrix3d F = Eigen::Matrix3d::Zero();
  /// standstill_motion: sigma_xy^2 S_xy + sigma_theta^2 S_theta when the
  /// piece ends where the robot settles (isotropic in position, any frame).
  Eigen::Matrix3d S_xy = Eigen::Matrix3d::Zero(), S_theta = Eigen::Matrix3d::Zero();
  /// run_time_offset: tau_sd^2 T, T = (J+ J+^T + J- J-^T) / 2 with J+-
  /// = d eps / d tau on either side (tau_lever_pos, tau_lever_neg): each
  /// piece's second moment. The pieces of a run share tau_i: their
  /// correlation is the run block of run_block.hpp.
  Eigen::Matrix3d T = Eigen::Matrix3d::Zero();
  /// castor_swivel after a reversal: swivel_rev2 K, K = v v^T with v =
  /// (-y, x, 1) the lever of a heading kick at the piece's start on its
  /// end pose (x, y: the predicted motion), on a piece in which a straight
  /// or arc motion starts that reverses the one before (DiagRun::reversal).
  Eigen::Matrix3d K = Eigen::Matrix3d::Zero();
  /// A heading kick of random size at a run's first start
  /// (effects::NoiseTerm::kFirstStart): first_start2 P, P = v v^T with v as
  /// for K, on the piece in which the run's first motion (a straight or arc
  /// one) starts (DiagRun::first_start).
  Eigen::Matrix3d P = Eigen::Matrix3d::Zero();
  /// The position slip there: first_start_xy2 P_xy, P_xy = R R^T with R the
  /// rotation from the robot's frame at the start to the piece's start frame
  /// (the identity: isotropic along both axes).
  Eigen::Matrix3d P_xy = Eigen::Matrix3d::Zero();
  /// The scatter of a heading kick where a straight or arc motion starts
  /// after a spot turn (effects::NoiseTerm::kFirstStart): turn_start2 P_turn,
  /// P_turn = v v^T as for K, on the piece holding such a start.
  Eigen::Matrix3d P_turn = Eigen::Matrix3d::Zero();
  Eigen::Vector3d tau_lever_pos = Eigen::Vector3d::Zero(), tau_lever_neg = Eigen::Vector3d::Zero();
};

/// Bases of every piece, along the path predicted for `p` (the shape of a
/// piece barely depends on the parameters; the baseline fit is used).
std::vector<PieceBases> ComputeBases(const CampaignData& campaign, const MeanModel& model, const ParamVector& p);

/// Re-takes run_time_offset's levers (T, tau_lever_pos, tau_lever_neg) of
/// every piece as secants over +-`step` seconds (at least 1 ms) at `p`.
/// ComputeBases uses one ground-truth sample interval; the fit of tau_sd
/// re-takes them at its own scale (run_block.hpp).
void SetTimeOffsetLevers(const MeanModel& model, const ParamVector& p, double step, std::vector<PieceBases>& bases);

}  // namespace umbmark::diag
