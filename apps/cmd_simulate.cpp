// `umbmark simulate MANIFEST.toml --out DIR [--effect NAME:k=v,...] [--seed N]`:
// writes a synthetic campaign (OUTDIR/campaign.toml + one CSV per experiment,
// contract formats) for the manifest's experiments, from a true robot given
// by flags (--E-d, --E-b, --kl, --kr; defaults: the manifest's robot with
// k = 0.001 m^1/2) with any of the contract's effects. The truth (seed, true
// robot, effects) goes to --truth-out (default OUTDIR/truth.json), never into
// the campaign itself, so the campaign can be diagnosed blind.
//
// Output safety: the campaign is written into a staging folder and renamed
// into place as a whole; a non-empty --out is refused without --force, an
// --out that contains an input (the manifest, a template) always. Ground
// truth carries motion-capture noise by default (docs/diagnosis.md).
#include <filesystem>
#include <map>
#include <memory>
#include <variant>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "common.hpp"
#include "core/errors.hpp"
#include "output/atomic_write.hpp"
#include "formats/campaign_writer.hpp"
#include "formats/data_file.hpp"
#include "formats/manifest.hpp"
#include "simulation/campaign_sim.hpp"
#include "simulation/effects.hpp"

namespace umbmark::cli {

namespace {

struct SimulateOptions {
  std::string manifest;
  std::string out;
  std::vector<std::string> effects;
  std::uint64_t seed = 1;
  sim::CampaignSimOptions sim;
  std::optional<double> gt_sigma_xy, gt_sigma_theta;
  bool hide_gt_sigma = false;
  std::string truth_out;
  bool force = false;
  JsonFlag json;
};

/// Ground-truth noise when neither the manifest nor a flag states it: a
/// motion-capture system's (the contract: a fraction of a millimetre and
/// about 0.1 deg).
constexpr GroundTruthNoise kDefaultGroundTruthNoise{3e-4, 1.7e-3};

/// Parses every --effect; an effect named twice is a usage error (the second
/// would silently replace the first).
void ParseEffects(const std::vector<std::string>& specs, sim::Effects& effects) {
  std::map<std::string, std::string> seen;
  for (const auto& spec : specs) {
    const std::string name = spec.substr(0, spec.find(':'));
    if (auto it = seen.find(name); it != seen.end()) {
      throw InvalidOptions(fmt::format("--effect {} is given twice ('{}' and '{}'); give each effect once with all "
                                       "its parameters",
                                       name, it->second, spec));
    }
    seen.emplace(name, spec);
    sim::ParseEffectSpec(spec, effects);
  }
}

int RunSimulate(SimulateOptions o) {
  namespace fs = std::filesystem;
  const Manifest manifest = io::ReadManifest(o.manifest);
  ParseEffects(o.effects, o.sim.effects);
  o.sim.seed = o.seed;
  if (!manifest.ground_truth && !o.gt_sigma_xy && !o.gt_sigma_theta) o.sim.ground_truth = kDefaultGroundTruthNoise;
  if (o.gt_sigma_xy || o.gt_sigma_theta) {
    GroundTruthNoise gt = manifest.ground_truth.value_or(kDefaultGroundTruthNoise);
    if (o.gt_sigma_xy) gt.sigma_xy_m = *o.gt_sigma_xy;
    if (o.gt_sigma_theta) gt.sigma_theta_rad = *o.gt_sigma_theta;
    o.sim.ground_truth = gt;
  }
  o.sim.state_ground_truth = !o.hide_gt_sigma;
  if (auto e = o.sim.Check(); !e.empty()) throw InvalidOptions("simulate: " + e);

  // Free experiments whose file exists are replayed from it.
  std::vector<std::optional<TrajectoryData>> templates(manifest.experiments.size());
  for (std::size_t e = 0; e < manifest.experiments.size(); ++e) {
    const Experiment& ex = manifest.experiments[e];
    if (ex.kind != ExperimentKind::kFree || !fs::exists(ex.resolved_file)) continue;
    io::RunFile rf = io::ReadRunFile(ex.resolved_file);
    auto* t = std::get_if<TrajectoryData>(&rf);
    if (!t) throw InputError(ex.resolved_file, "a free experiment's template must be a trajectory CSV");
    templates[e] = std::move(*t);
  }

  // Every input and output is known: refuse collisions before any work.
  io::OutputSet& outs = CommandOutputs();
  outs.AddManifestInputs(o.manifest, manifest);
  std::vector<std::string> names = {"campaign.toml"};
  for (const auto& ex : manifest.experiments)
    if (!fs::path(ex.file).is_absolute()) names.push_back(ex.file);  // WriteCampaign refuses absolute ones
  if (o.truth_out.empty()) names.push_back("truth.json");
  outs.AddOutputDirectory("--out", o.out, names, o.force);
  outs.AddOutput("--truth-out", o.truth_out);
  outs.AddOutput("--json", o.json.path);
  outs.Check();

  const sim::SimulatedCampaign campaign = sim::SimulateCampaign(manifest, o.sim, templates);
  const std::vector<std::string> comment = {
      fmt::format("synthetic campaign written by umbmark simulate from {} (seed {})",
                  fs::path(o.manifest).filename().string(), o.seed)};
  const nlohmann::json truth = sim::CampaignTruthJson(campaign, o.sim);
  std::vector<io::ExtraFile> extra;
  if (o.truth_out.empty()) extra.push_back({"truth.json", DumpJson(truth) + "\n"});
  const std::string manifest_path = io::WriteCampaign(campaign.manifest, campaign.data, o.out, comment, extra, o.force);
  const std::string truth_path = o.truth_out.empty() ? (fs::path(o.out) / "truth.json").string() : o.truth_out;
  if (!o.truth_out.empty()) outs.Write(truth_path, DumpJson(truth) + "\n");

  if (o.json.PrintText()) {
    fmt::print("Simulated campaign from {} (seed {})\n", o.manifest, o.seed);
    fmt::print("  true robot: E_d = {}, E_b = {}, k_L = {} m^1/2, k_R = {} m^1/2\n", o.sim.truth.E_d,
               o.sim.truth.E_b, o.sim.truth.k_L, o.sim.truth.k_R);
    const auto active = o.sim.effects.ActiveKinds();
    if (active.empty()) fmt::print("  effects: none\n");
    for (auto k : active) fmt::print("  effect: {}\n", sim::EffectSpecString(k, o.sim.effects));
    fmt::print("  ground truth noise: sigma_xy = {} m, sigma_theta = {} rad{}\n",
               campaign.ground_truth_noise.sigma_xy_m, campaign.ground_truth_noise.sigma_theta_rad,
               campaign.manifest.ground_truth ? "" : " (not stated in the manifest)");
    for (std::size_t e = 0; e < campaign.manifest.experiments.size(); ++e) {
      const auto& ex = campaign.manifest.experiments[e];
      const auto& d = campaign.data[e];
      const std::size_t runs = std::holds_alternative<TrajectoryData>(d) ? std::get<TrajectoryData>(d).runs.size()
                                                                         : std::get<EndpointData>(d).runs.size();
      fmt::print("  experiment {} ({}{}): {} runs -> {}\n", e + 1, ExperimentKindToString(ex.kind),
                 templates[e] ? ", replayed from its file" : "", runs, (fs::path(o.out) / ex.file).string());
    }
    fmt::print("  wrote {}\n  wrote {} (the truth; keep it away from a blind diagnosis)\n", manifest_path, truth_path);
  }
  nlohmann::json j = truth;
  j["manifest"] = manifest_path;
  j["truth_file"] = truth_path;
  o.json.Emit(j);
  return 0;
}

}  // namespace

Command SetupSimulate(CLI::App& parent) {
  auto opts = std::make_shared<SimulateOptions>();
  auto* app = parent.add_subcommand("simulate", "Write a synthetic campaign (manifest + CSVs) with chosen effects");
  app->add_option("MANIFEST", opts->manifest, "Campaign manifest (TOML): robot and experiments to simulate")
      ->required();
  app->add_option("--out", opts->out, "Output directory (campaign.toml + experiment files)")->required();
  app->add_option("--effect", opts->effects,
                  "Effect NAME:k=v,... (repeatable), e.g. turn_scrub:k=0.05 or gt_offset:dx=0.02,dy=0");
  app->add_option("--seed", opts->seed, "Seed of every random process (default 1)")->check(SeedValidator());
  auto& s = opts->sim;
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
  app->add_option("--gt-sigma-xy", opts->gt_sigma_xy, "Ground-truth position noise [m] (default: the manifest's, else 0.0003)")
      ->check(NumberIn(0.0, 1.0));
  app->add_option("--gt-sigma-theta", opts->gt_sigma_theta,
                  "Ground-truth heading noise [rad] (default: the manifest's, else 0.0017)")
      ->check(NumberIn(0.0, 1.0));
  app->add_flag("--hide-gt-sigma", opts->hide_gt_sigma,
                "Do not state [ground_truth] in the written manifest (diagnose then estimates it)");
  app->add_flag("--endpoint-squares", s.endpoint_squares, "Write squares as endpoint CSV (return errors only)");
  app->add_option("--truth-out", opts->truth_out, "Where the truth JSON goes (default OUTDIR/truth.json)");
  app->add_flag("--force", opts->force, "Replace a non-empty --out folder (and everything in it)");
  opts->json.Bind(*app);
  return {app, [opts] { return RunSimulate(*opts); }};
}

}  // namespace umbmark::cli
