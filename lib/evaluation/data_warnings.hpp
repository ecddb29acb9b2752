// Degenerate-data warnings for trajectory runs, shared by evaluate, diagnose
// and import (docs/safety.md, "Warnings"): runs that never move, ground
// truth that stays still while the wheels turn, ground truth at fewer than
// half of the samples, a single run (in total, or of cw or ccw), and runs
// whose ground-truth end poses are bit-for-bit identical (copies: zero
// scatter). Streaming: Add() one run at a time; memory does not grow with
// the number of runs beyond the handful of example ids it names.
// EndpointDataCheck does the same for return errors (diagnose's endpoint
// files): a single run, a single cw or ccw run, identical return errors
// (copies), every return error exactly 0 (nothing measured).
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/robot.hpp"
#include "core/runs.hpp"

namespace umbmark {

class TrajectoryDataCheck {
 public:
  /// Motion thresholds: a run "never moves" when its ground truth stays
  /// within kStillM of the start and kStillRad of the start heading, and
  /// each wheel's reading changes by less than kStillM (ticks: not at all).
  static constexpr double kStillM = 1e-3, kStillRad = 1e-3;
  /// "Ground truth missing for most samples": fewer than this fraction.
  static constexpr double kSparseFraction = 0.5;

  /// `robot` converts ticks to metres (may lack ticks_per_rev: then ticks
  /// count as moving when they change).
  explicit TrajectoryDataCheck(RobotParams robot) : robot_(std::move(robot)) {}

  void Add(const TrajectoryRun& run);
  /// Adds the runs `later` has seen, as if they had been Add()ed here after
  /// this object's own (a file evaluated in parts, in file order).
  void Merge(const TrajectoryDataCheck& later);

  /// The warnings so far (empty when there is nothing to say); `what` names
  /// the data in the messages (a file or manifest).
  std::vector<std::string> Warnings(const std::string& what) const;

 private:
  RobotParams robot_;
  std::size_t runs_ = 0, samples_ = 0, gt_samples_ = 0;
  std::size_t still_ = 0, gt_still_wheels_move_ = 0;
  std::vector<std::string> still_ids_, gt_still_ids_;
  std::map<std::string, std::size_t> square_runs_;  ///< cw, ccw counts
  bool all_same_end_ = true;
  double end_[3] = {0.0, 0.0, 0.0};
};

class EndpointDataCheck {
 public:
  void Add(const ReturnError& run);
  /// The warnings so far (empty when there is nothing to say); `what` names
  /// the data in the messages (a file).
  std::vector<std::string> Warnings(const std::string& what) const;

 private:
  std::size_t runs_ = 0;
  std::map<std::string, std::size_t> square_runs_;  ///< cw, ccw counts
  bool all_same_ = true, all_zero_ = true;
  double first_[3] = {0.0, 0.0, 0.0};
  bool first_has_theta_ = false;
};

}  // namespace umbmark
