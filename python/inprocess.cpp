// The in-process functions of the Python module (see inprocess.hpp).
#include "inprocess.hpp"

#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <new>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "api/calibrate.hpp"
#include "api/diagnose.hpp"
#include "api/fit_noise.hpp"
#include "api/json.hpp"
#include "api/predict.hpp"
#include "api/robot_source.hpp"
#include "api/simulate.hpp"
#include "api/summarize.hpp"
#include "arrays.hpp"
#include "core/errors.hpp"
#include "keywords.hpp"

namespace py = pybind11;

namespace umbmark::python {
namespace {

/// What the command line does with a library error (apps/main.cpp): its
/// exit status and message.
struct Failure {
  int status = 0;
  std::string message;
};

/// Runs `compute` with the GIL released; an error becomes a Failure as
/// apps/main.cpp maps it.
Failure Compute(const std::function<void()>& compute) {
  const py::gil_scoped_release release;
  try {
    compute();
    return {};
  } catch (const InputError& e) {
    return {1, e.what()};
  } catch (const InvalidOptions& e) {
    return {2, std::string("umbmark: ") + e.what()};
  } catch (const QualityGateError& e) {
    return {3, std::string("umbmark: quality gate failed: ") + e.what()};
  } catch (const std::bad_alloc&) {
    return {1, "umbmark: not enough memory for this input or these sizes; reduce the run count, the sample rate or "
               "the sizes given"};
  } catch (const nlohmann::json::exception& e) {
    return {1, std::string("umbmark: invalid JSON data: ") + e.what()};
  } catch (const std::filesystem::filesystem_error& e) {
    return {1, std::string("umbmark: ") + e.what()};
  } catch (const std::exception& e) {
    return {1, std::string("umbmark: error: ") + e.what()};
  }
}

/// The JSON text as `--json -` prints it (every object has `warnings`).
std::string JsonText(nlohmann::json j) {
  if (j.is_object() && !j.contains("warnings")) j["warnings"] = nlohmann::json::array();
  return api::DumpJson(j) + "\n";
}

/// The options of a call, their conversion's usage errors raised as the
/// command line's parser says them (no "umbmark: "), then Check()'s.
template <class O>
O Options(const std::string& command, const std::function<void(O&)>& fill) {
  O options;
  try {
    fill(options);
  } catch (const InvalidOptions& e) {
    Raise(2, e.what(), std::nullopt, command);
  } catch (const InputError& e) {
    Raise(1, e.what(), std::nullopt, command);
  }
  if (const std::string err = options.Check(); !err.empty()) Raise(2, err, std::nullopt, command);
  return options;
}

/// Positional inputs: paths (str or PathLike), lists of them flattened.
std::vector<std::string> Inputs(const py::args& inputs, const char* name) {
  std::vector<std::string> out;
  std::function<void(const py::handle&)> add = [&](const py::handle& input) {
    if (py::isinstance<py::list>(input) || py::isinstance<py::tuple>(input)) {
      for (const py::handle item : input) add(item);
      return;
    }
    out.push_back(Path(name, input));
  };
  for (const py::handle input : inputs) add(input);
  return out;
}

/// The one positional input of a command taking one (MANIFEST).
std::string OneInput(const py::args& inputs, const char* name) {
  std::vector<std::string> in = Inputs(inputs, name);
  if (in.size() != 1) throw InvalidOptions(fmt::format("{} takes exactly one path (got {})", name, in.size()));
  return in.front();
}

/// CLI11's PositiveNumber message for `--flag value`, as the command line says it.
std::string NotPositive(const std::string& flag, double value) {
  return fmt::format("{}: Value {} not in range 0.000000 to {:f}", flag, value, std::numeric_limits<double>::max());
}

// ----- calibrate -----

template <class O>
void RobotSetters(std::map<std::string, Setter<O>>& s) {
  using H = const py::handle&;
  using K = const std::string&;
  s["robot"] = [](O& o, K k, H v) { o.robot.robot_file = Path(k, v); };
  s["wheelbase"] = [](O& o, K k, H v) { o.robot.wheelbase_m = Number(k, v); };
  s["diameter_left"] = [](O& o, K k, H v) { o.robot.diameter_left_m = Number(k, v); };
  s["diameter_right"] = [](O& o, K k, H v) { o.robot.diameter_right_m = Number(k, v); };
  s["ticks_per_rev"] = [](O& o, K k, H v) { o.robot.ticks_per_rev = Number(k, v); };
}

// One line per option: a table, about 40 lines.
const std::map<std::string, Setter<api::CalibrateOptions>>& CalibrateSetters() {
  using O = api::CalibrateOptions;
  using H = const py::handle&;
  using K = const std::string&;
  static const std::map<std::string, Setter<O>> setters = [] {
    std::map<std::string, Setter<O>> s;
    RobotSetters(s);
    s["side"] = [](O& o, K k, H v) { o.side_m = Number(k, v); };
    s["estimator"] = [](O& o, K k, H v) { o.estimator = Text(k, v); };
    s["integrator"] = [](O& o, K k, H v) { o.integrator = Text(k, v); };
    s["ed_wheelbase"] = [](O& o, K k, H v) { o.ed_wheelbase = Text(k, v); };
    s["exclude_runs"] = [](O& o, K k, H v) { o.exclude_runs = List(k, v); };
    s["reject_outliers"] = [](O& o, K, H v) { o.reject_outliers = Truth(v); };
    s["outlier_threshold"] = [](O& o, K k, H v) { o.outlier_threshold = Number(k, v); };
    s["refine"] = [](O& o, K, H v) { o.refine = Truth(v); };
    s["fix"] = [](O& o, K k, H v) { o.fix = List(k, v); };
    s["free"] = [](O& o, K k, H v) { o.free = List(k, v); };
    s["loss"] = [](O& o, K k, H v) { o.loss = Text(k, v); };
    s["loss_scale"] = [](O& o, K k, H v) { o.loss_scale_m = Number(k, v); };
    s["samples_per_run"] = [](O& o, K k, H v) { o.samples_per_run = WholeNumber(k, v); };
    s["sampling"] = [](O& o, K k, H v) { o.sampling = Text(k, v); };
    s["start_pose"] = [](O& o, K k, H v) { o.start_pose = Text(k, v); };
    s["heading_weight"] = [](O& o, K k, H v) { o.heading_weight = Number(k, v); };
    s["use"] = [](O& o, K k, H v) { o.use = Text(k, v); };
    s["per_experiment"] = [](O& o, K, H v) { o.per_experiment = Truth(v); };
    s["no_heldout"] = [](O& o, K, H v) { o.no_heldout = Truth(v); };
    s["scan_range_scale"] = [](O& o, K k, H v) { o.scan_range_scale = Number(k, v); };
    s["ros2"] = [](O& o, K k, H v) { o.ros2 = Path(k, v); };
    s["controller"] = [](O& o, K k, H v) { o.controller = Text(k, v); };
    s["plot"] = [](O& o, K k, H v) { o.plot = Path(k, v); };
    s["report"] = [](O& o, K k, H v) { o.report = Path(k, v); };
    s["runs"] = [](O& o, K, H v) { o.data.push_back({kRunsName, TrajectoryFromArrays(v)}); };
    s["json"] = [](O&, K, H) {
      throw InvalidOptions("json=: the module returns the JSON (result.to_dict()); write it with the json module");
    };
    return s;
  }();
  return setters;
}

/// The failures of a calibration that gave a result (a batch, or a refined
/// fit that failed while the classic result stands), as the command line
/// prints them.
std::string FailureMessages(const api::CalibrateResult& r) {
  std::string message;
  for (const auto& out : r.results) {
    if (out.exit_status == 0) continue;
    std::string m = out.Message();
    while (!m.empty() && m.back() == '\n') m.pop_back();
    message += (message.empty() ? "" : "\n") + m;
  }
  return message.empty() ? std::string("umbmark: the calibration failed (see the result)") : message;
}

}  // namespace

Result CalibrateInProcess(const py::args& inputs, const py::kwargs& kwargs) {
  auto o = Options<api::CalibrateOptions>("calibrate", [&](api::CalibrateOptions& opts) {
    opts.inputs = Inputs(inputs, "DATA");
    ApplyKeywords(opts, kwargs, CalibrateSetters(), "calibrate");
  });
  std::optional<api::CalibrateResult> result;
  std::string before;  // a failed refined fit's report, printed before the error by the command line
  Failure f = Compute([&] {
    result = api::Calibrate(std::move(o), [&](const api::CalibrateOutcome& out) {
      if (out.failure == api::CalibrateOutcome::Failure::kRefine) before = out.Message();
    });
  });
  if (f.status == 3 && !before.empty()) f.message = before + f.message;
  if (f.status != 0) Raise(f.status, f.message, std::nullopt, "calibrate");
  std::string json = JsonText(api::ToJson(*result));
  if (result->exit_status != 0) Raise(result->exit_status, FailureMessages(*result), std::move(json), "calibrate");
  return {"calibrate", std::move(json)};
}

Result PredictInProcess(const py::args& inputs, const py::kwargs& kwargs) {
  using O = api::PredictOptions;
  using H = const py::handle&;
  using K = const std::string&;
  static const std::map<std::string, Setter<O>> setters = [] {
    std::map<std::string, Setter<O>> s;
    RobotSetters(s);
    s["kl"] = [](O& o, K k, H v) { o.k_L = Number(k, v); };
    s["kr"] = [](O& o, K k, H v) { o.k_R = Number(k, v); };
    s["path"] = [](O& o, K k, H v) { o.path = Text(k, v); };
    s["P0"] = [](O& o, K k, H v) { o.P0 = Numbers(k, v); };
    s["monte_carlo"] = [](O& o, K k, H v) {
      const double runs = Number(k, v);
      if (!(runs >= 2 && runs <= 1099511627776.0 && runs == std::floor(runs)))
        throw InvalidOptions(fmt::format("--monte-carlo: must be a number from 2 to 1.09951e+12 (got '{}')", runs));
      o.monte_carlo = static_cast<std::int64_t>(runs);
    };
    s["partitions"] = [](O& o, K k, H v) { o.partitions = WholeNumber(k, v); };
    s["seed"] = [](O& o, K k, H v) { o.seed = Seed(k, v); };
    s["threads"] = [](O& o, K k, H v) { o.threads = WholeNumber(k, v); };
    return s;
  }();
  auto o = Options<O>("predict", [&](O& opts) {
    if (!Inputs(inputs, "predict").empty()) throw InvalidOptions("predict takes no positional input");
    ApplyKeywords(opts, kwargs, setters, "predict");
    for (const char* required : {"kl", "kr", "path"})
      if (!kwargs.contains(required) || kwargs[required].is_none())
        throw InvalidOptions(fmt::format("{} is required", FlagOf(required)));
  });
  std::optional<api::PredictResult> r;
  const Failure f = Compute([&] { r = api::Predict(o); });
  if (f.status != 0) Raise(f.status, f.message, std::nullopt, "predict");
  return {"predict", JsonText(api::ToJson(*r))};
}

// One line per option: a table, about 45 lines.
Result SimulateInProcess(const py::args& inputs, const py::kwargs& kwargs) {
  using O = api::SimulateOptions;
  using H = const py::handle&;
  using K = const std::string&;
  static const std::map<std::string, Setter<O>> setters = {
      {"out", [](O& o, K k, H v) { o.out = Path(k, v); }},
      {"effect", [](O& o, K k, H v) {
         // Each --effect is one spec (its parameters are comma-separated).
         if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) {
           for (const py::handle e : v) o.effects.push_back(Text(k, e));
         } else {
           o.effects.push_back(Text(k, v));
         }
       }},
      {"seed", [](O& o, K k, H v) { o.seed = Seed(k, v); }},
      {"E_d", [](O& o, K k, H v) { o.sim.truth.E_d = Number(k, v); }},
      {"E_b", [](O& o, K k, H v) { o.sim.truth.E_b = Number(k, v); }},
      {"kl", [](O& o, K k, H v) { o.sim.truth.k_L = Number(k, v); }},
      {"kr", [](O& o, K k, H v) { o.sim.truth.k_R = Number(k, v); }},
      {"square_runs", [](O& o, K k, H v) { o.sim.square_runs_per_direction = WholeNumber(k, v); }},
      {"back_and_forth_runs", [](O& o, K k, H v) { o.sim.back_and_forth_runs = WholeNumber(k, v); }},
      {"free_runs", [](O& o, K k, H v) { o.sim.free_runs = WholeNumber(k, v); }},
      {"sample_rate", [](O& o, K k, H v) { o.sim.sample_rate_hz = Number(k, v); }},
      {"speed", [](O& o, K k, H v) { o.sim.speed_m_s = Number(k, v); }},
      {"turn_rate", [](O& o, K k, H v) { o.sim.turn_rate_rad_s = Number(k, v); }},
      {"pause", [](O& o, K k, H v) { o.sim.pause_s = Number(k, v); }},
      {"free_radius", [](O& o, K k, H v) { o.sim.free_radius_m = Number(k, v); }},
      {"gt_sigma_xy", [](O& o, K k, H v) { o.gt_sigma_xy_m = Number(k, v); }},
      {"gt_sigma_theta", [](O& o, K k, H v) { o.gt_sigma_theta_rad = Number(k, v); }},
      {"hide_gt_sigma", [](O& o, K, H v) { o.hide_gt_sigma = Truth(v); }},
      {"endpoint_squares", [](O& o, K, H v) { o.sim.endpoint_squares = Truth(v); }},
      {"truth_out", [](O& o, K k, H v) { o.truth_out = Path(k, v); }},
      {"force", [](O& o, K, H v) { o.force = Truth(v); }},
  };
  auto o = Options<O>("simulate", [&](O& opts) {
    opts.manifest = OneInput(inputs, "MANIFEST");
    ApplyKeywords(opts, kwargs, setters, "simulate");
  });
  std::optional<api::SimulateResult> r;
  const Failure f = Compute([&] { r = api::Simulate(std::move(o)); });
  if (f.status != 0) Raise(f.status, f.message, std::nullopt, "simulate");
  return {"simulate", JsonText(api::ToJson(*r))};
}

// One line per option: a table, about 50 lines.
Result FitNoiseInProcess(const py::args& inputs, const py::kwargs& kwargs) {
  // The plot, the report and the --ros2 file are written by the command
  // line; arrays (runs=) go to it as a trajectory CSV.
  for (const char* written : {"plot", "report", "ros2", "runs"})
    if (kwargs.contains(written) && !kwargs[written].is_none()) return RunExecutable({"fit-noise"}, inputs, kwargs);
  using O = api::FitNoiseOptions;
  using H = const py::handle&;
  using K = const std::string&;
  static const std::map<std::string, Setter<O>> setters = [] {
    std::map<std::string, Setter<O>> s;
    RobotSetters(s);
    s["distance"] = [](O& o, K k, H v) {
      const double d = Number(k, v);
      if (std::string err = api::CheckPlausibleFlag("--distance", "distance_m", d); !err.empty())
        throw InvalidOptions(err);
      o.distance_m = d;
    };
    s["meas_sigma"] = [](O& o, K k, H v) { o.meas_sigma = Numbers(k, v); };
    s["first_order"] = [](O& o, K, H v) { o.first_order = Truth(v); };
    s["ml"] = [](O& o, K, H v) { o.ml = Truth(v); };
    s["params"] = [](O& o, K k, H v) {
      o.params_file = Path(k, v);
      if (!std::filesystem::is_regular_file(o.params_file))
        throw InvalidOptions(fmt::format("--params: File does not exist: {}", o.params_file));
    };
    s["systematic"] = [](O& o, K k, H v) {
      o.systematic = Text(k, v);
      if (o.systematic != "none" && o.systematic != "estimate")
        throw InvalidOptions(fmt::format("--systematic: {} not in {{none,estimate}}", o.systematic));
    };
    s["controller"] = [](O& o, K k, H v) { o.controller = Text(k, v); };
    s["rate"] = [](O& o, K k, H v) { o.covariance.rate_hz = Number(k, v); };
    s["speed"] = [](O& o, K k, H v) { o.covariance.speed_mps = Number(k, v); };
    s["reml"] = [](O&, K, H) {};  // the default; checked against ml below
    s["json"] = [](O&, K, H) {
      throw InvalidOptions("json=: the module returns the JSON (result.to_dict()); write it with the json module");
    };
    return s;
  }();
  auto given = [&](const char* key) { return kwargs.contains(key) && !kwargs[key].is_none(); };
  auto o = Options<O>("fit-noise", [&](O& opts) {
    opts.inputs = Inputs(inputs, "DATA");
    if (opts.inputs.empty()) throw InvalidOptions("DATA is required");
    ApplyKeywords(opts, kwargs, setters, "fit_noise");
    for (const char* positive : {"rate", "speed"})
      if (given(positive) && !(Number(positive, kwargs[positive]) > 0))
        throw InvalidOptions(NotPositive(FlagOf(positive), Number(positive, kwargs[positive])));
  });
  const bool params_and_estimate = !o.params_file.empty() && given("systematic") && o.systematic == "estimate";
  const bool ml_and_reml = o.ml && given("reml") && Truth(kwargs["reml"]);
  std::optional<api::FitNoiseResult> r;
  const Failure f = Compute([&] {
    // The command's own checks (apps/cmd_fit_noise.cpp), said as it says them.
    if (params_and_estimate)
      throw InvalidOptions("--params and --systematic estimate contradict each other (give one)");
    if (ml_and_reml) throw InvalidOptions("--ml and --reml contradict each other (give one)");
    r = api::FitNoise(o);
  });
  if (f.status != 0) Raise(f.status, f.message, std::nullopt, "fit-noise");
  return {"fit-noise", JsonText(api::ToJson(*r))};
}

// umbmark.summarize: api::Summarize (with csv= or report=, the executable,
// which writes those files).
Result SummarizeInProcess(const py::args& inputs, const py::kwargs& kwargs) {
  for (const char* written : {"csv", "report"})
    if (kwargs.contains(written) && !kwargs[written].is_none()) return RunExecutable({"summarize"}, inputs, kwargs);
  using O = api::SummarizeOptions;
  using H = const py::handle&;
  using K = const std::string&;
  static const std::map<std::string, Setter<O>> setters = {
      {"threshold", [](O& o, K k, H v) {
         o.fleet.threshold = Number(k, v);
         if (!(o.fleet.threshold > 0))
           throw InvalidOptions(NotPositive("--threshold", o.fleet.threshold));
       }},
      {"json", [](O&, K, H) {
         throw InvalidOptions("json=: the module returns the JSON (result.to_dict()); write it with the json module");
       }},
  };
  auto o = Options<O>("summarize", [&](O& opts) {
    opts.inputs = Inputs(inputs, "CAL");
    if (opts.inputs.empty()) throw InvalidOptions("CAL is required");
    ApplyKeywords(opts, kwargs, setters, "summarize");
  });
  std::optional<api::SummarizeResult> r;
  const Failure f = Compute([&] { r = api::Summarize(o); });
  if (f.status != 0) Raise(f.status, f.message, std::nullopt, "summarize");
  return {"summarize", JsonText(api::ToJson(*r))};
}

// One line per option: a table, about 50 lines.
Result DiagnoseInProcess(const py::args& inputs, const py::kwargs& kwargs) {
  // The plot and the report are drawn by the command line (from the JSON).
  for (const char* drawn : {"plot", "report"})
    if (kwargs.contains(drawn) && !kwargs[drawn].is_none()) return RunExecutable({"diagnose"}, inputs, kwargs);
  using O = api::DiagnoseOptions;
  using H = const py::handle&;
  using K = const std::string&;
  static const std::map<std::string, Setter<O>> setters = {
      {"null_sims", [](O& o, K k, H v) { o.diag.null_simulations = WholeNumber(k, v); }},
      {"alpha", [](O& o, K k, H v) { o.diag.alpha = Number(k, v); }},
      {"min_heldout_shrink", [](O& o, K k, H v) { o.diag.min_heldout_shrink = Number(k, v); }},
      {"penalty", [](O& o, K k, H v) { o.diag.complexity_penalty_nats = Number(k, v); }},
      {"decisive", [](O& o, K k, H v) { o.diag.decisive_nats = Number(k, v); }},
      {"monotone_shrink", [](O& o, K, H v) { o.diag.keep_heldout_shrink = Truth(v); }},
      {"no_monotone_shrink", [](O& o, K, H v) { o.diag.keep_heldout_shrink = !Truth(v); }},
      {"fit_ground_truth_noise",
       [](O& o, K, H v) {
         if (Truth(v)) o.diag.baseline_fit.ground_truth = diag::GroundTruthNoiseSource::kFitted;
       }},
      {"hold_wheel_noise",
       [](O& o, K, H v) {
         if (Truth(v)) o.diag.baseline_fit.wheel = diag::WheelNoiseSource::kRepeats;
       }},
      {"fit_wheel_noise",
       [](O& o, K, H v) {
         if (Truth(v)) o.diag.baseline_fit.wheel = diag::WheelNoiseSource::kFitted;
       }},
      {"folds", [](O& o, K k, H v) { o.diag.pieces.folds = WholeNumber(k, v); }},
      {"piece_length", [](O& o, K k, H v) { o.diag.pieces.max_piece_length_m = Number(k, v); }},
      {"no_likelihood_tests", [](O& o, K, H v) { o.diag.likelihood_tests = !Truth(v); }},
      {"no_standstill_averaging", [](O& o, K, H v) { o.diag.pieces.average_standstills = !Truth(v); }},
      {"negligible", [](O& o, K k, H v) { o.diag.negligible = Number(k, v); }},
      {"max_effects", [](O& o, K k, H v) { o.diag.max_explanation_effects = WholeNumber(k, v); }},
      {"seed", [](O& o, K k, H v) { o.diag.seed = Seed(k, v); }},
      {"threads", [](O& o, K k, H v) { o.diag.threads = WholeNumber(k, v); }},
      {"where", [](O& o, K k, H v) { o.diag.where_top = WholeNumber(k, v); }},
      {"effects", [](O& o, K k, H v) { o.effects = List(k, v); }},
      {"baseline", [](O& o, K k, H v) { o.baseline = Path(k, v); }},
      {"baseline_other_robot", [](O& o, K, H v) { o.baseline_other_robot = Truth(v); }},
      {"kl", [](O& o, K k, H v) { o.k_L = Number(k, v); }},
      {"kr", [](O& o, K k, H v) { o.k_R = Number(k, v); }},
  };
  auto o = Options<O>("diagnose", [&](O& opts) {
    opts.manifest = OneInput(inputs, "MANIFEST");
    // As the command line: --hold-wheel-noise excludes --fit-wheel-noise.
    const auto given = [&](const char* key) { return kwargs.contains(key) && Truth(kwargs[key]); };
    if (given("hold_wheel_noise") && given("fit_wheel_noise"))
      throw InvalidOptions("--hold-wheel-noise excludes --fit-wheel-noise");
    ApplyKeywords(opts, kwargs, setters, "diagnose", {"fail_unexplained"});
  });
  std::optional<api::DiagnoseResult> r;
  const Failure f = Compute([&] { r = api::Diagnose(o); });
  if (f.status != 0) Raise(f.status, f.message, std::nullopt, "diagnose");
  std::string json = JsonText(api::ToJson(*r));
  const bool gate = kwargs.contains("fail_unexplained") && Truth(kwargs["fail_unexplained"]);
  if (gate && r->summary.verdict == "unexplained") {
    Raise(3, "umbmark: quality gate failed: the campaign leaves the model and no known effect explains the gap",
          std::move(json), "diagnose");
  }
  return {"diagnose", std::move(json)};
}

}  // namespace umbmark::python
