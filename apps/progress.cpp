// Progress lines on stderr (see progress.hpp).
#include "progress.hpp"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>

#include <fmt/format.h>

namespace umbmark::cli {
namespace {
std::atomic<bool> g_quiet{false};
/// The first line after 2 s, or UMBMARK_PROGRESS_DELAY_S (tests).
std::chrono::milliseconds FirstAfter() {
  if (const char* env = std::getenv("UMBMARK_PROGRESS_DELAY_S")) {
    char* end = nullptr;
    const double s = std::strtod(env, &end);
    if (end != env && s >= 0.0 && s < 3600.0) return std::chrono::milliseconds(static_cast<long>(1000.0 * s));
  }
  return std::chrono::seconds(2);
}
constexpr auto kRefresh = std::chrono::milliseconds(250);
}  // namespace

void SetQuiet(bool quiet) { g_quiet = quiet; }

bool ProgressWanted() { return !g_quiet && ::isatty(STDERR_FILENO) == 1; }

Progress::Progress(std::string what, double total)
    : what_(std::move(what)), total_(total), start_(std::chrono::steady_clock::now()) {
  if (ProgressWanted()) thread_ = std::thread([this] { Tick(); });
}

Progress::~Progress() {
  if (!thread_.joinable()) return;
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
  if (shown_) {
    fmt::print(stderr, "\r\033[K");  // clear the progress line
    std::fflush(stderr);
  }
}

void Progress::Tick() {
  std::unique_lock lock(mutex_);
  if (wake_.wait_for(lock, FirstAfter(), [this] { return stop_; })) return;
  do {
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double done = done_.load(std::memory_order_relaxed), total = total_.load(std::memory_order_relaxed);
    std::string line = fmt::format("{}: {:.0f} s", what_, seconds);
    if (total > 0.0 && done > 0.0) {
      const double fraction = std::min(1.0, done / total);
      line = fmt::format("{}: {:3.0f}%  {:.0f} s elapsed, about {:.0f} s left", what_, 100.0 * fraction, seconds,
                         seconds * (1.0 - fraction) / fraction);
    }
    fmt::print(stderr, "\r{}\033[K", line);
    std::fflush(stderr);
    shown_ = true;
  } while (!wake_.wait_for(lock, kRefresh, [this] { return stop_; }));
}

}  // namespace umbmark::cli
