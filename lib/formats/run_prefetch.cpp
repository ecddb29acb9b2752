// Trajectory runs read ahead on a second thread (see run_prefetch.hpp).
#include "formats/run_prefetch.hpp"

#include <utility>

namespace umbmark::io {

RunPrefetcher::RunPrefetcher(TrajectoryReader& reader) : reader_(reader), thread_([this] { Loop(); }) {}

RunPrefetcher::~RunPrefetcher() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

void RunPrefetcher::Loop() {
  TrajectoryRun run;
  for (;;) {
    bool more = false;
    std::exception_ptr error;
    try {
      more = reader_.NextRun(run);
    } catch (...) {
      error = std::current_exception();
    }
    std::unique_lock<std::mutex> lock(mutex_);
    // One run ready at a time: wait until the consumer took the last one.
    changed_.wait(lock, [this] { return stop_ || !ready_.has_value(); });
    if (stop_) return;
    if (error || !more) {
      error_ = error;
      done_ = true;
      changed_.notify_all();
      return;
    }
    ready_.emplace(std::move(run));
    // Read the next run into the capacity the consumer gave back, if any.
    if (have_spare_) {
      run = std::move(spare_);
      have_spare_ = false;
    } else {
      run = TrajectoryRun();
    }
    changed_.notify_all();
  }
}

bool RunPrefetcher::NextRun(TrajectoryRun& out) {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [this] { return ready_.has_value() || done_; });
  if (!ready_) {
    if (error_) std::rethrow_exception(error_);
    return false;
  }
  std::swap(out, *ready_);
  spare_ = std::move(*ready_);  // the caller's previous run: its vectors' capacity is reused
  have_spare_ = true;
  ready_.reset();
  changed_.notify_all();
  return true;
}

}  // namespace umbmark::io
