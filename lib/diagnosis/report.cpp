// Output of the diagnosis: contract JSON, readable report, gap bar chart
// (see diagnose.hpp).
#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "core/angles.hpp"
#include "diagnosis/advice.hpp"
#include "diagnosis/diagnose.hpp"
#include "diagnosis/report_given.hpp"
#include "report/svg_plot.hpp"

namespace umbmark::diag {

namespace {

nlohmann::json Num(double v) {
  if (!std::isfinite(v)) return nullptr;
  return v;
}

nlohmann::json Vec(const Eigen::Vector3d& v) { return {Num(v[0]), Num(v[1]), Num(v[2])}; }

nlohmann::json Mat(const Eigen::Matrix3d& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int i = 0; i < 3; ++i) rows.push_back({Num(m(i, 0)), Num(m(i, 1)), Num(m(i, 2))});
  return rows;
}

nlohmann::json ByKind(const std::array<double, kNumStatKinds>& a) {
  nlohmann::json j = nlohmann::json::object();
  for (int k = 0; k < kNumStatKinds; ++k) j[StatKindToString(static_cast<StatKind>(k))] = Num(a[k]);
  return j;
}

std::string FormatParam(const std::string& name, double v, const std::string& effect) {
  return FormatEffectParam(name, v, NAN, effect);
}
std::string FormatP(double p) { return FormatPValue(p); }

const Candidate* Winner(const DiagnoseSummary& s) {
  for (const auto& c : s.candidates)
    if (s.verdict == sim::EffectToString(c.effect)) return &c;
  return s.candidates.empty() || !s.candidates.front().identifiable ? nullptr : &s.candidates.front();
}

nlohmann::json ExplanationJson(const DiagnoseSummary& s) {
  nlohmann::json steps = nlohmann::json::array();
  for (const auto& e : s.explanation) {
    nlohmann::json params = nlohmann::json::object();
    for (const auto& [k, v] : e.params) params[k] = Num(v);
    steps.push_back({{"effect", sim::EffectToString(e.effect)},
                     {"params", params},
                     {"cumulative_shrink", Num(e.cumulative_shrink)},
                     {"cumulative_heldout_shrink", Num(e.cumulative_heldout_shrink)},
                     {"heldout_gain_nats", Num(e.heldout_gain_nats)},
                     {"earned_given_others_nats", Num(e.earned_given_others_nats)},
                     {"gap_after", Num(e.gap_after)},
                     {"size_mm", Num(e.size_mm)},
                     {"size_mrad", Num(e.size_mrad)},
                     {"relative_size", Num(e.relative_size)},
                     {"negligible", e.negligible},
                     {"not_decisive", e.not_decisive}});
    if (!e.outside_range.empty()) steps.back()["outside_range"] = e.outside_range;
    if (!e.spread_of_named.empty()) steps.back()["spread_of_named"] = e.spread_of_named;
    if (!e.size_pieces.empty()) steps.back()["size_pieces"] = e.size_pieces;
    if (!e.practical_floor.empty()) steps.back()["practical_floor"] = e.practical_floor;
    // An impossible fit is a symptom, never named (diagnose.cpp NameEffects).
    if (!e.unphysical.empty()) steps.back()["unphysical"] = e.unphysical;
  }
  return steps;
}

/// verdict.explained_model: the robot with the explanation's effects fitted,
/// or null (no explanation step, or a given model).
nlohmann::json ExplainedModelJson(const DiagnoseSummary& s) {
  if (!(s.explained_wheelbase_m > 0.0)) return nullptr;
  return {{"E_d", Num(s.explained_E_d)},
          {"E_b", Num(s.explained_E_b)},
          {"wheelbase_m", Num(s.explained_wheelbase_m)},
          {"wheel_diameter_left_m", Num(s.explained_diameter_left_m)},
          {"wheel_diameter_right_m", Num(s.explained_diameter_right_m)}};
}

nlohmann::json SymptomsJson(const DiagnoseSummary& s) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& e : s.symptoms) {
    nlohmann::json params = nlohmann::json::object();
    for (const auto& [k, v] : e.params) params[k] = Num(v);
    out.push_back({{"effect", sim::EffectToString(e.effect)},
                   {"params", params},
                   {"why", e.unphysical},
                   {"heldout_gain_nats", Num(e.heldout_gain_nats)}});
  }
  return out;
}

nlohmann::json WhereJson(const DiagnoseSummary& s, const std::vector<WhereItem>& items) {
  nlohmann::json where = nlohmann::json::array();
  for (const auto& w : items) {
    where.push_back({{"experiment", w.experiment + 1},
                     {"experiment_label", w.experiment >= 0 ? s.experiment_labels[w.experiment] : "all experiments"},
                     {"subset", w.subset},
                     {"statistic", StatKindToString(w.statistic)},
                     {"component", w.component},
                     {"size_se", Num(w.z)},
                     {"n", w.n}});
  }
  return where;
}

nlohmann::json CandidatesJson(const DiagnoseSummary& s) {
  nlohmann::json cands = nlohmann::json::array();
  for (const auto& c : s.candidates) {
    nlohmann::json params = nlohmann::json::object(), se = nlohmann::json::object();
    for (const auto& [k, v] : c.params) params[k] = Num(v);
    for (const auto& [k, v] : c.param_se) se[k] = Num(v);
    nlohmann::json& added = cands.emplace_back(nlohmann::json::object());
    if (c.clock.checked)
      added["clock_check"] = {{"supported", c.clock.supported},
                              {"moving_pieces", c.clock.pieces},
                              {"moving_value_s", Num(c.clock.value)},
                              {"moving_se_s", Num(c.clock.se)},
                              {"evidence", c.clock.text}};
    if (c.footprint.checked)
      added["footprint_check"] = {{"consistent", c.footprint.consistent},
                                  {"pairs", c.footprint.pairs},
                                  {"z", Num(c.footprint.z)},
                                  {"correlation", Num(c.footprint.correlation)},
                                  {"expected_correlation", Num(c.footprint.expected_correlation)},
                                  {"evidence", c.footprint.text}};
    added.update({{"effect", sim::EffectToString(c.effect)},
                     {"params", params},
                     {"shrink", Num(c.shrink)},
                     {"heldout_shrink", Num(c.heldout_shrink)},
                     {"params_se", se},
                     {"identifiable", c.identifiable},
                     {"weakly_identifiable", c.weak},
                     {"gap_after", Num(c.gap_after)},
                     {"heldout_loglik_gain_nats", Num(c.heldout_loglik_gain)},
                     {"evidence_nats", Num(c.evidence)},
                     {"loglik_gain_nats", Num(c.loglik_gain)},
                     {"lr_p_value", c.tested ? Num(c.lr_p_value) : nlohmann::json(nullptr)},
                     {"parameters", c.parameters},
                     {"E_d", Num(c.E_d)},
                     {"E_b", Num(c.E_b)},
                     {"gap_after_by_statistic", ByKind(c.gap_by_kind)},
                     {"note", c.note},
                     {"unphysical", UnphysicalFit(sim::EffectToString(c.effect), c.params, s.baseline.runs, c.param_se)}});
  }
  return cands;
}

/// A run id as in the file: a number when it is one.
nlohmann::json RunId(const std::string& id) {
  if (!id.empty() && id.size() < 16 && std::all_of(id.begin(), id.end(), [](char ch) { return ch >= '0' && ch <= '9'; }))
    return std::stoll(id);
  return id;
}

nlohmann::json RunFaultsJson(const DiagnoseSummary& s) {
  nlohmann::json out = nlohmann::json::array();
  for (const RunFault& f : s.run_faults)
    out.push_back({{"experiment", f.experiment + 1},
                   {"run", RunId(f.run_id)},
                   {"what", f.what},
                   {"statistic", f.statistic},
                   {"z", Num(f.z)},
                   {"threshold", Num(f.threshold)},
                   {"tau_s", Num(f.tau_s)},
                   {"dx_m", Num(f.dx_m)},
                   {"dy_m", Num(f.dy_m)}});
  return out;
}

nlohmann::json BaselineJson(const BaselineSummary& b) {
  nlohmann::json returns = nlohmann::json::array();
  for (const auto& r : b.returns) {
    returns.push_back({{"experiment", r.experiment + 1},
                       {"direction", r.direction},
                       {"runs", r.runs},
                       {"observed_mean", Vec(r.observed_mean)},
                       {"predicted_mean", Vec(r.predicted_mean)},
                       {"observed_covariance", Mat(r.observed_cov)},
                       {"predicted_covariance", Mat(r.predicted_cov)}});
  }
  nlohmann::json growth = nlohmann::json::array();
  for (const auto& g : b.growth) {
    growth.push_back({{"segment", PieceTypeToString(g.type)},
                      {"pieces", g.pieces},
                      {"mean_travel_m", Num(g.mean_travel_m)},
                      {"observed_rms", Vec(g.observed_rms)},
                      {"predicted_rms", Vec(g.predicted_rms)}});
  }
  return {{"E_d", Num(b.E_d)},
          {"E_b", Num(b.E_b)},
          {"k_L", Num(b.k_L)},
          {"k_R", Num(b.k_R)},
          {"sigma_xy_m", Num(b.sigma_xy_m)},
          {"sigma_theta_rad", Num(b.sigma_theta_rad)},
          {"ground_truth_noise_estimated", b.ground_truth_estimated},
          {"ground_truth_noise_source", b.ground_truth_source},
          {"standstill_scatter",
           b.standstill.measured ? nlohmann::json{{"sigma_xy_m", Num(b.standstill.sigma_xy_m)},
                                                  {"sigma_theta_rad", Num(b.standstill.sigma_theta_rad)},
                                                  {"lag1_sigma_xy_m", Num(b.standstill.lag1_sigma_xy_m)},
                                                  {"lag1_sigma_theta_rad", Num(b.standstill.lag1_sigma_theta_rad)},
                                                  {"robust_sigma_xy_m", Num(b.standstill.robust_sigma_xy_m)},
                                                  {"robust_sigma_theta_rad", Num(b.standstill.robust_sigma_theta_rad)},
                                                  {"plateau_lag_xy", b.standstill.lag_xy},
                                                  {"plateau_lag_theta", b.standstill.lag_theta},
                                                  {"plateau", b.standstill.plateau_xy && b.standstill.plateau_theta},
                                                  {"floored", b.standstill.floored_xy || b.standstill.floored_theta},
                                                  {"differences", b.standstill.differences},
                                                  {"standstills", b.standstill.standstills}}
                                 : nlohmann::json(nullptr)},
          {"ground_truth_noise_fitted_to_pieces",
           b.ground_truth_source == "standstills"
               ? nlohmann::json{{"sigma_xy_m", Num(b.pieces_sigma_xy_m)},
                                {"sigma_theta_rad", Num(b.pieces_sigma_theta_rad)}}
               : nlohmann::json(nullptr)},
          {"wheel_noise_source", b.wheel_noise_source},
          {"repeat_scatter",
           b.repeat.measured ? nlohmann::json{{"k_L", Num(b.repeat.k_L)},
                                              {"k_R", Num(b.repeat.k_R)},
                                              {"sd_k_L", Num(b.repeat.sd_k_L)},
                                              {"sd_k_R", Num(b.repeat.sd_k_R)},
                                              {"correlation", Num(b.repeat.correlation)},
                                              {"contrasts", b.repeat.contrasts},
                                              {"positions", b.repeat.positions},
                                              {"runs", b.repeat.runs},
                                              {"groups", b.repeat.groups}}
                             : nlohmann::json{{"not_measured", b.repeat.reason}}},
          {"wheel_noise_fitted_to_pieces",
           b.wheel_noise_source == "repeats" ? nlohmann::json{{"k_L", Num(b.pieces_k_L)}, {"k_R", Num(b.pieces_k_R)}}
                                             : nlohmann::json(nullptr)},
          {"start", b.start},
          {"return_error_noise_fit",
           b.return_fit ? nlohmann::json{{"k_L", Num(b.return_k_L)},
                                         {"k_R", Num(b.return_k_R)},
                                         {"k_L_ci95", {Num(b.return_k_L_ci[0]), Num(b.return_k_L_ci[1])}},
                                         {"k_R_ci95", {Num(b.return_k_R_ci[0]), Num(b.return_k_R_ci[1])}}}
                        : nlohmann::json(b.return_fit_note)},
          {"runs", b.runs},
          {"pieces", b.pieces},
          {"return_errors", returns},
          {"residual_growth", growth}};
}

// The readable report, one function per numbered section.
struct TextReport {
  std::string text;
  void line(const std::string& t) { text += t + "\n"; }
};

void RunFaultSection(TextReport& o, const DiagnoseSummary& s) {
  if (s.run_faults.empty()) {
    if (!s.run_fault_test.empty()) o.line("Faulty runs: none (" + s.run_fault_test + ")");
    o.line("");
    return;
  }
  o.line(fmt::format("Faulty runs: {} (left out; everything below is fitted without {}):", s.run_faults.size(),
                     s.run_faults.size() == 1 ? "it" : "them"));
  for (const RunFault& f : s.run_faults)
    o.line(fmt::format("  experiment {} run {}: {}", f.experiment + 1, f.run_id, f.what));
  o.line("  test: " + s.run_fault_test);
  o.line("");
}

/// The explained model's calibration beside the baseline's (a marker offset
/// the baseline leaves out walks its E_b to 1.2-1.3 on the June sessions:
/// the explained model's is the robot's).
void ExplainedModelLine(TextReport& o, const DiagnoseSummary& s) {
  if (!(s.explained_wheelbase_m > 0.0)) return;
  std::vector<std::string> named;
  for (const ExplanationStep& st : s.explanation) named.push_back(sim::EffectToString(st.effect));
  o.line(fmt::format("  with {} fitted (the explanation's last joint fit): E_d = {:.6f}   E_b = {:.6f}: wheelbase "
                     "{:.5f} m, wheel diameters {:.5f} / {:.5f} m (left / right): the robot with them accounted for (the "
                     "baseline above took part of them in); to confirm it, fix or model them, record again and "
                     "calibrate",
                     fmt::join(named, " + "), s.explained_E_d, s.explained_E_b, s.explained_wheelbase_m,
                     s.explained_diameter_left_m, s.explained_diameter_right_m));
}

void BaselineSection(TextReport& o, const DiagnoseSummary& s) {
  const BaselineSummary& b = s.baseline;
  o.line("1. Baseline (E_d, E_b, k_L, k_R; ground-truth noise " +
         std::string(b.ground_truth_source == "standstills" ? "from the scatter inside the standstills"
                     : b.ground_truth_estimated            ? "fitted with the wheel noise"
                                                           : "as stated in the manifest") +
         ")");
  o.line(fmt::format("  E_d = {:.6f}   E_b = {:.6f}   k_L = {:.3g} m^1/2   k_R = {:.3g} m^1/2", b.E_d, b.E_b, b.k_L, b.k_R));
  ExplainedModelLine(o, s);
  o.line(fmt::format("  ground truth: sigma_xy = {:.3g} mm, sigma_theta = {:.3g} mrad; start: {}", 1e3 * b.sigma_xy_m,
                     1e3 * b.sigma_theta_rad, b.start));
  if (b.standstill.measured)
    o.line(fmt::format("  ground truth's scatter inside standstills: sigma_xy = {:.3g} mm, sigma_theta = {:.3g} mrad, the "
                       "differences' sd ({} sample-to-sample differences in {} standstills; plateau at lags {} and {} "
                       "samples; robust core 1.4826 MAD: {:.3g} mm, {:.3g} mrad)",
                       1e3 * b.standstill.sigma_xy_m, 1e3 * b.standstill.sigma_theta_rad, b.standstill.differences,
                       b.standstill.standstills, b.standstill.lag_xy, b.standstill.lag_theta,
                       1e3 * b.standstill.robust_sigma_xy_m, 1e3 * b.standstill.robust_sigma_theta_rad));
  if (b.ground_truth_source == "standstills")
    o.line(fmt::format("  fitted to the pieces with the wheel noise instead: sigma_xy = {:.3g} mm, sigma_theta = {:.3g} "
                       "mrad (not used)",
                       1e3 * b.pieces_sigma_xy_m, 1e3 * b.pieces_sigma_theta_rad));
  if (!b.wheel_noise_source.empty() && b.wheel_noise_source != "given")
    o.line("  wheel noise: " + std::string(b.wheel_noise_source == "repeats" ? "held at " : "fitted with E_d, E_b; ") +
           RepeatNoiseSummary(b.repeat) +
           (b.wheel_noise_source == "repeats"
                ? fmt::format("; fitted jointly with E_d, E_b instead: k_L = {:.3g}, k_R = {:.3g} m^1/2 (not used)",
                              b.pieces_k_L, b.pieces_k_R)
                : std::string()));
  for (const auto& w : s.warnings) o.line("  WARNING: " + w);
  o.line(fmt::format("  {} runs, {} pieces", b.runs, b.pieces));
  if (b.return_fit)
    o.line(fmt::format("  cross-check, fit-noise on the runs' return errors: k_L = {:.3g} [{:.3g}, {:.3g}], k_R = {:.3g} "
                       "[{:.3g}, {:.3g}] m^1/2 (95%)",
                       b.return_k_L, b.return_k_L_ci[0], b.return_k_L_ci[1], b.return_k_R, b.return_k_R_ci[0],
                       b.return_k_R_ci[1]));
  else if (!b.return_fit_note.empty())
    o.line("  " + b.return_fit_note);
  o.line("  return errors per experiment and direction (mean x, y [mm], theta [mrad]; sd from the covariance):");
  for (const auto& r : b.returns) {
    o.line(fmt::format("    exp {} {:<10} {:>3} runs  observed ({:+8.2f}, {:+8.2f}, {:+8.2f}) sd ({:6.2f}, {:6.2f}, {:6.2f})",
                       r.experiment + 1, r.direction, r.runs, 1e3 * r.observed_mean[0], 1e3 * r.observed_mean[1],
                       1e3 * r.observed_mean[2], 1e3 * std::sqrt(r.observed_cov(0, 0)),
                       1e3 * std::sqrt(r.observed_cov(1, 1)), 1e3 * std::sqrt(r.observed_cov(2, 2))));
    o.line(fmt::format("    {:<24}  predicted ({:+8.2f}, {:+8.2f}, {:+8.2f}) sd ({:6.2f}, {:6.2f}, {:6.2f})", "",
                       1e3 * r.predicted_mean[0], 1e3 * r.predicted_mean[1], 1e3 * r.predicted_mean[2],
                       1e3 * std::sqrt(r.predicted_cov(0, 0)), 1e3 * std::sqrt(r.predicted_cov(1, 1)),
                       1e3 * std::sqrt(r.predicted_cov(2, 2))));
  }
  o.line("  residual growth per segment type (RMS per piece x [mm], y [mm], theta [mrad]: observed / predicted):");
  for (const auto& g : b.growth) {
    o.line(fmt::format("    {:<13} {:>5} pieces, {:6.3f} m each: x {:6.2f}/{:6.2f}  y {:6.2f}/{:6.2f}  theta {:6.2f}/{:6.2f}",
                       PieceTypeToString(g.type), g.pieces, g.mean_travel_m, 1e3 * g.observed_rms[0],
                       1e3 * g.predicted_rms[0], 1e3 * g.observed_rms[1], 1e3 * g.predicted_rms[1],
                       1e3 * g.observed_rms[2], 1e3 * g.predicted_rms[2]));
  }
  o.line("");
}

void WhereLines(TextReport& o, const std::vector<WhereItem>& items) {
  for (const auto& w : items) {
    o.line(fmt::format("    {:+8.2f} SE  {:<6} {:<40} {:<11} {}", w.z,
                       w.experiment >= 0 ? fmt::format("exp {}", w.experiment + 1) : std::string("all"), w.subset,
                       StatKindToString(w.statistic), w.component));
  }
}

void WhereSection(TextReport& o, const DiagnoseSummary& s) {
  o.line(fmt::format("2. Where: gap score G = {:.2f} (null median {:.2f}, {:.0f}% quantile {:.2f}); p = {} from {} "
                     "simulations of the baseline",
                     s.gap_score, s.null_median, 100.0 * (1.0 - s.alpha), s.null_quantile_alpha, FormatP(s.score_p_value),
                     s.null_simulations));
  if (s.tests > 0)
    o.line(fmt::format("   likelihood-ratio tests of the candidates: p = {} (Bonferroni over {}); combined p = {} "
                       "-> {}",
                       FormatP(s.tests_p_value), s.tests, FormatP(s.p_value), s.significant ? "significant" : "not significant"));
  else
    o.line(fmt::format("   p = {} -> {}", FormatP(s.p_value), s.significant ? "significant" : "not significant"));
  WhereLines(o, s.where);
  o.line("");
}

void CandidatesSection(TextReport& o, const DiagnoseSummary& s) {
  const BaselineSummary& b = s.baseline;
  o.line("3. Which: candidate effects, each fitted alone on top of the baseline (best first; shrink = 1 - gap after "
         "/ gap before; the values to use are the explanation's, below)");
  o.line(fmt::format("    {:<20} {:>8} {:>9} {:>11} {:>10}  {}", "effect", "shrink", "held-out", "evidence", "LR p",
                     "parameters"));
  for (const auto& c : s.candidates) {
    std::string params;
    for (const auto& [k, v] : c.params) {
      const auto se = c.param_se.find(k);
      params += FormatEffectParam(k, v, se != c.param_se.end() ? se->second : NAN, sim::EffectToString(c.effect)) + "  ";
    }
    if (!c.note.empty()) params += "(" + c.note + ")";
    if (c.clock.checked) params += " [" + c.clock.text + "]";
    if (c.footprint.checked && !c.footprint.consistent) params += " [" + c.footprint.text + "]";
    if (const auto why = UnphysicalFit(sim::EffectToString(c.effect), c.params, b.runs, c.param_se); !why.empty())
      params += " IMPOSSIBLE VALUE, a symptom (the gap is something else): " + why;
    o.line(fmt::format("    {:<20} {:>8.3f} {:>9.3f} {:>9.1f} n {:>10}  {}", sim::EffectToString(c.effect), c.shrink,
                       c.heldout_shrink, c.evidence, c.tested ? FormatP(c.lr_p_value) : std::string("-"),
                       params));
  }
  o.line("");
}

void ExplanationSection(TextReport& o, const DiagnoseSummary& s) {
  if (!s.explanation.empty()) {
    o.line("");
    o.line(fmt::format("   Stepwise explanation (effects added one at a time, fitted jointly; stops: {}):",
                       s.explanation_stop));
    o.line("    step effect                 cumulative shrink  held-out   size (mm / mrad, relative)   parameters");
    int k = 0;
    for (const auto& e : s.explanation) {
      std::string params;
      for (const auto& [n, v] : e.params) params += FormatParam(n, v, sim::EffectToString(e.effect)) + "  ";
      // A noise effect's size is the growth of the spread of one piece type
      // (explanation.hpp), printed as such.
      const std::string rel = e.size_pieces.empty()
                                  ? fmt::format("x {:<5.{}f}", e.relative_size,
                                                RelativeSizeDecimals(e.relative_size, s.negligible_threshold))
                                  : fmt::format("+{:.0f}% sd of {} pieces", 100.0 * e.relative_size, e.size_pieces);
      o.line(fmt::format("    {:>4} {:<22} {:>17.0f}% {:>8.0f}%   {:>7.2f} / {:>6.2f}, {}{}  {}", ++k,
                         sim::EffectToString(e.effect), 100.0 * e.cumulative_shrink, 100.0 * e.cumulative_heldout_shrink,
                         e.size_mm, e.size_mrad, rel,
                         !e.unphysical.empty() ? std::string(" (impossible value: a symptom)")
                         : !e.practical_floor.empty() ? " (negligible: " + e.practical_floor + ")"
                         : e.negligible                 ? std::string(" (negligible)")
                         : e.not_decisive ? fmt::format(" (not decisive: {:+.1f} nats given the others)",
                                                        e.earned_given_others_nats)
                         : !e.outside_range.empty() ? std::string(" (outside the physical range: not named)")
                         : !e.spread_of_named.empty()
                             ? fmt::format(" ({}'s spread: not named)", e.spread_of_named)
                             : std::string(),
                         params));
    }
    for (const auto& e : s.symptoms) {
      std::string params;
      for (const auto& [n, v] : e.params) params += FormatParam(n, v, sim::EffectToString(e.effect)) + "  ";
      o.line(fmt::format("    symptom, not a step: {} {}-- {}", sim::EffectToString(e.effect), params, e.unphysical));
    }
    const std::string against = ShrinkReferenceClause(s.shrink_reference, s.heldout_shrink_against_baseline);
    o.line(fmt::format("    unexplained on held-out runs: {:.0f}%{}; negligible = size below {:.2g} x the noise of one "
                       "piece (<= 1 m of travel or a spot turn); for a noise effect, widening the pose spread of the "
                       "pieces it acts on by less than {:.0f}% (median per piece type, the type it widens most)",
                       100.0 * s.unexplained_fraction, against, s.negligible_threshold,
                       100.0 * s.negligible_threshold));
  }
  o.line("");
}

void VerdictSection(TextReport& o, const DiagnoseSummary& s) {
  o.line("4. Verdict: " + s.verdict +
         (s.verdict_effects.size() > 1 ? fmt::format(" (effects: {})", fmt::join(s.verdict_effects, ", ")) : ""));
  o.line("  " + s.verdict_reason);
  if (!s.remaining_where.empty()) {
    o.line(fmt::format("  what is left after the explanation, where (G = {:.1f} with its effects fitted, null {:.0f}% "
                       "quantile {:.1f}):",
                       s.remaining_gap_score, 100.0 * (1.0 - s.alpha), s.null_quantile_alpha));
    WhereLines(o, std::vector<WhereItem>(s.remaining_where.begin(),
                                         s.remaining_where.begin() + std::min<std::ptrdiff_t>(6, std::ssize(s.remaining_where))));
  }
  for (const auto& i : s.indistinguishable) o.line("  cannot tell apart: " + i);
  for (const auto& n : s.notes) o.line("  note: " + n);
  if (const Candidate* w = Winner(s); w && s.verdict != "none")
    o.line(std::string("  evidence for ") + sim::EffectToString(w->effect) + ": " +
           EvidenceInWords(w->heldout_loglik_gain, w->evidence, w->heldout_shrink, IsNoiseEffect(w->effect)));
  o.line("");
  o.line("What to do next:");
  for (std::size_t i = 0; i < s.next_steps.size(); ++i) o.line(fmt::format("  {}. {}", i + 1, s.next_steps[i]));
  o.line("");
  if (const std::string given = GivenModelReport(s); !given.empty()) {
    o.text += given;
    o.line("");
  }
}

void TimingSection(TextReport& o, const DiagnoseSummary& s) {
  o.line("Time per stage:");
  for (const auto& [k, v] : s.timings) o.line(fmt::format("  {:<42} {:8.3f} s", k, v));
}

}  // namespace

nlohmann::json DiagnoseToJson(const DiagnoseSummary& s) {
  nlohmann::json timing = nlohmann::json::object();
  for (const auto& [k, v] : s.timings) timing[k] = Num(v);
  nlohmann::json j = {{"gap",
           {{"score", Num(s.gap_score)},
            {"p_value", Num(s.p_value)},
            {"where", WhereJson(s, s.where)},
            {"score_p_value", Num(s.score_p_value)},
            {"tests_p_value", Num(s.tests_p_value)},
            {"tests", s.tests},
            {"alpha", s.alpha},
            {"significant", s.significant},
            {"null_simulations", s.null_simulations},
            {"null_median", Num(s.null_median)},
            {"null_quantile_1_minus_alpha", Num(s.null_quantile_alpha)},
            {"by_statistic", ByKind(s.gap_by_kind)},
            {"seed", s.seed}}},
          {"candidates", CandidatesJson(s)},
          {"explanation", ExplanationJson(s)},
          {"symptoms", SymptomsJson(s)},
          {"summary", s.summary},
          {"verdict",
           {{"effect", s.verdict},
            {"effects", s.verdict_effects},
            {"unexplained_fraction", Num(s.unexplained_fraction)},
            {"shrink_reference", s.shrink_reference},
            {"heldout_shrink_against_baseline", Num(s.heldout_shrink_against_baseline)},
            {"remainder_significant", s.remainder_significant},
            {"remainder_mean_share", Num(s.remainder_mean_share)},
            {"remaining_score", Num(s.remaining_gap_score)},
            {"remaining_where", WhereJson(s, s.remaining_where)},
            {"reason", s.verdict_reason},
            {"negligible_threshold", Num(s.negligible_threshold)},
            {"explained_model", ExplainedModelJson(s)}}},
          {"run_faults", RunFaultsJson(s)},
          {"warnings", s.warnings},
          {"run_fault_test", s.run_fault_test},
          {"indistinguishable", s.indistinguishable},
          {"baseline", BaselineJson(s.baseline)},
          {"experiments", s.experiment_labels},
          {"piece_residuals", PieceResidualsToJson(s.piece_residuals)},
          {"notes", s.notes},
          {"next_steps", s.next_steps},
          {"timing_s", timing}};
  AddGivenModelJson(s, j);
  return j;
}

std::string DiagnoseReport(const DiagnoseSummary& s) {
  TextReport o;
  o.line("Diagnosis of the sim-to-real gap");
  for (const auto& l : s.experiment_labels) o.line("  experiment " + l);
  o.line("");
  // What is wrong and what to do, in plain words, before the statistics.
  if (!s.summary.empty()) {
    o.line("In short: " + s.summary);
    o.line("");
  }
  RunFaultSection(o, s);
  BaselineSection(o, s);
  WhereSection(o, s);
  CandidatesSection(o, s);
  ExplanationSection(o, s);
  VerdictSection(o, s);
  TimingSection(o, s);
  return o.text;
}

std::string DiagnosePlotSvg(const DiagnoseSummary& s) {
  // Gaps span orders of magnitude (a time offset can score 1e6, noise 1):
  // bars show log10(1 + gap) per statistic kind.
  std::vector<std::string> labels;
  std::vector<double> before, after;
  const Candidate* w = Winner(s);
  for (int k = 0; k < kNumStatKinds; ++k) {
    labels.push_back(StatKindToString(static_cast<StatKind>(k)));
    before.push_back(std::log10(1.0 + s.gap_by_kind[k]));
    after.push_back(std::log10(1.0 + (w ? w->gap_by_kind[k] : s.gap_by_kind[k])));
  }
  const std::string name = w ? fmt::format("with {}", sim::EffectToString(w->effect)) : "no candidate";
  const std::string chart =
      io::SvgBarChart(fmt::format("log10(1 + gap) per statistic, gap = sum (|z| - 2)^2; verdict: {}", s.verdict),
                      labels, {before, after}, {"baseline", name}, {"#d62728", "#2ca02c"});
  return io::SvgDocument(760, 40 + 28.0 * kNumStatKinds + 60, {chart});
}

}  // namespace umbmark::diag
