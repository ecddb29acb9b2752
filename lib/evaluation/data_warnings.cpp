// Degenerate-data warnings for trajectory runs (see data_warnings.hpp).
#include "evaluation/data_warnings.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/angles.hpp"

namespace umbmark {
namespace {

constexpr std::size_t kExampleIds = 3;

std::string Examples(const std::vector<std::string>& ids, std::size_t total) {
  std::string out;
  for (const auto& id : ids) out += (out.empty() ? "" : ", ") + id;
  if (total > ids.size()) out += ", ...";
  return out;
}

/// What the number of runs and their spread say, for both kinds of data: a
/// single run, a single cw or ccw run, and (`copies`) runs that are
/// bit-for-bit the same.
void CountWarnings(const std::string& what, std::size_t runs, const std::map<std::string, std::size_t>& square_runs,
                   bool copies, const char* same_what, std::vector<std::string>& w) {
  if (runs == 1) {
    w.push_back(fmt::format("{}: a single run: nothing shows how runs scatter; record 5 or more", what));
    return;
  }
  for (const auto& [dir, count] : square_runs) {
    if (count == 1) {
      w.push_back(fmt::format("{}: only 1 {} run: its scatter cannot be estimated; UMBmark asks for 5 per direction",
                              what, dir));
    }
  }
  if (copies) {
    w.push_back(fmt::format("{}: all {} runs end at exactly the same {} (zero scatter): real runs scatter, so check "
                            "the runs are not copies",
                            what, runs, same_what));
  }
}

}  // namespace

void TrajectoryDataCheck::Add(const TrajectoryRun& run) {
  const std::size_t n = run.size();
  if (n == 0) return;
  ++runs_;
  samples_ += n;
  double gt_reach = 0.0, gt_turn = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!run.HasGroundTruth(i)) continue;
    ++gt_samples_;
    gt_reach = std::max(gt_reach, std::hypot(run.gt_x_m[i] - run.gt_x_m[0], run.gt_y_m[i] - run.gt_y_m[0]));
    gt_turn = std::max(gt_turn, std::abs(WrapAngle(run.gt_theta_rad[i] - run.gt_theta_rad[0])));
  }
  bool wheels_move = false;
  for (std::size_t i = 1; i < n && !wheels_move; ++i) {
    if (run.has_ticks()) {
      const double dl = static_cast<double>(run.ticks_left[i] - run.ticks_left[0]);
      const double dr = static_cast<double>(run.ticks_right[i] - run.ticks_right[0]);
      if (robot_.ticks_per_rev) {
        wheels_move = std::abs(dl) * robot_.MetresPerTickLeft() >= kStillM ||
                      std::abs(dr) * robot_.MetresPerTickRight() >= kStillM;
      } else {
        wheels_move = dl != 0.0 || dr != 0.0;
      }
    } else {
      wheels_move = std::abs(run.dist_left_m[i] - run.dist_left_m[0]) >= kStillM ||
                    std::abs(run.dist_right_m[i] - run.dist_right_m[0]) >= kStillM;
    }
  }
  const bool gt_still = gt_reach < kStillM && gt_turn < kStillRad;
  if (gt_still && !wheels_move) {
    if (still_++ < kExampleIds) still_ids_.push_back(run.run);
  } else if (gt_still) {
    if (gt_still_wheels_move_++ < kExampleIds) gt_still_ids_.push_back(run.run);
  }
  if (run.direction == "cw" || run.direction == "ccw") ++square_runs_[run.direction];
  // End pose relative to the start (contract: ground truth at the last sample).
  const std::size_t last = n - 1;
  const double end[3] = {run.gt_x_m[last] - run.gt_x_m[0], run.gt_y_m[last] - run.gt_y_m[0],
                         run.gt_theta_rad[last] - run.gt_theta_rad[0]};
  if (runs_ == 1) {
    std::copy(end, end + 3, end_);
  } else if (!std::equal(end, end + 3, end_)) {
    all_same_end_ = false;
  }
}

void TrajectoryDataCheck::Merge(const TrajectoryDataCheck& later) {
  if (later.runs_ == 0) return;
  if (runs_ == 0) {
    *this = later;
    return;
  }
  all_same_end_ = all_same_end_ && later.all_same_end_ && std::equal(end_, end_ + 3, later.end_);
  runs_ += later.runs_;
  samples_ += later.samples_;
  gt_samples_ += later.gt_samples_;
  for (const auto& id : later.still_ids_)
    if (still_ids_.size() < kExampleIds) still_ids_.push_back(id);
  for (const auto& id : later.gt_still_ids_)
    if (gt_still_ids_.size() < kExampleIds) gt_still_ids_.push_back(id);
  still_ += later.still_;
  gt_still_wheels_move_ += later.gt_still_wheels_move_;
  for (const auto& [direction, n] : later.square_runs_) square_runs_[direction] += n;
}

std::vector<std::string> TrajectoryDataCheck::Warnings(const std::string& what) const {
  std::vector<std::string> w;
  if (runs_ == 0) return w;
  if (still_ > 0) {
    w.push_back(fmt::format("{}: {} of {} runs never move (ground truth within 1 mm and 1 mrad of the start, wheels "
                            "still: run {}); their errors say nothing about the odometry: drop them or check the "
                            "recording",
                            what, still_, runs_, Examples(still_ids_, still_)));
  }
  if (gt_still_wheels_move_ > 0) {
    w.push_back(fmt::format("{}: in {} of {} runs the wheels turn but the ground truth stays at the start (run {}): "
                            "lost tracking, or the wrong rigid body?",
                            what, gt_still_wheels_move_, runs_, Examples(gt_still_ids_, gt_still_wheels_move_)));
  }
  if (static_cast<double>(gt_samples_) < kSparseFraction * static_cast<double>(samples_)) {
    w.push_back(fmt::format("{}: ground truth at only {} of {} samples ({:.0f} %): errors along the path are "
                            "measured at those samples only",
                            what, gt_samples_, samples_, 100.0 * static_cast<double>(gt_samples_) / static_cast<double>(samples_)));
  }
  CountWarnings(what, runs_, square_runs_, all_same_end_ && still_ < runs_, "ground-truth pose", w);
  return w;
}

void EndpointDataCheck::Add(const ReturnError& run) {
  const double e[3] = {run.ex_m, run.ey_m, run.etheta_rad.value_or(0.0)};
  if (runs_++ == 0) {
    std::copy(e, e + 3, first_);
    first_has_theta_ = run.etheta_rad.has_value();
  } else if (!std::equal(e, e + 3, first_) || first_has_theta_ != run.etheta_rad.has_value()) {
    all_same_ = false;
  }
  all_zero_ = all_zero_ && e[0] == 0.0 && e[1] == 0.0 && e[2] == 0.0;
  if (run.direction == "cw" || run.direction == "ccw") ++square_runs_[run.direction];
}

std::vector<std::string> EndpointDataCheck::Warnings(const std::string& what) const {
  std::vector<std::string> w;
  if (runs_ == 0) return w;
  if (all_zero_) {
    w.push_back(fmt::format("{}: every return error is exactly 0 ({} runs): nothing was measured (placeholder "
                            "values?); record the robot's final pose against its start",
                            what, runs_));
  }
  CountWarnings(what, runs_, square_runs_, all_same_ && !all_zero_, "return error", w);
  return w;
}

}  // namespace umbmark
