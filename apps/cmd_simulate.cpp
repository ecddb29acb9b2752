// `umbmark simulate MANIFEST.toml --out DIR [--effect NAME:k=v,...] [--seed N]`:
// writes a synthetic campaign (OUTDIR/campaign.toml + one CSV per experiment,
// contract formats) for the manifest's experiments, from a true robot given
// by flags (--E-d, --E-b, --kl, --kr; defaults: the manifest's robot with
// k = 0.001 m^1/2) with any of the contract's effects. The truth (seed, true
// robot, effects) goes to --truth-out (default OUTDIR/truth.json), never into
// the campaign itself, so the campaign can be diagnosed blind. The command
// is the library's api::Simulate (lib/api/simulate.hpp): this file binds
// the flags to its options, and prints.
//
// Output safety: the campaign is written into a staging folder and renamed
// into place as a whole; a non-empty --out is refused without --force, an
// --out that contains an input (the manifest, a template) always. Ground
// truth carries motion-capture noise by default (docs/diagnosis.md).
#include <memory>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "api/simulate.hpp"
#include "commands.hpp"
#include "common.hpp"

namespace umbmark::cli {

namespace {

/// The command line's options: the library's, and where the JSON goes.
struct SimulateFlags {
  api::SimulateOptions o;
  JsonFlag json;
};

int RunSimulate(SimulateFlags f) {
  CommandOutputs().AddOutput("--json", f.json.path);
  f.o.outputs = &CommandOutputs();
  const std::string manifest = f.o.manifest;
  const api::SimulateResult r = api::Simulate(std::move(f.o));
  if (f.json.PrintText()) {
    fmt::print("Simulated campaign from {} (seed {})\n", manifest, r.seed);
    fmt::print("  true robot: E_d = {}, E_b = {}, k_L = {} m^1/2, k_R = {} m^1/2\n", r.true_robot.E_d,
               r.true_robot.E_b, r.true_robot.k_L, r.true_robot.k_R);
    if (r.effects.empty()) fmt::print("  effects: none\n");
    for (const auto& e : r.effects) fmt::print("  effect: {}\n", e);
    fmt::print("  ground truth noise: sigma_xy = {} m, sigma_theta = {} rad{}\n", r.ground_truth.sigma_xy_m,
               r.ground_truth.sigma_theta_rad, r.ground_truth_stated ? "" : " (not stated in the manifest)");
    for (std::size_t e = 0; e < r.experiments.size(); ++e) {
      const auto& ex = r.experiments[e];
      fmt::print("  experiment {} ({}{}): {} runs -> {}\n", e + 1, ex.kind, ex.replayed ? ", replayed from its file" : "",
                 ex.runs, ex.path);
    }
    fmt::print("  wrote {}\n  wrote {} (the truth; keep it away from a blind diagnosis)\n", r.manifest, r.truth_file);
  }
  f.json.Emit(api::ToJson(r));
  return 0;
}

}  // namespace

Command SetupSimulate(CLI::App& parent) {
  auto opts = std::make_shared<SimulateFlags>();
  auto* app = parent.add_subcommand("simulate", "Write a synthetic campaign (manifest + CSVs) with chosen effects");
  app->add_option("MANIFEST", opts->o.manifest, "Campaign manifest (TOML): robot and experiments to simulate")
      ->required();
  app->add_option("--out", opts->o.out, "Output directory (campaign.toml + experiment files)")->required();
  app->add_option("--effect", opts->o.effects,
                  "Effect NAME:k=v,... (repeatable), e.g. turn_scrub:k=0.05 or gt_offset:dx=0.02,dy=0");
  app->add_option("--seed", opts->o.seed, "Seed of every random process (default 1)")->check(SeedValidator());
  auto& s = opts->o.sim;
  // Ranges as calibrate's plausibility gates: no robot is off by a factor of
  // two, and wheel noise beyond 0.1 m^1/2 (3 cm after 1 m) is no odometry.
  app->add_option("--E-d", s.truth.E_d, "True wheel diameter ratio error E_d (default 1)")->check(NumberIn(0.5, 2.0));
  app->add_option("--E-b", s.truth.E_b, "True wheelbase error E_b (default 1)")->check(NumberIn(0.5, 2.0));
  app->add_option("--kl", s.truth.k_L, "True left wheel noise k_L [m^1/2] (default 0.001)")->check(NumberIn(0.0, 0.1));
  app->add_option("--kr", s.truth.k_R, "True right wheel noise k_R [m^1/2] (default 0.001)")->check(NumberIn(0.0, 0.1));
  app->add_option("--square-runs", s.square_runs_per_direction, "Square runs per direction (default 10)")
      ->check(NumberIn(1, 1000000));
  app->add_option("--back-and-forth-runs", s.back_and_forth_runs, "Back-and-forth runs (default 20)")
      ->check(NumberIn(1, 1000000));
  app->add_option("--free-runs", s.free_runs, "Figure-eight runs per free experiment without a template (default 4)")
      ->check(NumberIn(1, 1000000));
  app->add_option("--sample-rate", s.sample_rate_hz, "Logging rate [Hz] (default 20)")->check(Positive());
  app->add_option("--speed", s.speed_m_s, "Leg speed [m/s] (default 0.3)")->check(Positive());
  app->add_option("--turn-rate", s.turn_rate_rad_s, "Spot-turn rate [rad/s] (default 1)")->check(Positive());
  app->add_option("--pause", s.pause_s, "Standstill between motions [s] (default 1)")->check(NonNegative());
  app->add_option("--free-radius", s.free_radius_m, "Radius of the figure-eight circles [m] (default 1)")
      ->check(Positive());
  app->add_option("--gt-sigma-xy", opts->o.gt_sigma_xy_m, "Ground-truth position noise [m] (default: the manifest's, else 0.0003)")
      ->check(NumberIn(0.0, 1.0));
  app->add_option("--gt-sigma-theta", opts->o.gt_sigma_theta_rad,
                  "Ground-truth heading noise [rad] (default: the manifest's, else 0.0017)")
      ->check(NumberIn(0.0, 1.0));
  app->add_flag("--hide-gt-sigma", opts->o.hide_gt_sigma,
                "Do not state [ground_truth] in the written manifest (diagnose then estimates it)");
  app->add_flag("--endpoint-squares", s.endpoint_squares, "Write squares as endpoint CSV (return errors only)");
  app->add_option("--truth-out", opts->o.truth_out, "Where the truth JSON goes (default OUTDIR/truth.json)");
  app->add_flag("--force", opts->o.force, "Replace a non-empty --out folder (and everything in it)");
  opts->json.Bind(*app);
  return {app, [opts] { return RunSimulate(*opts); }};
}

}  // namespace umbmark::cli
