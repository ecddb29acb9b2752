// fit-noise validation: coverage and bias of the 95 % intervals of k_L, k_R
// over independently simulated campaigns of an uncalibrated robot (issue 13
// part 3). Each campaign: 60 runs (argument 6) of 10 m forward and back
// (Chong & Kleeman section 6.3, k_L = 0.0004, k_R = 0.00058 m^1/2,
// b = 0.371 m) simulated by the Monte Carlo engine (simulation/, 100
// partitions per leg; it shares no code with the fit's covariance), true
// E_d uniform in 1 +- argument 3, E_b in 1 +- argument 4, the reference
// measuring start and end with 0.5 mm / 0.1 deg noise. Campaign c uses
// simulation seed 5000 + c; E_d, E_b are drawn from mt19937_64(2024).
// Usage: fit_noise_coverage MODE CAMPAIGNS [ED_HALF [EB_HALF [ml|reml [RUNS]]]]
//   MODE: ignored (propagate along the odometry's path), estimated (joint
//   fit, fit-noise's default), given (the true factors, like --params).
// Prints one line: coverage (misses below / above), bias, seconds.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>
#include <chrono>

#include <fmt/format.h>

#include "core/angles.hpp"
#include "error_models/path_spec.hpp"
#include "error_models/wheel_noise_fit.hpp"
#include "error_models/wheel_noise_fit_data.hpp"
#include "simulation/monte_carlo_kernel.hpp"
#include "support/fit_noise_campaign.hpp"

using namespace umbmark;
namespace {
using testing::kB;
using testing::kTrueKL;
using testing::kTrueKR;
EndpointData Simulate(const std::vector<PathSegment>& spec, double E_d, double E_b, int n, std::uint64_t seed) {
  return testing::SimulateReturnErrors(spec, E_d, E_b, n, seed, "fb");
}
struct Tally {
  int cL = 0, cR = 0, n = 0, loL = 0, hiL = 0, loR = 0, hiR = 0;
  double sL = 0, sR = 0;
  void Add(const WheelNoiseFitSummary& s) {
    cL += s.k_L_ci[0] <= kTrueKL && kTrueKL <= s.k_L_ci[1];
    cR += s.k_R_ci[0] <= kTrueKR && kTrueKR <= s.k_R_ci[1];
    loL += kTrueKL < s.k_L_ci[0]; hiL += kTrueKL > s.k_L_ci[1];
    loR += kTrueKR < s.k_R_ci[0]; hiR += kTrueKR > s.k_R_ci[1];
    sL += s.k_L; sR += s.k_R; ++n;
  }
};
}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "estimated";
  if (mode != "ignored" && mode != "estimated" && mode != "given") {
    fmt::print(stderr, "usage: fit_noise_coverage ignored|estimated|given CAMPAIGNS [ED_HALF [EB_HALF [ml|reml [RUNS]]]]\n");
    return 2;
  }
  const int campaigns = argc > 2 ? std::atoi(argv[2]) : 200;
  const double edr = argc > 3 ? std::atof(argv[3]) : 0.01, ebr = argc > 4 ? std::atof(argv[4]) : 0.03;
  const bool reml = !(argc > 5 && std::string(argv[5]) == "ml");
  const int nruns = argc > 6 ? std::atoi(argv[6]) : 60;
  const auto path = BackAndForthPath(10.0);
  NoiseFitInputOptions in;
  in.sigma_xy_m = 0.0005;
  in.sigma_theta_rad = Deg2Rad(0.1);
  WheelNoiseFitOptions fo;
  fo.restricted = reml;
  Tally t;
  int failed = 0;
  std::mt19937_64 draw(2024);
  std::uniform_real_distribution<double> Ed(1 - edr, 1 + edr), Eb(1 - ebr, 1 + ebr);
  auto t0 = std::chrono::steady_clock::now();
  for (int c = 0; c < campaigns; ++c) {
    const double E_d = Ed(draw), E_b = Eb(draw);
    const EndpointData data = Simulate(path, E_d, E_b, nruns, 5000 + static_cast<std::uint64_t>(c));
    NoiseFitInputOptions known = in;
    if (mode == "given") known.systematic = {E_b, 2.0 / (E_d + 1.0), 2.0 * E_d / (E_d + 1.0)};
    if (mode == "estimated") {
      try {
      t.Add(FitWheelNoiseWithSystematics([&](const SystematicErrors& e) { NoiseFitInputOptions w = in; w.systematic = e; return NoiseRunsFromEndpoints(data, path, kB, "", w); }, fo, nullptr));
      } catch (const std::exception& e) {
        ++failed;
        fmt::print(stderr, "campaign {}: E_d {} E_b {}: {}\n", c, E_d, E_b, e.what());
      }
    } else {
      t.Add(FitWheelNoise(NoiseRunsFromEndpoints(data, path, kB, "", known), fo));
    }
  }
  const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  fmt::print("| {} | {} | {} | {:.3f} ({}/{}) | {:.3f} ({}/{}) | {:+.1f} % | {:+.1f} % | {} | {:.1f} |\n", mode,
             reml ? "REML" : "ML", t.n, double(t.cL) / t.n, t.loL, t.hiL, double(t.cR) / t.n, t.loR, t.hiR,
             100 * (t.sL / t.n / kTrueKL - 1), 100 * (t.sR / t.n / kTrueKR - 1), failed, sec);
}
