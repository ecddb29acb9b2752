// `umbmark simulate` as one library call (lib/api, see calibrate.hpp for the
// pattern): a synthetic campaign (DIR/campaign.toml + one CSV per
// experiment, the contract's formats) for a manifest's experiments, from a
// true robot with any of the contract's effects, written into `out`
// atomically; the truth (seed, true robot, effects) goes to `truth_out`
// (default DIR/truth.json), never into the campaign.
//
//   api::SimulateOptions o;
//   o.manifest = "simulate.toml";
//   o.out = "campaign";
//   o.effects = {"turn_scrub:k=0.05"};
//   o.sim.truth.E_d = 1.002;
//   const api::SimulateResult r = api::Simulate(o);   // r.manifest: campaign/campaign.toml
//
// Errors: InvalidOptions (Check()'s message, an effect given twice, an
// output that is an input, a non-empty `out` without force), InputError (a
// bad manifest or template).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "simulation/campaign_sim.hpp"

namespace umbmark::io {
class OutputSet;
}

namespace umbmark::api {

/// Every option of `umbmark simulate` (the flag in brackets).
struct SimulateOptions {
  std::string manifest;              ///< [MANIFEST] robot and experiments to simulate (required)
  std::string out;                   ///< [--out] output folder (required)
  std::vector<std::string> effects;  ///< [--effect] NAME:k=v,... each effect once
  std::uint64_t seed = 1;            ///< [--seed] of every random process
  /// [--E-d, --E-b] (0.5 to 2), [--kl, --kr] (0 to 0.1 m^1/2; default
  /// 0.001), [--square-runs], [--back-and-forth-runs], [--free-runs] (1 to
  /// 10^6), [--sample-rate], [--speed], [--turn-rate], [--free-radius] (> 0),
  /// [--pause] (>= 0), [--endpoint-squares]; its seed, effects and ground
  /// truth are set from the fields here.
  sim::CampaignSimOptions sim;
  /// [--gt-sigma-xy] [m], [--gt-sigma-theta] [rad], 0 to 1: ground-truth
  /// noise; unset: the manifest's, else a motion-capture system's (0.0003 m,
  /// 0.0017 rad).
  std::optional<double> gt_sigma_xy_m, gt_sigma_theta_rad;
  bool hide_gt_sigma = false;  ///< [--hide-gt-sigma] no [ground_truth] in the written manifest
  std::string truth_out;       ///< [--truth-out] "" = DIR/truth.json
  bool force = false;          ///< [--force] replace a non-empty `out`
  /// The output set the files are registered with (output/output_set.hpp);
  /// null: Simulate() makes its own.
  io::OutputSet* outputs = nullptr;

  /// "" when valid, else a message naming the bad field by its flag.
  std::string Check() const;
};

/// One experiment written (JSON `experiments[i]` has kind, file, runs).
struct SimulatedExperiment {
  std::string kind, file;  ///< file as in the manifest
  std::size_t runs = 0;
  bool replayed = false;   ///< a free experiment replayed from its template file
  std::string path;        ///< where it was written
};

struct SimulateResult {
  /// The truth (sim::CampaignTruthJson: seed, truth, effects, ground_truth,
  /// total_runs, experiments, motion), as written to `truth_file`.
  nlohmann::json truth;
  std::string manifest;    ///< the written campaign.toml
  std::string truth_file;  ///< where the truth went
  std::uint64_t seed = 0;
  sim::CampaignTruth true_robot;
  std::vector<std::string> effects;  ///< the active effects as specs
  GroundTruthNoise ground_truth;     ///< applied
  bool ground_truth_stated = true;   ///< in the written manifest
  std::vector<SimulatedExperiment> experiments;
};

SimulateResult Simulate(SimulateOptions options);
/// The JSON `--json` writes: the truth plus `manifest` and `truth_file`.
nlohmann::json ToJson(const SimulateResult& result);

}  // namespace umbmark::api
