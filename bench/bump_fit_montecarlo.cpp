// Monte Carlo of bump_outliers' joint fit (diagnosis/piece_noise.hpp
// FitBumps; docs/diagnosis.md, "Bumps fitted jointly"): simulated campaigns
// (5 squares per direction, 10 back-and-forth runs; k_L = 1.5e-3,
// k_R = 2.5e-3 m^1/2) with bumps at 0.8 per metre of 6 mm (issue 28's
// injection), alone and with a 1 mm motion noise floor fitted jointly.
// Prints each seed's fit and the mean and sd over seeds.
// Usage: bump_fit_montecarlo [SEEDS=20] [FIRST_SEED=1]
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "diagnosis/baseline.hpp"
#include "diagnosis/model.hpp"
#include "diagnosis/piece_noise.hpp"
#include "diagnosis/pieces.hpp"
#include "simulation/campaign_sim.hpp"

using namespace umbmark;
using namespace umbmark::diag;

namespace {

struct Stat {
  double s = 0.0, s2 = 0.0;
  int n = 0;
  void Add(double v) {
    s += v;
    s2 += v * v;
    ++n;
  }
  double Mean() const { return n ? s / n : 0.0; }
  double Sd() const { return n > 1 ? std::sqrt(std::max(0.0, (s2 - s * s / n) / (n - 1))) : 0.0; }
};

CampaignData Simulate(std::uint64_t seed, double floor_sigma) {
  RobotParams r;
  r.wheelbase_m = 0.35;
  r.wheel_diameter_left_m = r.wheel_diameter_right_m = 0.1;
  r.ticks_per_rev = 8192;
  const Manifest man = sim::StandardCampaignManifest(r, 2.0, 2.0, GroundTruthNoise{3e-4, 1.5e-3});
  sim::CampaignSimOptions o;
  o.seed = seed;
  o.truth.E_d = 1.004;
  o.truth.E_b = 1.012;
  o.truth.k_L = 1.5e-3;
  o.truth.k_R = 2.5e-3;
  o.square_runs_per_direction = 5;
  o.back_and_forth_runs = 10;
  o.sample_rate_hz = 10.0;
  o.speed_m_s = 0.5;
  o.pause_s = 0.5;
  o.effects.bump_rate = 0.8;
  o.effects.bump_sigma = 0.006;
  o.effects.floor_sigma = floor_sigma;
  const sim::SimulatedCampaign sc = sim::SimulateCampaign(man, o);
  return BuildCampaign(sc.manifest, sc.data);
}

}  // namespace

int main(int argc, char** argv) {
  const int seeds = argc > 1 ? std::stoi(argv[1]) : 20;
  const int first = argc > 2 ? std::stoi(argv[2]) : 1;
  for (const double floor_sigma : {0.0, 1e-3}) {
    Stat rate, sigma, var, kL, kR, fl;
    int at_bound = 0;
    std::printf("bumps 0.8 per metre of 6 mm%s\n", floor_sigma > 0 ? ", motion floor 1 mm (fitted jointly)" : "");
    for (int i = 0; i < seeds; ++i) {
      const std::uint64_t seed = static_cast<std::uint64_t>(first + i + (floor_sigma > 0 ? 1000 : 0));
      const CampaignData c = Simulate(seed, floor_sigma);
      const MeanModel model(c);
      const BaselineFit b = FitBaseline(c, model, StartBaseline(c, true), BaselineFitOptions{});
      BumpFitOptions o;
      o.motion_floor = floor_sigma > 0;
      if (b.repeat.measured) {
        o.repeat_kL2 = b.repeat.k_L * b.repeat.k_L;
        o.repeat_kR2 = b.repeat.k_R * b.repeat.k_R;
      }
      const NoiseParams n = FitBumps(b.eps, b.bases, c.pieces, {}, b.noise, o);
      std::printf("  seed %4llu: rate %.3f /m  sigma %.2f mm  k_L %.3g  k_R %.3g  floor %.2f mm\n",
                  static_cast<unsigned long long>(seed), n.bump_rate, 1e3 * std::sqrt(n.bump_s2), std::sqrt(n.kL2),
                  std::sqrt(n.kR2), 1e3 * std::sqrt(n.floor_s2));
      rate.Add(n.bump_rate);
      sigma.Add(1e3 * std::sqrt(n.bump_s2));
      var.Add(n.bump_rate * n.bump_s2);
      kL.Add(std::sqrt(n.kL2));
      kR.Add(std::sqrt(n.kR2));
      fl.Add(1e3 * std::sqrt(n.floor_s2));
      at_bound += n.bump_rate >= 0.95 * kMaxBumpRatePerMetre;
    }
    std::printf("  mean (sd) over %d seeds: rate %.3f (%.3f) /m, sigma %.2f (%.2f) mm, rate sigma^2 %.3g (%.2g) "
                "[truth 2.88e-05], k_L %.3g (%.2g), k_R %.3g (%.2g), floor %.2f (%.2f) mm; at the rate bound %d\n",
                seeds, rate.Mean(), rate.Sd(), sigma.Mean(), sigma.Sd(), var.Mean(), var.Sd(), kL.Mean(), kL.Sd(),
                kR.Mean(), kR.Sd(), fl.Mean(), fl.Sd(), at_bound);
  }
  return 0;
}
