// `umbmark simulate` as a library call (see simulate.hpp).
#include "api/simulate.hpp"

#include <filesystem>
#include <map>
#include <utility>
#include <variant>

#include <fmt/format.h>

#include "api/json.hpp"
#include "core/errors.hpp"
#include "formats/campaign_writer.hpp"
#include "formats/data_file.hpp"
#include "formats/manifest.hpp"
#include "output/output_set.hpp"
#include "simulation/effects.hpp"

namespace umbmark::api {

namespace {

std::string In(const char* flag, double v, double lo, double hi) {
  if (std::isfinite(v) && v >= lo && v <= hi) return {};
  return fmt::format("{}: must be a number from {:g} to {:g} (got '{}')", flag, lo, hi, v);
}

std::string Positive(const char* flag, double v) {
  if (std::isfinite(v) && v > 0.0) return {};
  return fmt::format("{}: must be a finite number > 0 (got '{}')", flag, v);
}

/// Ground-truth noise when neither the manifest nor an option states it: a
/// motion-capture system's (the contract: a fraction of a millimetre and
/// about 0.1 deg).
constexpr GroundTruthNoise kDefaultGroundTruthNoise{3e-4, 1.7e-3};

/// Parses every effect; an effect named twice is a usage error (the second
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

/// Free experiments whose file exists are replayed from it.
std::vector<std::optional<TrajectoryData>> Templates(const Manifest& manifest) {
  std::vector<std::optional<TrajectoryData>> templates(manifest.experiments.size());
  for (std::size_t e = 0; e < manifest.experiments.size(); ++e) {
    const Experiment& ex = manifest.experiments[e];
    if (ex.kind != ExperimentKind::kFree || !std::filesystem::exists(ex.resolved_file)) continue;
    io::RunFile rf = io::ReadRunFile(ex.resolved_file);
    auto* t = std::get_if<TrajectoryData>(&rf);
    if (!t) throw InputError(ex.resolved_file, "a free experiment's template must be a trajectory CSV");
    templates[e] = std::move(*t);
  }
  return templates;
}

}  // namespace

std::string SimulateOptions::Check() const {
  if (manifest.empty()) return "MANIFEST is required";
  if (out.empty()) return "--out is required";
  const auto& s = sim;
  for (const std::string& e :
       {In("--E-d", s.truth.E_d, 0.5, 2.0), In("--E-b", s.truth.E_b, 0.5, 2.0), In("--kl", s.truth.k_L, 0.0, 0.1),
        In("--kr", s.truth.k_R, 0.0, 0.1), In("--square-runs", s.square_runs_per_direction, 1, 1000000),
        In("--back-and-forth-runs", s.back_and_forth_runs, 1, 1000000), In("--free-runs", s.free_runs, 1, 1000000),
        Positive("--sample-rate", s.sample_rate_hz), Positive("--speed", s.speed_m_s),
        Positive("--turn-rate", s.turn_rate_rad_s), Positive("--free-radius", s.free_radius_m),
        std::isfinite(s.pause_s) && s.pause_s >= 0.0
            ? std::string()
            : fmt::format("--pause: must be a finite number >= 0 (got '{}')", s.pause_s),
        gt_sigma_xy_m ? In("--gt-sigma-xy", *gt_sigma_xy_m, 0.0, 1.0) : std::string(),
        gt_sigma_theta_rad ? In("--gt-sigma-theta", *gt_sigma_theta_rad, 0.0, 1.0) : std::string()}) {
    if (!e.empty()) return e;
  }
  return {};
}

SimulateResult Simulate(SimulateOptions o) {
  namespace fs = std::filesystem;
  if (std::string err = o.Check(); !err.empty()) throw InvalidOptions(err);
  const Manifest manifest = io::ReadManifest(o.manifest);
  ParseEffects(o.effects, o.sim.effects);
  o.sim.seed = o.seed;
  if (!manifest.ground_truth && !o.gt_sigma_xy_m && !o.gt_sigma_theta_rad) o.sim.ground_truth = kDefaultGroundTruthNoise;
  if (o.gt_sigma_xy_m || o.gt_sigma_theta_rad) {
    GroundTruthNoise gt = manifest.ground_truth.value_or(kDefaultGroundTruthNoise);
    if (o.gt_sigma_xy_m) gt.sigma_xy_m = *o.gt_sigma_xy_m;
    if (o.gt_sigma_theta_rad) gt.sigma_theta_rad = *o.gt_sigma_theta_rad;
    o.sim.ground_truth = gt;
  }
  o.sim.state_ground_truth = !o.hide_gt_sigma;
  if (auto e = o.sim.Check(); !e.empty()) throw InvalidOptions("simulate: " + e);
  const std::vector<std::optional<TrajectoryData>> templates = Templates(manifest);

  // Every input and output is known: refuse collisions before any work.
  std::optional<io::OutputSet> own;
  io::OutputSet& outs = o.outputs ? *o.outputs : own.emplace();
  outs.AddManifestInputs(o.manifest, manifest);
  std::vector<std::string> names = {"campaign.toml"};
  for (const auto& ex : manifest.experiments)
    if (!fs::path(ex.file).is_absolute()) names.push_back(ex.file);  // WriteCampaign refuses absolute ones
  if (o.truth_out.empty()) names.push_back("truth.json");
  outs.AddOutputDirectory("--out", o.out, names, o.force);
  outs.AddOutput("--truth-out", o.truth_out);
  outs.Check();

  const sim::SimulatedCampaign campaign = sim::SimulateCampaign(manifest, o.sim, templates);
  const std::vector<std::string> comment = {
      fmt::format("synthetic campaign written by umbmark simulate from {} (seed {})",
                  fs::path(o.manifest).filename().string(), o.seed)};
  SimulateResult r;
  r.truth = sim::CampaignTruthJson(campaign, o.sim);
  std::vector<io::ExtraFile> extra;
  if (o.truth_out.empty()) extra.push_back({"truth.json", DumpJson(r.truth) + "\n"});
  r.manifest = io::WriteCampaign(campaign.manifest, campaign.data, o.out, comment, extra, o.force);
  r.truth_file = o.truth_out.empty() ? (fs::path(o.out) / "truth.json").string() : o.truth_out;
  if (!o.truth_out.empty()) outs.Write(r.truth_file, DumpJson(r.truth) + "\n");

  r.seed = o.seed;
  r.true_robot = o.sim.truth;
  for (auto k : o.sim.effects.ActiveKinds()) r.effects.push_back(sim::EffectSpecString(k, o.sim.effects));
  r.ground_truth = campaign.ground_truth_noise;
  r.ground_truth_stated = campaign.manifest.ground_truth.has_value();
  for (std::size_t e = 0; e < campaign.manifest.experiments.size(); ++e) {
    const auto& ex = campaign.manifest.experiments[e];
    const auto& d = campaign.data[e];
    const std::size_t runs = std::holds_alternative<TrajectoryData>(d) ? std::get<TrajectoryData>(d).runs.size()
                                                                       : std::get<EndpointData>(d).runs.size();
    r.experiments.push_back({ExperimentKindToString(ex.kind), ex.file, runs, templates[e].has_value(),
                             (fs::path(o.out) / ex.file).string()});
  }
  return r;
}

nlohmann::json ToJson(const SimulateResult& r) {
  nlohmann::json j = r.truth;
  j["manifest"] = r.manifest;
  j["truth_file"] = r.truth_file;
  return j;
}

}  // namespace umbmark::api
