// `evaluate` as a library call (see evaluate.hpp).
#include "api/evaluate.hpp"

#include <algorithm>
#include <exception>
#include <filesystem>
#include <iterator>
#include <set>
#include <thread>
#include <variant>

#include <fmt/format.h>

#include "api/json.hpp"
#include "core/errors.hpp"
#include "evaluation/data_warnings.hpp"
#include "formats/data_file.hpp"
#include "formats/manifest.hpp"
#include "formats/params_json.hpp"
#include "formats/run_prefetch.hpp"

namespace umbmark::api {

namespace {

/// One file to evaluate: a trajectory CSV, or one experiment of a manifest.
struct Source {
  std::string label;
  RobotParams recorded;
  std::string path;
  std::string manifest;  ///< the manifest it comes from (its endpoint files are skipped), or empty
};

/// The files to read, in order (manifests are read here, the data files not).
std::vector<Source> ListSources(const EvaluateOptions& o) {
  std::vector<Source> out;
  for (const auto& path : o.inputs) {
    if (io::IsManifestPath(path)) {
      const Manifest m = io::ReadManifest(path);
      const RobotParams robot = o.robot.Resolve(m.robot);
      int index = 0;
      for (const auto& e : m.experiments) {
        ++index;
        out.push_back({fmt::format("{}#{}:{}", path, index, ExperimentKindToString(e.kind)), robot, e.resolved_file,
                       path});
      }
    } else {
      out.push_back({path, o.robot.Resolve(), path, ""});
    }
  }
  return out;
}

/// What evaluating one file (or a part of one) gives.
struct FileResult {
  std::vector<RunEvaluation> base, param;  ///< recorded parameters; --params
  TrajectoryDataCheck check;
  explicit FileResult(const RobotParams& recorded) : check(recorded) {}
  void Add(const TrajectoryRun& run, const Source& src, const std::optional<RobotParams>& params, Integrator integ) {
    check.Add(run);
    base.push_back(EvaluateRun(run, src.path, src.label, src.recorded, src.recorded, integ));
    if (params) param.push_back(EvaluateRun(run, src.path, src.label, *params, src.recorded, integ));
  }
};

/// Files at least this large are evaluated in two parts at once.
constexpr std::uint64_t kPartsFromBytes = std::uint64_t{32} << 20;

// A large file cut in two at a run boundary near its middle, each part read
// and evaluated on its own thread, the results joined in file order: the
// whole process takes about half the time on two cores. Any fault in either
// part, or a run id in both parts (a run split in two blocks, an error the
// sequential read names), gives nullopt: the caller then reads the file in
// one pass from `whole` (still at its first row), so every message is the
// sequential read's.
std::optional<FileResult> EvaluateInParts(const io::TrajectoryReader& whole, const Source& src,
                                          const std::optional<RobotParams>& params, Integrator integ) {
  std::error_code ec;
  const std::uint64_t size = std::filesystem::file_size(src.path, ec);
  if (ec || size < kPartsFromBytes || std::thread::hardware_concurrency() < 2) return std::nullopt;
  const auto cut = io::FindRunBoundary(src.path, size / 2, whole.run_column());
  if (!cut || *cut <= whole.offset()) return std::nullopt;
  FileResult first(src.recorded), second(src.recorded);
  std::vector<std::string> first_ids, second_ids;
  std::exception_ptr first_error, second_error;
  const auto evaluate = [&](std::uint64_t begin, std::uint64_t end, std::size_t line, FileResult& out,
                            std::vector<std::string>& ids, std::exception_ptr& error) {
    try {
      io::TrajectoryReader part(whole, begin, end, line == 0 ? io::LineAtOffset(src.path, begin) : line);
      TrajectoryRun run;
      while (part.NextRun(run)) out.Add(run, src, params, integ);
      ids = part.RunIds();
    } catch (...) {
      error = std::current_exception();
    }
  };
  std::thread later([&] { evaluate(*cut, size, 0, second, second_ids, second_error); });
  evaluate(whole.offset(), *cut, whole.next_line(), first, first_ids, first_error);
  later.join();
  if (first_error || second_error) return std::nullopt;
  std::sort(first_ids.begin(), first_ids.end());
  for (const auto& id : second_ids)
    if (std::binary_search(first_ids.begin(), first_ids.end(), id)) return std::nullopt;
  std::move(second.base.begin(), second.base.end(), std::back_inserter(first.base));
  std::move(second.param.begin(), second.param.end(), std::back_inserter(first.param));
  first.check.Merge(second.check);
  return first;
}

}  // namespace

std::string EvaluateOptions::Check() const {
  if (inputs.empty()) return "inputs: give at least one trajectory CSV or campaign manifest (DATA)";
  for (const auto& i : inputs)
    if (i.empty()) return "inputs: an empty path";
  return robot.Check();
}

// Streams each file run by run: only the run in hand is in memory (and the
// first few, for the plot).
EvaluateResult Evaluate(const EvaluateOptions& o) {
  if (const std::string err = o.Check(); !err.empty()) throw InvalidOptions(err);
  const std::vector<Source> sources = ListSources(o);
  EvaluateResult out;
  out.integrator = IntegratorToString(o.integrator);
  if (!o.params_file.empty()) out.params = io::ReadParamsJson(o.params_file, sources.front().recorded);
  const std::optional<RobotParams>& params = out.params;
  std::vector<RunEvaluation> base_runs, param_runs;
  std::set<std::string> manifests_with_trajectories;
  for (const auto& src : sources) {
    io::OpenedRunFile file = io::OpenRunFile(src.path);
    auto* reader = std::get_if<io::TrajectoryReader>(&file);
    if (reader == nullptr) {
      if (!src.manifest.empty()) continue;
      throw InputError(src.path, "evaluate needs a trajectory CSV (ticks or wheel travel with ground truth)");
    }
    manifests_with_trajectories.insert(src.manifest);
    std::optional<FileResult> r;
    if (!o.keep_plot_runs) r = EvaluateInParts(*reader, src, params, o.integrator);
    if (!r) {
      r.emplace(src.recorded);
      // The next run is read on a second thread while this one is evaluated.
      io::RunPrefetcher prefetch(*reader);
      TrajectoryRun run;
      while (prefetch.NextRun(run)) {
        r->Add(run, src, params, o.integrator);
        if (o.keep_plot_runs && out.plot_runs.size() < kEvaluatePlotRuns) out.plot_runs.push_back({src.path, src.recorded, run});
      }
    }
    std::move(r->base.begin(), r->base.end(), std::back_inserter(base_runs));
    std::move(r->param.begin(), r->param.end(), std::back_inserter(param_runs));
    for (auto& w : r->check.Warnings(src.path)) out.warnings.push_back(std::move(w));
  }
  for (const auto& src : sources) {
    if (!src.manifest.empty() && manifests_with_trajectories.count(src.manifest) == 0) {
      throw InputError(src.manifest, "no experiment of the manifest has trajectory data to evaluate");
    }
  }
  EvaluationSummary base = Summarise(std::move(base_runs));
  if (params) {
    out.parameters = *params;
    out.summary = Summarise(std::move(param_runs));
    out.recorded = EvaluateRecorded{sources.front().recorded, std::move(base)};
  } else {
    out.parameters = sources.front().recorded;
    out.summary = std::move(base);
  }
  return out;
}

nlohmann::json ToJson(const EvaluateResult& r) {
  nlohmann::json j = {{"integrator", r.integrator},
                      {"parameters", JsonParams(r.parameters)},
                      {"runs", JsonEvaluationRuns(r.summary)},
                      {"summary", JsonEvaluationSummary(r.summary)},
                      {"warnings", r.warnings}};
  if (r.recorded) {
    j["recorded"] = {{"parameters", JsonParams(r.recorded->parameters)},
                     {"runs", JsonEvaluationRuns(r.recorded->summary)},
                     {"summary", JsonEvaluationSummary(r.recorded->summary)}};
  }
  return j;
}

}  // namespace umbmark::api
