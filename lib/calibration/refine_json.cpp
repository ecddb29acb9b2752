// The contract's `refined` JSON object and a short readable report for a
// RefineSummary (see refine.hpp). The library builds them; apps print them.
#include <cmath>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "calibration/refine.hpp"

namespace umbmark {

namespace {

nlohmann::json Number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json IntervalJson(const RefineInterval& iv) {
  return {{"value", Number(iv.value)}, {"sigma", Number(iv.sigma)}, {"low", Number(iv.low)}, {"high", Number(iv.high)}};
}

}  // namespace

nlohmann::json RefinedToJson(const RefineSummary& s) {
  nlohmann::json j;
  j["input"] = RefineInputKindToString(s.input);
  j["parameters"] = {{"wheelbase_m", s.refined.wheelbase_m},
                     {"wheel_diameter_left_m", s.refined.wheel_diameter_left_m},
                     {"wheel_diameter_right_m", s.refined.wheel_diameter_right_m}};
  nlohmann::json cov = nlohmann::json::array();
  for (int i = 0; i < 3; ++i) cov.push_back({s.covariance(i, 0), s.covariance(i, 1), s.covariance(i, 2)});
  j["covariance"] = cov;
  j["covariance_order"] = s.covariance_order;
  j["covariance_method"] = s.covariance_method;
  j["final_cost"] = s.final_cost;
  j["reduced_chi2"] = Number(s.reduced_chi2);
  j["E_b"] = s.E_b;
  j["E_d"] = s.E_d;
  j["E_s"] = s.E_s;
  j["c_L"] = s.c_L;
  j["c_R"] = s.c_R;
  j["scale_free"] = s.scale_free;
  j["confidence"] = s.confidence;
  j["quantile"] = s.quantile;
  j["dof"] = s.dof ? nlohmann::json(*s.dof) : nlohmann::json(nullptr);
  nlohmann::json iv = {{"wheelbase_m", IntervalJson(s.intervals.wheelbase_m)},
                       {"wheel_diameter_right_m", IntervalJson(s.intervals.wheel_diameter_right_m)},
                       {"wheel_diameter_left_m", IntervalJson(s.intervals.wheel_diameter_left_m)},
                       {"E_d", IntervalJson(s.intervals.E_d)},
                       {"E_b", IntervalJson(s.intervals.E_b)}};
  if (s.scale_free) iv["E_s"] = IntervalJson(s.intervals.E_s);
  j["intervals"] = iv;
  j["solver"] = {{"termination_type", s.solver.termination_type},
                 {"message", s.solver.message},
                 {"brief_report", s.solver.brief_report},
                 {"usable", s.solver.usable},
                 {"iterations", s.solver.iterations},
                 {"initial_cost", s.solver.initial_cost},
                 {"final_cost", s.solver.final_cost},
                 {"residual_evaluations", s.solver.residual_evaluations},
                 {"jacobian_evaluations", s.solver.jacobian_evaluations},
                 {"solve_time_s", s.solver.solve_time_s}};
  const RefineIdentifiability& id = s.identifiability;
  j["identifiability"] = {{"free_parameters", id.free_parameters},
                          {"fixed_parameters", id.fixed_parameters},
                          {"singular_values", id.singular_values},
                          {"condition_number", Number(id.condition_number)},
                          {"sigma", id.sigma},
                          {"determined", id.determined},
                          {"undetermined", id.undetermined},
                          {"rank_deficient", id.rank_deficient},
                          {"message", id.message}};
  nlohmann::json groups = nlohmann::json::array();
  for (const auto& g : s.groups) {
    groups.push_back({{"set", g.set},
                      {"direction", g.direction},
                      {"side_m", g.side_m},
                      {"runs", g.runs},
                      {"heading", g.heading},
                      {"method", g.method},
                      {"sigma_x_m", g.sigma_x_m},
                      {"sigma_y_m", g.sigma_y_m},
                      {"sigma_theta_rad", g.sigma_theta_rad}});
  }
  if (s.input == RefineInputKind::kReturnErrors) j["weighting"] = groups;
  j["runs"] = s.runs;
  j["residuals"] = s.residuals;
  if (s.input == RefineInputKind::kTrajectories) {
    j["sampled_poses"] = s.sampled_poses;
    const auto& t = s.trajectory_settings;
    j["trajectory_settings"] = {{"sampling", t.sampling},
                                {"start_pose", t.start_pose},
                                {"heading_length_m_per_rad", t.heading_length_m},
                                {"loss", t.loss},
                                {"loss_scale_m", t.loss_scale_m}};
  }
  j["notes"] = s.notes;
  return j;
}

std::string RefineReport(const RefineSummary& s) {
  std::string out;
  const int pct = static_cast<int>(std::lround(100.0 * s.confidence));
  auto line = [&](const char* name, const RefineInterval& iv, int digits) {
    out += fmt::format("  {:<24} {:.{}f}  [{:.{}f}, {:.{}f}] ({}%)\n", name, iv.value, digits, iv.low, digits,
                       iv.high, digits, pct);
  };
  out += fmt::format("refined calibration ({}, {} runs, {} residuals):\n", RefineInputKindToString(s.input), s.runs,
                     s.residuals);
  if (s.input == RefineInputKind::kTrajectories) {
    const auto& t = s.trajectory_settings;
    out += fmt::format("  poses {}, run frames {}, heading {:.3g} m/rad, loss {} ({} m)\n", t.sampling, t.start_pose,
                       t.heading_length_m, t.loss, t.loss_scale_m);
  }
  line("wheelbase_m", s.intervals.wheelbase_m, 6);
  line("wheel_diameter_right_m", s.intervals.wheel_diameter_right_m, 6);
  line("wheel_diameter_left_m", s.intervals.wheel_diameter_left_m, 6);
  line("E_d", s.intervals.E_d, 6);
  line("E_b", s.intervals.E_b, 6);
  if (s.scale_free) line("E_s", s.intervals.E_s, 6);
  out += fmt::format("  identifiability: {}\n", s.identifiability.message);
  out += fmt::format("  solver: {}\n", s.solver.brief_report);
  for (const auto& n : s.notes) out += fmt::format("  note: {}\n", n);
  return out;
}

}  // namespace umbmark
