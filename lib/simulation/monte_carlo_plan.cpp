// Compiles a commanded path into the per-segment numbers the Monte Carlo
// kernel executes; see monte_carlo_plan.hpp.
#include "simulation/monte_carlo_plan.hpp"

#include <cmath>

#include <Eigen/Cholesky>
#include <fmt/format.h>

#include "core/errors.hpp"
#include "kinematics/diff_drive.hpp"

namespace umbmark::sim {

std::string SimulationModel::Check() const {
  if (auto e = nominal.Check(); !e.empty()) return "nominal." + e;
  if (auto e = truth.Check(); !e.empty()) return e;
  if (auto e = noise.Check(); !e.empty()) return e;
  if (quantise_encoders && !nominal.ticks_per_rev) return "quantise_encoders needs nominal.ticks_per_rev";
  if (!initial_covariance.allFinite() || !initial_covariance.isApprox(initial_covariance.transpose(), 1e-12))
    return "initial_covariance must be finite and symmetric";
  if (initial_covariance.squaredNorm() > 0.0) {
    const Eigen::LDLT<PoseCovariance> ldlt(initial_covariance);
    if (ldlt.info() != Eigen::Success || (ldlt.vectorD().array() < -1e-15).any())
      return "initial_covariance must be positive semidefinite";
  }
  return {};
}

std::int64_t SimPlan::StepsPerRun() const {
  std::int64_t n = 0;
  for (const SimSegment& s : segments) n += s.partitions;
  return n;
}

SimPlan CompilePlan(const SimulationModel& model, const std::vector<WheelSegment>& commanded, int partitions) {
  if (auto e = model.Check(); !e.empty()) throw InvalidOptions(e);
  if (partitions < 1) throw InvalidOptions(fmt::format("partitions = {} must be >= 1", partitions));
  const RobotParams& nom = model.nominal;
  const double g_L = model.truth.WheelFactorLeft(), g_R = model.truth.WheelFactorRight();

  SimPlan plan;
  plan.nominal_wheelbase_m = nom.wheelbase_m;
  plan.true_wheelbase_m = model.truth.E_b * nom.wheelbase_m;
  plan.noise = model.noise;
  plan.initial_covariance = model.initial_covariance;
  plan.quantised = model.quantise_encoders;

  Pose2 odo{};
  if (!model.quantise_encoders) {
    for (const WheelSegment& c : commanded) {
      SimSegment s;
      s.partitions = partitions;
      s.left_m = g_L * c.left_m;
      s.right_m = g_R * c.right_m;
      s.odo_left_m = c.left_m;
      s.odo_right_m = c.right_m;
      plan.segments.push_back(s);
      odo = DiffDriveStep(odo, s.odo_left_m, s.odo_right_m, nom.wheelbase_m);
    }
    plan.odometry_final = odo;
    return plan;
  }

  // Quantised encoders: wheel positions in ticks (see the header).
  const double mpt_L = nom.MetresPerTickLeft(), mpt_R = nom.MetresPerTickRight();
  plan.true_metres_per_tick_left = g_L * mpt_L;
  plan.true_metres_per_tick_right = g_R * mpt_R;
  plan.nominal_metres_per_tick_left = mpt_L;
  plan.nominal_metres_per_tick_right = mpt_R;
  double cum_L = 0.0, cum_R = 0.0;           // cumulative nominal travel
  std::int64_t T_L = 0, T_R = 0;             // count targets
  double p_L = 0.0, p_R = 0.0;               // stop positions for start phase 0
  for (std::size_t k = 0; k < commanded.size(); ++k) {
    cum_L += commanded[k].left_m;
    cum_R += commanded[k].right_m;
    const auto target_L = static_cast<std::int64_t>(std::llround(cum_L / mpt_L));
    const auto target_R = static_cast<std::int64_t>(std::llround(cum_R / mpt_R));
    // The counts are kept here (target_*), so the backward stop is the limit T + 1.
    const double np_L = EncoderStopPosition(static_cast<double>(target_L), static_cast<double>(T_L), p_L);
    const double np_R = EncoderStopPosition(static_cast<double>(target_R), static_cast<double>(T_R), p_R);
    if (plan.phase_segment_left < 0 && target_L != T_L) plan.phase_segment_left = static_cast<int>(k);
    if (plan.phase_segment_right < 0 && target_R != T_R) plan.phase_segment_right = static_cast<int>(k);
    SimSegment s;
    s.partitions = partitions;
    s.left_m = (np_L - p_L) * plan.true_metres_per_tick_left;
    s.right_m = (np_R - p_R) * plan.true_metres_per_tick_right;
    s.odo_left_m = static_cast<double>(target_L - T_L) * mpt_L;
    s.odo_right_m = static_cast<double>(target_R - T_R) * mpt_R;
    s.ticks_left = target_L;
    s.ticks_right = target_R;
    s.stop_left_ticks = np_L;
    s.stop_right_ticks = np_R;
    plan.segments.push_back(s);
    odo = DiffDriveStep(odo, s.odo_left_m, s.odo_right_m, nom.wheelbase_m);
    T_L = target_L;
    T_R = target_R;
    p_L = np_L;
    p_R = np_R;
  }
  plan.odometry_final = odo;
  return plan;
}

}  // namespace umbmark::sim
