// One parallel-for for the diagnosis' independent work items (null
// campaigns, candidate fits): `threads` workers take items 0..count-1 in
// turn; each item must write only its own outputs, so results do not depend
// on the number of threads or on the schedule.
#pragma once

#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

namespace umbmark::diag {

template <class Work>
void ParallelFor(int threads, int count, const Work& work) {
  threads = std::max(1, std::min(threads, count));
  std::atomic_int next{0};
  auto worker = [&]() {
    for (int i = next++; i < count; i = next++) work(i);
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& th : pool) th.join();
}

}  // namespace umbmark::diag
