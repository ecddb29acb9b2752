// The one parallel-for of the library (Monte Carlo blocks, null campaigns,
// candidate fits): `threads` workers take items 0..count-1 in turn. Each
// item must write only its own outputs, so results do not depend on the
// number of threads or on the schedule.
#pragma once

#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

namespace umbmark {

/// Worker count for a `threads` option where 0 means all hardware threads.
inline int ResolveThreads(int threads) {
  return threads > 0 ? threads : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

/// Runs work(i) for i = 0..count-1 on min(threads, count) threads (at least
/// one: the caller's). Index is any integer type (int, std::int64_t).
template <class Index, class Work>
void ParallelFor(int threads, Index count, const Work& work) {
  const int n = static_cast<int>(std::clamp<Index>(static_cast<Index>(threads), 1, std::max<Index>(count, 1)));
  std::atomic<Index> next{0};
  auto worker = [&]() {
    for (Index i = next++; i < count; i = next++) work(i);
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < n; ++t) pool.emplace_back(worker);
  worker();
  for (auto& th : pool) th.join();
}

}  // namespace umbmark
