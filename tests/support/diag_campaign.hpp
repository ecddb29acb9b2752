// A small simulated campaign for the diagnosis' tests: cw and ccw squares
// of 2 m and back-and-forth runs of 2 m with ground truth at 10 Hz
// (0.5 m/s, 0.5 s pauses), robot 0.35 m wheelbase, 0.1 m wheels, 8192
// ticks per revolution, truth E_d 1.004, E_b 1.012, k_L 1.5e-3,
// k_R 2.5e-3 m^1/2, ground-truth noise 0.3 mm / 1.5 mrad. The caller adds
// effects to `sim.effects`.
#pragma once

#include <cstdint>

#include "diagnosis/diagnose.hpp"
#include "diagnosis/pieces.hpp"
#include "simulation/campaign_sim.hpp"

namespace umbmark::testing {

struct SmallCampaign {
  Manifest manifest;
  sim::CampaignSimOptions sim;
};

inline SmallCampaign MakeSmallCampaign(std::uint64_t seed, int square_runs = 5, int back_and_forth_runs = 10) {
  RobotParams r;
  r.wheelbase_m = 0.35;
  r.wheel_diameter_left_m = r.wheel_diameter_right_m = 0.1;
  r.ticks_per_rev = 8192;
  SmallCampaign s;
  s.manifest = sim::StandardCampaignManifest(r, 2.0, 2.0, GroundTruthNoise{3e-4, 1.5e-3});
  s.sim.seed = seed;
  s.sim.truth.E_d = 1.004;
  s.sim.truth.E_b = 1.012;
  s.sim.truth.k_L = 1.5e-3;
  s.sim.truth.k_R = 2.5e-3;
  s.sim.square_runs_per_direction = square_runs;
  s.sim.back_and_forth_runs = back_and_forth_runs;
  s.sim.sample_rate_hz = 10.0;
  s.sim.speed_m_s = 0.5;
  s.sim.pause_s = 0.5;
  return s;
}

/// Appends a free experiment (the simulator's arcs or figure-eights) read
/// from `file` to a manifest.
inline void AddFreeExperiment(Manifest& m, const char* file) {
  Experiment e;
  e.kind = ExperimentKind::kFree;
  e.file = e.resolved_file = file;
  m.experiments.push_back(e);
}

/// Simulates the campaign and builds the diagnosis' view of it.
inline diag::CampaignData BuildSmallCampaign(const SmallCampaign& s) {
  const sim::SimulatedCampaign c = sim::SimulateCampaign(s.manifest, s.sim);
  return diag::BuildCampaign(c.manifest, c.data);
}

/// Diagnoses the campaign with 100 null simulations, seed 1, 2 threads.
inline diag::DiagnoseSummary DiagnoseSmallCampaign(const SmallCampaign& s) {
  diag::DiagnoseOptions o;
  o.null_simulations = 100;
  o.seed = 1;
  o.threads = 2;
  return diag::Diagnose(BuildSmallCampaign(s), o);
}

}  // namespace umbmark::testing
