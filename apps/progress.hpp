// Progress lines on stderr for computations that can run longer than 2 s
// (Monte Carlo, null simulations, batches): shown only when stderr is a
// terminal and --quiet was not given, first after 2 s, then refreshed a few
// times a second on one line ("what:  42%  3 s elapsed, about 4 s left"),
// which is cleared when the work ends. Scripts and pipes never see them.
// The library reports through its options' ProgressCallback
// (core/progress.hpp): pass Callback(). UMBMARK_PROGRESS_DELAY_S (seconds,
// default 2) moves the first line, for tests.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>

#include "core/progress.hpp"

namespace umbmark::cli {

/// `--quiet` (any command): no progress lines.
void SetQuiet(bool quiet);
/// Progress is shown: not quiet and stderr is a terminal.
bool ProgressWanted();

/// One piece of work that may take a while; RAII (the line is cleared by
/// the destructor). Thread-safe Update() from any worker.
class Progress {
 public:
  /// `what`: e.g. "Monte Carlo, 200000 runs". `total`: units of work for a
  /// percentage (0 = unknown: elapsed time only).
  explicit Progress(std::string what, double total = 0.0);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  /// Units of work done so far (of `total`).
  void Update(double done) { done_.store(done, std::memory_order_relaxed); }
  /// A library progress callback feeding this line (done and total).
  ProgressCallback Callback() {
    return [this](double done, double total) {
      total_.store(total, std::memory_order_relaxed);
      done_.store(done, std::memory_order_relaxed);
    };
  }

 private:
  void Tick();
  std::string what_;
  std::atomic<double> total_;
  std::atomic<double> done_{0.0};
  std::chrono::steady_clock::time_point start_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  bool shown_ = false;
  std::thread thread_;
};

}  // namespace umbmark::cli
