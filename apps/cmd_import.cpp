// `umbmark import optiodom DIR --out OUTDIR`: converts one OptiOdom dataset
// folder into the contract's campaign manifest (OUTDIR/campaign.toml) and
// trajectory CSV (OUTDIR/runs.csv).
#include <filesystem>
#include <memory>

#include <fmt/format.h>

#include "commands.hpp"
#include "common.hpp"
#include "core/angles.hpp"
#include "core/errors.hpp"
#include "io/atomic_write.hpp"
#include "io/campaign_writer.hpp"
#include "io/optiodom.hpp"

namespace umbmark::cli {

namespace {

struct ImportOptions {
  std::string dir;
  std::string out;
  std::string category;
  JsonFlag json;
};

int RunImportOptiOdom(const ImportOptions& o) {
  namespace fs = std::filesystem;
  std::optional<std::string> category;
  if (!o.category.empty()) category = o.category;
  const io::OptiOdomDataset ds = io::ImportOptiOdom(o.dir, category);

  std::error_code ec;
  fs::create_directories(o.out, ec);
  if (ec || !fs::is_directory(o.out)) throw InputError(o.out, "cannot create output directory: " + ec.message());
  const std::string source = fmt::format("OptiOdom dataset {} ({}), imported by umbmark import optiodom", ds.id,
                                         ds.category);
  Manifest m;
  m.robot = ds.robot;
  m.experiments.push_back(ds.experiment);
  const std::string runs_path = (fs::path(o.out) / "runs.csv").string();
  const std::string manifest_path = (fs::path(o.out) / "campaign.toml").string();
  io::WriteFileAtomically(runs_path, io::FormatTrajectoryCsv(ds.runs, {source}));
  io::WriteFileAtomically(manifest_path, io::FormatManifest(m, {source}));

  std::size_t samples = 0;
  nlohmann::json runs = nlohmann::json::array();
  for (const auto& r : ds.runs.runs) {
    samples += r.size();
    runs.push_back({{"run", r.run}, {"direction", r.direction}, {"samples", r.size()}});
  }
  if (o.json.PrintText()) {
    fmt::print("Imported OptiOdom dataset {} ({}): {} runs, {} samples\n", ds.id, ds.category, ds.runs.runs.size(),
               samples);
    fmt::print("  robot: wheelbase {} m, D_L {} m, D_R {} m, {} ticks/rev\n", ds.robot.wheelbase_m,
               ds.robot.wheel_diameter_left_m, ds.robot.wheel_diameter_right_m, *ds.robot.ticks_per_rev);
    if (ds.experiment.kind == ExperimentKind::kSquare) fmt::print("  experiment: square, side {} m\n", ds.experiment.side_m);
    for (const auto& r : ds.runs.runs) fmt::print("  run {:>3}  {:<9} {} samples\n", r.run, r.direction, r.size());
    fmt::print("  wrote {}\n  wrote {}\n", manifest_path, runs_path);
  }
  o.json.Emit({{"dataset", ds.id},
               {"category", ds.category},
               {"manifest", manifest_path},
               {"runs_csv", runs_path},
               {"robot", JsonParams(ds.robot)},
               {"experiment", {{"kind", ExperimentKindToString(ds.experiment.kind)}, {"side_m", ds.experiment.side_m}}},
               {"runs", runs}});
  return 0;
}

}  // namespace

Command SetupImport(CLI::App& parent) {
  auto* imp = parent.add_subcommand("import", "Convert external datasets to the umbmark formats");
  imp->require_subcommand(1);
  auto opts = std::make_shared<ImportOptions>();
  auto* od = imp->add_subcommand("optiodom", "Convert one OptiOdom dataset folder to OUTDIR/campaign.toml + runs.csv");
  od->add_option("DIR", opts->dir, "Dataset folder (<id>_metadata.csv + <id>_run-NN.csv)")
      ->required()
      ->check(CLI::ExistingDirectory);
  od->add_option("--out", opts->out, "Output directory")->required();
  od->add_option("--category", opts->category,
                 "Dataset category (square|circular|ivanjko|free); default: the parent folder's name")
      ->check(CLI::IsMember({"square", "circular", "ivanjko", "free"}));
  opts->json.Bind(*od);
  return {imp, [opts] { return RunImportOptiOdom(*opts); }};
}

}  // namespace umbmark::cli
