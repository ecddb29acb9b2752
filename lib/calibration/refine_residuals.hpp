// Residuals of the refined calibration (calibrate --refine), as templated
// functors for ceres::AutoDiffCostFunction over theta = [E_b, E_d, E_s]
// (refine_params.hpp). This header pulls in Ceres' autodiff and with it glog,
// whose CHECK macro clashes with Catch's: a test including it must include it
// before catch.hpp and #undef CHECK.
#pragma once

#include <cmath>
#include <cstddef>
#include <memory>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <ceres/autodiff_cost_function.h>

#include "calibration/refine_params.hpp"
#include "core/angles.hpp"
#include "kinematics/diff_drive.hpp"
#include "core/pose2.hpp"
#include "model/commanded_square.hpp"

namespace umbmark {

/// Endpoint residual of one square run:
///   r = sqrt_information * (e_measured - e_model(theta))
/// e_model = exact return error of the commanded square (commanded_square.hpp)
/// on the run's own recorded robot, whose true factors are the reference's
/// times ref/recorded (so sets recorded with different parameters share one
/// true robot). e = [ex_m, ey_m] or [ex_m, ey_m, etheta_rad]; the measured
/// heading error is taken on the 2 pi branch nearest the model's.
class SquareReturnErrorResidual {
 public:
  /// to_set = {b_ref/b_rec, D_L,ref/D_L,rec, D_R,ref/D_R,rec} of the run's set.
  SquareReturnErrorResidual(std::vector<CommandedMotion> motions, double recorded_wheelbase_m,
                            Eigen::Vector3d to_set, Eigen::VectorXd measured, Eigen::MatrixXd sqrt_information)
      : motions_(std::move(motions)),
        recorded_wheelbase_m_(recorded_wheelbase_m),
        odometry_final_(OdometryOfCommanded(motions_, recorded_wheelbase_m)),
        to_set_(std::move(to_set)),
        measured_(std::move(measured)),
        sqrt_information_(std::move(sqrt_information)) {}

  int num_residuals() const { return static_cast<int>(measured_.size()); }

  template <typename T>
  bool operator()(const T* theta, T* residuals) const {
    T c_L, c_R;
    WheelFactors(theta, &c_L, &c_R);
    const Pose2T<T> e = PredictReturnError(motions_, recorded_wheelbase_m_, odometry_final_,
                                           theta[kIndexEb] * T(to_set_[0]), c_L * T(to_set_[1]),
                                           c_R * T(to_set_[2]));
    T diff[3] = {T(measured_[0]) - e.x, T(measured_[1]) - e.y, T(0.0)};
    const int n = num_residuals();
    if (n == 3) {
      T d = T(measured_[2]) - e.theta;
      d -= T(2.0 * kPi * std::round(ScalarPart(d) / (2.0 * kPi)));
      diff[2] = d;
    }
    for (int i = 0; i < n; ++i) {
      residuals[i] = T(0.0);
      for (int j = 0; j < n; ++j) residuals[i] += T(sqrt_information_(i, j)) * diff[j];
    }
    return true;
  }

  static ceres::CostFunction* Create(std::vector<CommandedMotion> motions, double recorded_wheelbase_m,
                                     Eigen::Vector3d to_set, Eigen::VectorXd measured,
                                     Eigen::MatrixXd sqrt_information) {
    auto* functor = new SquareReturnErrorResidual(std::move(motions), recorded_wheelbase_m, std::move(to_set),
                                                  std::move(measured), std::move(sqrt_information));
    return new ceres::AutoDiffCostFunction<SquareReturnErrorResidual, ceres::DYNAMIC, kNumRefineParameters>(
        functor, functor->num_residuals());
  }

 private:
  const std::vector<CommandedMotion> motions_;
  const double recorded_wheelbase_m_;
  const Pose2 odometry_final_;
  const Eigen::Vector3d to_set_;
  const Eigen::VectorXd measured_;
  const Eigen::MatrixXd sqrt_information_;
};

/// Trajectory residual of one run: the odometry from the encoder samples
/// under theta, integrated from (0, 0, 0) at the first sample, against the
/// ground truth in the run's start frame, at the sampled indices:
///   r_k = f(s_k) * [x_odo - x_gt, y_odo - y_gt, h (theta_odo - theta_gt)]
/// with h = heading_length_m (metres per radian, so a heading error counts
/// like the position error it causes over h metres) and f the per-sample
/// robust factor (RobustFactor). One block per run: the run is integrated
/// once per evaluation, O(samples).
class TrajectoryRunResidual {
 public:
  struct Sample {
    std::size_t index = 0;  ///< sample index in the run (>= 1), strictly increasing
    Pose2 ground_truth;     ///< start frame, continuous heading
  };

  /// d_left_m[i], d_right_m[i]: wheel travel from sample i to i + 1 under the
  /// reference robot (true travel = c * these).
  TrajectoryRunResidual(std::vector<double> d_left_m, std::vector<double> d_right_m, double reference_wheelbase_m,
                        std::vector<Sample> samples, double heading_length_m, RobustLoss loss, double loss_scale_m,
                        Integrator integrator, bool fit_start = false)
      : d_left_m_(std::move(d_left_m)),
        d_right_m_(std::move(d_right_m)),
        reference_wheelbase_m_(reference_wheelbase_m),
        samples_(std::move(samples)),
        heading_length_m_(heading_length_m),
        loss_(loss),
        loss_scale_m_(loss_scale_m),
        integrator_(integrator),
        fit_start_(fit_start) {}

  int num_residuals() const { return static_cast<int>(3 * samples_.size()); }

  template <typename T>
  bool operator()(const T* theta, T* residuals) const {
    return Residuals(theta, static_cast<const T*>(nullptr), residuals);
  }

  /// The residuals with the ground truth seen through a session frame error
  /// `frame` = [yaw a (rad), origin o_x, o_y (m)] (nullptr: none): a rigid
  /// body whose pose is the axle pose composed with T = (o, a), expressed in
  /// its first pose, reports T^-1 P T for the true relative pose P. So the
  /// axle's relative position is R(a) g - (R(theta_g) - I) o, the heading
  /// unchanged (StartPose::kSessionFrame).
  template <typename T>
  bool Residuals(const T* theta, const T* frame, T* residuals) const {
    using std::cos;
    using std::sin;
    T c_L, c_R;
    WheelFactors(theta, &c_L, &c_R);
    const T wheelbase = theta[kIndexEb] * T(reference_wheelbase_m_);
    std::vector<Pose2T<T>> odo(samples_.size());
    Pose2T<T> pose{T(0.0), T(0.0), T(0.0)};
    std::size_t at = 0;  // pose is the odometry at sample `at`
    for (std::size_t k = 0; k < samples_.size(); ++k) {
      for (; at < samples_[k].index; ++at) {
        pose = DiffDriveStep(pose, c_L * d_left_m_[at], c_R * d_right_m_[at], wheelbase, integrator_);
      }
      odo[k] = pose;
    }
    if (fit_start_) AlignStart(&odo);
    for (std::size_t k = 0; k < samples_.size(); ++k) {
      const Pose2& gt = samples_[k].ground_truth;
      T gx(gt.x), gy(gt.y);
      if (frame != nullptr) {
        const T ca = cos(frame[0]), sa = sin(frame[0]);
        const double ct = std::cos(gt.theta) - 1.0, st = std::sin(gt.theta);
        gx = ca * T(gt.x) - sa * T(gt.y) - (T(ct) * frame[1] - T(st) * frame[2]);
        gy = sa * T(gt.x) + ca * T(gt.y) - (T(st) * frame[1] + T(ct) * frame[2]);
      }
      T r[3] = {odo[k].x - gx, odo[k].y - gy, T(heading_length_m_) * (odo[k].theta - T(gt.theta))};
      const T f = RobustFactor(r[0] * r[0] + r[1] * r[1] + r[2] * r[2], loss_, loss_scale_m_);
      for (int i = 0; i < 3; ++i) residuals[3 * k + static_cast<std::size_t>(i)] = f * r[i];
    }
    return true;
  }

  /// The residual with a session frame block [a, o_x, o_y] (see Residuals).
  struct Framed {
    std::shared_ptr<const TrajectoryRunResidual> run;
    template <typename T>
    bool operator()(const T* theta, const T* frame, T* residuals) const {
      return run->Residuals(theta, frame, residuals);
    }
  };
  static ceres::CostFunction* CreateFramed(std::shared_ptr<const TrajectoryRunResidual> run) {
    const int n = run->num_residuals();
    return new ceres::AutoDiffCostFunction<Framed, ceres::DYNAMIC, kNumRefineParameters, 3>(new Framed{std::move(run)},
                                                                                           n);
  }

  /// The same run with its ground truth seen through the fixed frame error
  /// `frame` (a plain TrajectoryRunResidual on the corrected samples).
  std::vector<Sample> CorrectedSamples(const double frame[3]) const {
    std::vector<Sample> out = samples_;
    const double ca = std::cos(frame[0]), sa = std::sin(frame[0]);
    for (auto& s : out) {
      const Pose2 g = s.ground_truth;
      const double ct = std::cos(g.theta) - 1.0, st = std::sin(g.theta);
      s.ground_truth.x = ca * g.x - sa * g.y - (ct * frame[1] - st * frame[2]);
      s.ground_truth.y = sa * g.x + ca * g.y - (st * frame[1] + ct * frame[2]);
    }
    return out;
  }

  static ceres::CostFunction* Create(std::vector<double> d_left_m, std::vector<double> d_right_m,
                                     double reference_wheelbase_m, std::vector<Sample> samples,
                                     double heading_length_m, RobustLoss loss, double loss_scale_m,
                                     Integrator integrator, bool fit_start = false) {
    auto* functor = new TrajectoryRunResidual(std::move(d_left_m), std::move(d_right_m), reference_wheelbase_m,
                                              std::move(samples), heading_length_m, loss, loss_scale_m, integrator,
                                              fit_start);
    return new ceres::AutoDiffCostFunction<TrajectoryRunResidual, ceres::DYNAMIC, kNumRefineParameters>(
        functor, functor->num_residuals());
  }

 private:
  /// Start pose profiled out (StartPose::kFitted): applies to the odometry
  /// poses the rigid transform (phi, t) minimising sum |R(phi) o_k + t - g_k|^2
  /// over the sampled positions (2-D Procrustes: phi = atan2(sum o' x g',
  /// sum o' . g') on the centred points, t = mean g - R mean o).
  template <typename T>
  void AlignStart(std::vector<Pose2T<T>>* odo) const {
    using std::atan2;
    using std::cos;
    using std::sin;
    const std::size_t n = samples_.size();
    if (n < 2) return;
    T mox(0.0), moy(0.0);
    double mgx = 0.0, mgy = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      mox += (*odo)[k].x;
      moy += (*odo)[k].y;
      mgx += samples_[k].ground_truth.x;
      mgy += samples_[k].ground_truth.y;
    }
    const T inv_n(1.0 / static_cast<double>(n));
    mox *= inv_n;
    moy *= inv_n;
    mgx /= static_cast<double>(n);
    mgy /= static_cast<double>(n);
    T cross(0.0), dot(0.0);
    for (std::size_t k = 0; k < n; ++k) {
      const T ox = (*odo)[k].x - mox, oy = (*odo)[k].y - moy;
      const double gx = samples_[k].ground_truth.x - mgx, gy = samples_[k].ground_truth.y - mgy;
      cross += ox * T(gy) - oy * T(gx);
      dot += ox * T(gx) + oy * T(gy);
    }
    const T phi = atan2(cross, dot);
    const T c = cos(phi), s = sin(phi);
    const T tx = T(mgx) - (c * mox - s * moy), ty = T(mgy) - (s * mox + c * moy);
    for (auto& p : *odo) {
      const T x = c * p.x - s * p.y + tx, y = s * p.x + c * p.y + ty;
      p.x = x;
      p.y = y;
      p.theta += phi;
    }
  }

  const std::vector<double> d_left_m_, d_right_m_;
  const double reference_wheelbase_m_;
  const std::vector<Sample> samples_;
  const double heading_length_m_;
  const RobustLoss loss_;
  const double loss_scale_m_;
  const Integrator integrator_;
  const bool fit_start_;
};

}  // namespace umbmark
