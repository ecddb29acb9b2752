// Plausibility gates on calibration results (see plausibility.hpp).
#include "calibration/plausibility.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace umbmark {
namespace {

bool Positive(double v) { return std::isfinite(v) && v > 0.0; }

void CheckMultiplier(const char* name, double m, PlausibilityReport& r) {
  if (!std::isfinite(m)) {
    r.failures.push_back(fmt::format("{} is not a finite number", name));
  } else if (!(m > kMinMultiplier && m < kMaxMultiplier)) {
    r.failures.push_back(fmt::format("{} = {:.4g} lies outside ({}, {}): the parameter would change by more than a "
                                     "factor of two",
                                     name, m, kMinMultiplier, kMaxMultiplier));
  }
}

void CheckParams(const char* what, const RobotParams& p, PlausibilityReport& r) {
  if (!Positive(p.wheelbase_m))
    r.failures.push_back(fmt::format("the {} wheelbase is {:.4g} m, not a positive length", what, p.wheelbase_m));
  if (!Positive(p.wheel_diameter_left_m))
    r.failures.push_back(
        fmt::format("the {} left wheel diameter is {:.4g} m, not a positive length", what, p.wheel_diameter_left_m));
  if (!Positive(p.wheel_diameter_right_m))
    r.failures.push_back(
        fmt::format("the {} right wheel diameter is {:.4g} m, not a positive length", what, p.wheel_diameter_right_m));
}

void AddHint(PlausibilityReport& r, std::string hint) {
  if (std::find(r.hints.begin(), r.hints.end(), hint) == r.hints.end()) r.hints.push_back(std::move(hint));
}

}  // namespace

std::string PlausibilityReport::Message() const {
  std::string out;
  for (const auto& f : failures) out += (out.empty() ? "" : "; ") + f;
  if (!hints.empty()) {
    out += " (check: ";
    for (std::size_t i = 0; i < hints.size(); ++i) out += (i ? "; " : "") + hints[i];
    out += ")";
  }
  return out;
}

PlausibilityReport CheckUmbmarkPlausibility(const UmbmarkSummary& s) {
  PlausibilityReport r;
  const UmbmarkEstimate& e = s.selected;
  for (auto [name, v] : {std::pair{"E_d", e.E_d}, {"E_b", e.E_b}, {"alpha", e.alpha_rad}, {"beta", e.beta_rad},
                         {"E_max,syst", s.E_max_syst_m}}) {
    if (!std::isfinite(v)) r.failures.push_back(fmt::format("{} is not a finite number", name));
  }
  CheckMultiplier("E_b (wheelbase multiplier)", e.E_b, r);
  CheckMultiplier("c_L (left diameter multiplier)", s.c_L, r);
  CheckMultiplier("c_R (right diameter multiplier)", s.c_R, r);
  CheckParams("corrected", s.corrected, r);

  // How large the return errors are compared with the square: a robot that
  // ends further from its start than a fraction of the side did not drive
  // the square its odometry reports.
  double largest = 0.0;
  for (const auto& c : {s.cw, s.ccw}) largest = std::max(largest, std::hypot(c.x_cg_m, c.y_cg_m) + 3.0 * c.sigma_m);
  const bool huge_errors = !(largest < 0.25 * s.side_m);
  if (!r.ok()) {
    if (huge_errors) {
      AddHint(r, fmt::format("return errors reach {:.3g} m on a {:.3g} m square: were millimetres given as metres "
                             "(use an _mm column suffix)?",
                             largest, s.side_m));
    }
    AddHint(r, fmt::format("is the square side right (--side {:.4g} m)?", s.side_m));
    AddHint(r, "are the left and right encoder channels swapped, or a cw/ccw label reversed?");
    AddHint(r, "are the robot file's wheelbase and diameters in metres and the ones the runs used?");
  }

  for (const auto* c : {&s.cw, &s.ccw}) {
    const char* dir = c == &s.cw ? "cw" : "ccw";
    if (c->n < 2) {
      r.warnings.push_back(fmt::format("only {} {} run: its scatter (SEM) cannot be estimated, so the 3*SEM test "
                                       "cannot say whether compensation helps; UMBmark asks for 5 runs per direction",
                                       c->n, dir));
    } else if (c->sigma_m == 0.0) {
      r.warnings.push_back(fmt::format("the {} {} runs have identical return errors (zero scatter): real runs "
                                       "scatter, so check the data are not copies; intervals have no meaning",
                                       c->n, dir));
    }
  }
  if (s.cw.r_cg_m == 0.0 && s.ccw.r_cg_m == 0.0 && s.cw.sigma_m == 0.0 && s.ccw.sigma_m == 0.0) {
    r.warnings.push_back("every return error is exactly zero: did the robot move, and are these measured values?");
  }
  return r;
}

void CheckRefinedPlausibility(const RobotParams& recorded, const RobotParams& refined, PlausibilityReport& r) {
  CheckParams("refined", refined, r);
  CheckMultiplier("refined wheelbase multiplier", refined.wheelbase_m / recorded.wheelbase_m, r);
  CheckMultiplier("refined left diameter multiplier", refined.wheel_diameter_left_m / recorded.wheel_diameter_left_m, r);
  CheckMultiplier("refined right diameter multiplier",
                  refined.wheel_diameter_right_m / recorded.wheel_diameter_right_m, r);
}

int CountMirroredRuns(const TrajectoryData& data, const RobotParams& recorded) {
  int mirrored = 0;
  for (const auto& run : data.runs) {
    if (run.size() < 2 || (run.direction != "cw" && run.direction != "ccw")) continue;
    const std::size_t last = run.size() - 1;
    double dl = 0.0, dr = 0.0;
    if (run.has_ticks()) {
      if (!recorded.ticks_per_rev) continue;
      dl = static_cast<double>(run.ticks_left[last] - run.ticks_left[0]) * recorded.MetresPerTickLeft();
      dr = static_cast<double>(run.ticks_right[last] - run.ticks_right[0]) * recorded.MetresPerTickRight();
    } else {
      dl = run.dist_left_m[last] - run.dist_left_m[0];
      dr = run.dist_right_m[last] - run.dist_right_m[0];
    }
    const double rotation = (dr - dl) / recorded.wheelbase_m;  // total, unwrapped
    // A square turns by 2 pi; half of it the wrong way is no noise.
    if ((run.direction == "cw" && rotation > 3.0) || (run.direction == "ccw" && rotation < -3.0)) ++mirrored;
  }
  return mirrored;
}

}  // namespace umbmark
