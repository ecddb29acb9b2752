// Simulated return errors for the fit-noise validation, shared by
// tests/test_fit_noise_systematic.cpp and bench/fit_noise_coverage.cpp: a
// robot with b = 0.371 m, 0.1 m wheels, k_L = 0.0004, k_R = 0.00058 m^1/2
// (Chong & Kleeman section 6.3) and true E_d, E_b drives `spec` n times in
// the Monte Carlo engine (100 partitions per leg; it shares no code with the
// fit's covariance); the reference measures start and end with 0.5 mm /
// 0.1 deg of noise.
#pragma once

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "core/angles.hpp"
#include "error_models/path_spec.hpp"
#include "error_models/wheel_noise_fit_data.hpp"
#include "simulation/monte_carlo_kernel.hpp"

namespace umbmark::testing {

constexpr double kB = 0.371;
constexpr double kTrueKL = 0.00040, kTrueKR = 0.00058;

/// n return errors of `spec` driven by a robot with E_d, E_b, as an endpoint file.
inline EndpointData SimulateReturnErrors(const std::vector<PathSegment>& spec, double E_d, double E_b, int n,
                                         std::uint64_t seed, const std::string& direction) {
  sim::SimulationModel m;
  m.nominal.wheelbase_m = kB;
  m.nominal.wheel_diameter_left_m = m.nominal.wheel_diameter_right_m = 0.1;
  m.noise = {kTrueKL, kTrueKR};
  m.truth.E_d = E_d;
  m.truth.E_b = E_b;
  const sim::SimPlan plan = sim::CompilePlan(m, ToWheelSegments(spec, kB), 100);
  std::vector<Pose2> truth(static_cast<std::size_t>(n));
  sim::SimulateFinalPoses(plan, seed, 0, n, truth.data());
  std::mt19937_64 rng(seed ^ 0x5eedull);
  std::normal_distribution<double> N01;
  const double sxy = 0.0005, sth = Deg2Rad(0.1);
  EndpointData d;
  d.path = "simulated.csv";
  for (int i = 0; i < n; ++i) {
    const Pose2 start{sxy * N01(rng), sxy * N01(rng), sth * N01(rng)};
    const Pose2& t = truth[static_cast<std::size_t>(i)];
    const Pose2 end{t.x + sxy * N01(rng), t.y + sxy * N01(rng), t.theta + sth * N01(rng)};
    const Pose2 rel = RelativeTo(start, end);
    ReturnError r;
    r.run = std::to_string(i + 1);
    r.direction = direction;
    r.ex_m = rel.x - plan.odometry_final.x;
    r.ey_m = rel.y - plan.odometry_final.y;
    r.etheta_rad = WrapAngle(rel.theta - plan.odometry_final.theta);
    d.runs.push_back(r);
  }
  return d;
}

}  // namespace umbmark::testing
