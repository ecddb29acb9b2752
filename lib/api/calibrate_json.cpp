// The JSON of `umbmark calibrate` (see calibrate.hpp; the keys are the
// contract's, docs/formats.md).
#include <string>

#include "api/calibrate.hpp"
#include "api/json.hpp"

namespace umbmark::api {

namespace {

constexpr const char* kHeldoutSkipped = "skipped";

nlohmann::json JsonCluster(const ClusterStats& c) {
  return {{"n", c.n}, {"x_m", c.x_cg_m}, {"y_m", c.y_cg_m}, {"r_m", c.r_cg_m}, {"sigma_m", c.sigma_m}, {"sem_m", c.sem_m}};
}

nlohmann::json JsonEstimate(const UmbmarkEstimate& e) {
  return {{"alpha_rad", e.alpha_rad}, {"beta_rad", e.beta_rad}, {"R_m", JsonNumber(e.R_m)}, {"E_b", e.E_b}, {"E_d", e.E_d}};
}

/// JSON `heldout_error`: each method's held-out error and parameters.
nlohmann::json JsonHeldout(const HeldoutComparison& h) {
  nlohmann::json methods = nlohmann::json::object();
  for (const auto& m : h.methods) {
    methods[m.method] = {{"mean_m", JsonNumber(m.mean_m)}, {"sem_m", JsonNumber(m.sem_m)},
                         {"rms_m", JsonNumber(m.rms_m)},   {"folds", m.folds},
                         {"failed_folds", m.failed_folds}, {"parameters", JsonParams(m.parameters)}};
  }
  return methods;
}

/// Each run's return error, outlier score and flags (JSON `runs`).
nlohmann::json JsonRuns(const std::vector<CalibratedRun>& runs) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& f : runs) {
    nlohmann::json jr = {{"run", f.run},         {"direction", f.direction}, {"ex_m", f.ex_m},
                         {"ey_m", f.ey_m},       {"outlier", f.outlier},     {"excluded", f.excluded},
                         {"rejected", f.rejected}};
    jr["etheta_rad"] = f.etheta_rad ? nlohmann::json(*f.etheta_rad) : nlohmann::json(nullptr);
    jr["outlier_score"] = f.outlier_score ? nlohmann::json(*f.outlier_score) : nlohmann::json(nullptr);
    out.push_back(jr);
  }
  return out;
}

/// JSON `heldout`: the scheme, the recommendation's expected error and the
/// runner-up (nulls where no_heldout skipped the comparison or there is
/// none).
nlohmann::json JsonHeldoutSummary(const HeldoutComparison& h) {
  const bool skipped = h.scheme == kHeldoutSkipped;
  const nlohmann::json null(nullptr);
  return {{"scheme", h.scheme},
          {"measure", h.measure},
          {"left_out", h.left_out},
          {"sessions", h.sessions},
          {"baseline", h.baseline.empty() ? null : nlohmann::json(h.baseline)},
          {"why", h.why},
          {"expected_error_m", skipped ? null : JsonNumber(h.expected_error_m)},
          {"expected_error_sem_m", skipped ? null : JsonNumber(h.expected_error_sem_m)},
          {"runner_up", h.runner_up.empty() ? null : nlohmann::json(h.runner_up)},
          {"runner_up_difference_m", h.runner_up.empty() ? null : JsonNumber(h.runner_up_difference_m)},
          {"runner_up_difference_sem_m", h.runner_up.empty() ? null : JsonNumber(h.runner_up_difference_sem_m)},
          {"checked", h.checked},
          {"not_checked", h.not_checked},
          {"notes", h.notes}};
}

/// JSON `evaluation`: the odometry against the ground truth before and
/// after the classic correction (trajectory input).
/// JSON `design_advice` (formats.md): the same analysis as plan --check's
/// cannot_separate, and record_more.
nlohmann::json JsonDesignAdvice(const planning::DesignAdvice& a) {
  nlohmann::json conf = nlohmann::json::array(), more = nlohmann::json::array();
  for (const auto& c : a.confusions)
    conf.push_back({{"what", c.what}, {"kind", c.kind}, {"add", c.add}, {"correlation", c.correlation}});
  for (const auto& m : a.check.record_more)
    more.push_back({{"quantity", m.quantity},
                    {"correction", m.correction},
                    {"half_width", m.half_width},
                    {"extra_runs_per_direction", m.extra_runs_per_direction},
                    {"half_width_after", m.half_width_after},
                    {"time_s", m.time_s},
                    {"side_m", m.side_m}});
  nlohmann::json j = {{"available", a.available}, {"cannot_separate", conf}, {"record_more", more}};
  if (!a.available) j["note"] = a.note;
  return j;
}

nlohmann::json JsonAfterCorrection(const AfterCorrection& a) {
  return {{"before", JsonEvaluationSummary(a.before)},
          {"after", JsonEvaluationSummary(a.after)},
          {"before_runs", JsonEvaluationRuns(a.before)},
          {"after_runs", JsonEvaluationRuns(a.after)},
          {"E_max_syst_after_m", a.E_max_syst_m},
          {"centres_of_gravity_after", {{"cw", JsonCluster(a.cw)}, {"ccw", JsonCluster(a.ccw)}}},
          {"sem_after_m", a.sem_m},
          {"second_pass_worthwhile", a.second_pass_worthwhile}};
}

}  // namespace

nlohmann::json ToJson(const CalibrateUnitResult& u) {
  const CalibrateJobResult& r = u.job;
  const UmbmarkSummary& s = r.umbmark;
  nlohmann::json j;
  j["input"] = u.input;
  if (!u.robot_id.empty()) j["robot_id"] = u.robot_id;  // for summarize
  j["method"] = u.method;
  j["estimator"] = u.estimator;
  j["side_m"] = u.side_m;
  j["integrator"] = u.integrator;
  j["E_d"] = u.E_d;
  j["E_b"] = u.E_b;
  j["alpha_rad"] = u.alpha_rad;
  j["beta_rad"] = u.beta_rad;
  j["R_m"] = JsonNumber(u.R_m);
  j["c_L"] = u.c_L;
  j["c_R"] = u.c_R;
  j["E_max_syst_m"] = u.E_max_syst_m;
  j["parameters"] = JsonParams(u.parameters);
  j["recorded_parameters"] = JsonParams(u.recorded_parameters);
  j["estimates"] = {{"x", JsonEstimate(s.from_x)},
                    {"y", JsonEstimate(s.from_y)},
                    {"spread", {{"E_d", s.spread_E_d}, {"E_b", s.spread_E_b}}}};
  j["centres_of_gravity"] = {{"cw", JsonCluster(s.cw)}, {"ccw", JsonCluster(s.ccw)}};
  j["sem_m"] = u.sem_m;
  j["three_sem_m"] = u.three_sem_m;
  j["compensation_worthwhile"] = u.compensation_worthwhile;
  j["runs"] = JsonRuns(u.runs);
  j["experiments"] = u.experiments;
  if (u.refine_error) j["refine_error"] = *u.refine_error;
  if (r.refined) {
    j["refined"] = RefinedToJson(*r.refined);
    if (r.refined_evaluation) {
      j["refined"]["evaluation"] = {{"summary", JsonEvaluationSummary(*r.refined_evaluation)},
                                    {"runs", JsonEvaluationRuns(*r.refined_evaluation)}};
    }
  }
  // no_heldout: both keys say so instead of naming a method.
  const HeldoutComparison& h = u.heldout;
  const bool skipped = h.scheme == kHeldoutSkipped;
  j["heldout_error"] = skipped ? nlohmann::json(kHeldoutSkipped) : JsonHeldout(h);
  j["heldout"] = JsonHeldoutSummary(h);
  j["recommended"] = skipped                ? nlohmann::json(kHeldoutSkipped)
                     : h.recommended.empty() ? nlohmann::json(nullptr)
                                             : nlohmann::json(h.recommended);
  if (r.refined && h.Find("refined")) j["refined"]["heldout_error"] = JsonHeldout(h)["refined"];
  const ModelCheck& check = u.model_check;
  j["model_check"] = check.available ? nlohmann::json{{"reduced_chi2", check.reduced_chi2},
                                                      {"dof", check.dof},
                                                      {"p_value", check.p_value}}
                                     : nlohmann::json(nullptr);
  j["outputs_use"] = {{"method", u.outputs_use.method},
                      {"parameters", JsonParams(u.outputs_use.parameters)},
                      {"why", u.outputs_use.why},
                      {"scale_source", u.outputs_use.scale_source}};
  j["warnings"] = u.warnings;
  j["design_advice"] = JsonDesignAdvice(u.design_advice);
  if (r.evaluation) j["evaluation"] = JsonAfterCorrection(*r.evaluation);
  return j;
}

nlohmann::json ToJson(const CalibrateResult& result) {
  if (!result.batch && result.results.size() == 1 && result.results.front().result)
    return ToJson(*result.results.front().result);
  nlohmann::json results = nlohmann::json::array();
  for (const auto& o : result.results)
    results.push_back(o.result ? ToJson(*o.result) : nlohmann::json{{"input", o.input}, {"error", o.error}});
  return {{"results", results}, {"failed", result.failed}, {"warnings", result.warnings}};
}

}  // namespace umbmark::api
