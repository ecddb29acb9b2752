// Plausibility gates on calibration results (see plausibility.hpp).
#include "calibration/plausibility.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include <fmt/format.h>

#include "calibration/correction_support.hpp"

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

// Corrections the data cannot support (correction_support.hpp): run only
// on a result that passed the gates above (finite, inside the bounds).
void CheckCorrectionSupport(const UmbmarkSummary& s, PlausibilityReport& r) {
  if (!r.ok()) return;
  const CorrectionSupport c = AnalyseCorrectionSupport(s);
  const UmbmarkEstimate& e = s.selected;
  const struct {
    const char* name;
    double value, se, bias, fail_floor, warn_floor;
  } params[] = {{"E_b", e.E_b, c.se_E_b, c.bias_E_b, kBiasFailFloorEb, kBiasWarnFloorEb},
                {"E_d", e.E_d, c.se_E_d, c.bias_E_d, kBiasFailFloorEd, kBiasWarnFloorEd}};
  for (const auto& p : params) {
    // The bias only counts where the data could see it: beyond the 95 %
    // half-width (unknown scatter: 0) and a floor.
    const double half = c.scatter_known ? HalfWidth95(c, p.se) : 0.0;
    const double bias = std::abs(p.bias);
    if (bias > kBiasFailFraction * std::abs(p.value - 1.0) && bias > std::max(half, p.fail_floor)) {
      r.failures.push_back(fmt::format(
          "correction larger than UMBmark can support: its small-angle formulas (eqs. 4.20-4.27) would give "
          "{} = {:.4f} for a robot whose true {} is {:.4f} (exact square model), so {:.0f} % of the correction "
          "{:+.4f} is an artefact of the approximation",
          p.name, p.value + p.bias, p.name, p.value, 100.0 * bias / std::abs(p.value - 1.0), p.value - 1.0));
      AddHint(r, "use --refine (exact model), or apply a partial correction and run a second pass");
    } else if (bias > std::max(half, p.warn_floor)) {
      r.warnings.push_back(fmt::format(
          "UMBmark's small-angle formulas are off by about {:+.2g} in {} at this correction size (more than the "
          "data's 95 % interval): apply the correction and run a second pass, or use --refine (exact model)",
          -p.bias, p.name));
    }
  }
  // Reversed labels (or swapped encoder channels): the centres lie on the
  // diagonals of the other direction.
  if (c.off_labels_m2 > kMirrorRatio * c.off_reversed_m2) {
    const std::string what = fmt::format(
        "the cw centre of gravity ({:.4g}, {:.4g}) m lies along y = -x and the ccw one ({:.4g}, {:.4g}) m along "
        "y = x, where UMBmark puts the other direction's (eqs. 4.20, 4.24): the cw/ccw labels are reversed, or the "
        "left and right encoder channels swapped (both give these return errors)",
        s.cw.x_cg_m, s.cw.y_cg_m, s.ccw.x_cg_m, s.ccw.y_cg_m);
    if (c.scatter_known && c.p_off_labels < kMirrorP) {
      r.failures.push_back(what);
      AddHint(r, "swap the cw/ccw labels, or the ticks_left/ticks_right columns, and run again");
    } else if (!c.scatter_known) {
      r.warnings.push_back(what + "; with a single run in a direction the scatter is unknown, so this may be chance");
    }
  }
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

  CheckCorrectionSupport(s, r);

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

namespace {

/// Total wheel travel (left, right) [m] of a square run from its first to
/// its last sample; nullopt when it is no cw/ccw run or ticks cannot be
/// converted.
std::optional<std::pair<double, double>> SquareRunTravel(const TrajectoryRun& run, const RobotParams& recorded) {
  if (run.size() < 2 || (run.direction != "cw" && run.direction != "ccw")) return std::nullopt;
  const std::size_t last = run.size() - 1;
  if (run.has_ticks()) {
    if (!recorded.ticks_per_rev) return std::nullopt;
    return std::pair{static_cast<double>(run.ticks_left[last] - run.ticks_left[0]) * recorded.MetresPerTickLeft(),
                     static_cast<double>(run.ticks_right[last] - run.ticks_right[0]) * recorded.MetresPerTickRight()};
  }
  return std::pair{run.dist_left_m[last] - run.dist_left_m[0], run.dist_right_m[last] - run.dist_right_m[0]};
}

double Median(std::vector<double>& v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

int CountMirroredRuns(const TrajectoryData& data, const RobotParams& recorded) {
  int mirrored = 0;
  for (const auto& run : data.runs) {
    const auto travel = SquareRunTravel(run, recorded);
    if (!travel) continue;
    const double rotation = (travel->second - travel->first) / recorded.wheelbase_m;  // total, unwrapped
    // A square turns by 2 pi; half of it the wrong way is no noise.
    if ((run.direction == "cw" && rotation > 3.0) || (run.direction == "ccw" && rotation < -3.0)) ++mirrored;
  }
  return mirrored;
}

std::string CheckReturnErrorScale(const std::vector<ReturnError>& errors, double side_m) {
  std::vector<double> size;
  for (const auto& e : errors) {
    if (e.direction == "cw" || e.direction == "ccw") size.push_back(std::hypot(e.ex_m, e.ey_m));
  }
  if (size.empty()) return {};
  const double median = Median(size);
  if (median < kMaxErrorPerSide * side_m) return {};
  return fmt::format(
      "the square runs' return errors are {:.4g} m (median) on a {:.4g} m square: a robot that drives the square "
      "ends within a fraction of the side from its start; were millimetres given as metres (name the columns "
      "ex_mm, ey_mm), or is the side wrong?",
      median, side_m);
}

std::string CheckTravelScale(const TrajectoryData& data, const RobotParams& recorded, double side_m) {
  std::vector<double> travel;
  for (const auto& run : data.runs) {
    if (const auto t = SquareRunTravel(run, recorded)) travel.push_back(0.5 * (t->first + t->second));
  }
  if (travel.empty()) return {};
  const double median = Median(travel);
  const double expected = 4.0 * side_m;
  if (median > expected / kTravelRatio && median < expected * kTravelRatio) return {};
  return fmt::format(
      "the odometry says the square runs travel {:.4g} m (median), but 4 sides of {:.4g} m are {:.4g} m: is the side "
      "right (metres), and are ticks_per_rev ({}) and the wheel diameters ({:.4g}, {:.4g} m) the robot's?",
      median, side_m, expected, recorded.ticks_per_rev ? fmt::format("{:g}", *recorded.ticks_per_rev) : "not used",
      recorded.wheel_diameter_left_m, recorded.wheel_diameter_right_m);
}

}  // namespace umbmark
