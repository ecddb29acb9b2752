// Progress of long library work (Monte Carlo runs, the diagnosis' null
// simulations, candidate fits and explanation, calibrate's held-out
// comparison). The library never prints: an options struct carries a
// ProgressCallback and the work reports through it; the app decides what
// to show (apps/progress.hpp: a percentage and an ETA on a terminal).
#pragma once

#include <algorithm>
#include <functional>
#include <mutex>
#include <utility>

namespace umbmark {

/// Reports `done` units of work out of `total` (same unit: runs, campaigns,
/// fits). Calls are serialised (never two at once, possibly from worker
/// threads), `done` never decreases, and the last call of a finished piece
/// of work has done == total. Must be cheap and must not throw. Empty: no
/// reporting.
using ProgressCallback = std::function<void(double done, double total)>;

/// Counts finished units of work for a ProgressCallback; Add() may be
/// called from any thread.
class ProgressCounter {
 public:
  ProgressCounter(ProgressCallback callback, double total) : callback_(std::move(callback)), total_(total) {}
  /// `units` more are done (clamped at the total).
  void Add(double units = 1.0) {
    if (!callback_) return;
    std::lock_guard lock(mutex_);
    done_ = std::min(total_, done_ + units);
    callback_(done_, total_);
  }
  /// The work is complete (also when it ended early, e.g. a search that
  /// stopped before its largest size): reports done == total.
  void Finish() { Add(total_); }

 private:
  ProgressCallback callback_;
  double total_;
  double done_ = 0.0;
  std::mutex mutex_;
};

/// A callback for one stage of a larger piece of work: the stage's
/// done / total maps onto [from, to] of the parent's `parent_total`.
inline ProgressCallback StageProgress(const ProgressCallback& parent, double from, double to, double parent_total) {
  if (!parent) return {};
  return [parent, from, to, parent_total](double done, double total) {
    parent(from + (to - from) * (total > 0.0 ? std::clamp(done / total, 0.0, 1.0) : 1.0), parent_total);
  };
}

}  // namespace umbmark
