// Parse throughput of the trajectory CSV reader (target: >= 300 MB/s on one
// core). Modes:
//   bench_parse --generate FILE SIZE_MB [SEED]            write a realistic trajectory CSV
//   bench_parse --generate-runs FILE RUNS ROWS [SEED]     the same, RUNS runs of ROWS rows each
//   bench_parse FILE [REPEATS]                            time ReadTrajectoryCsv on it
//   bench_parse --stream FILE [REPEATS]                   time TrajectoryReader, run by run
// The generated file has several runs of UMBmark-like squares (cw/ccw) with
// encoder ticks at 100 Hz and ground truth on 4 of 5 samples (the others
// empty), as a motion-capture log merged with an encoder log looks.
// bench/parse_bench.sh compares the figure with `wc -l` on the same file.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <random>
#include <string>

#include <fmt/format.h>

#include "core/angles.hpp"
#include "core/errors.hpp"
#include "formats/trajectory_csv.hpp"

namespace {

using namespace umbmark;

/// Writes runs until the file reaches `size_mb` or, when `runs` > 0, exactly
/// `runs` runs of `rows_per_run` rows each.
int Generate(const std::string& path, double size_mb, int runs, int rows_per_run, std::uint64_t seed) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) {
    fmt::print(stderr, "cannot write {}\n", path);
    return 1;
  }
  const auto target_bytes = runs > 0 ? std::numeric_limits<std::size_t>::max() : static_cast<std::size_t>(size_mb * 1e6);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  // Robot: 0.34 m wheelbase, 0.1524 m wheels, 2048 ticks/rev; square side 4 m.
  constexpr double kWheelbase = 0.34, kMetresPerTick = kPi * 0.1524 / 2048.0, kDt = 0.01;
  constexpr double kSpeed = 0.4, kTurnRate = 0.8, kSide = 4.0;
  std::string buf = "# synthetic trajectory log for bench_parse (seed " + std::to_string(seed) + ")\n";
  buf += "run,direction,t_s,ticks_left,ticks_right,x_gt_m,y_gt_m,theta_gt_rad\n";
  std::size_t written = 0, rows = 0;
  int run = 0;
  while (runs > 0 ? run < runs : written + buf.size() < target_bytes) {
    ++run;
    int run_rows = 0;
    const bool cw = run % 2 == 1;
    const char* direction = cw ? "cw" : "ccw";
    double x = 0, y = 0, theta = 0, travel_l = 0, travel_r = 0, t = 0;
    // Four legs and four turns per square, several squares per run.
    const int segments = runs > 0 ? 1 << 30 : 8 * 6;
    for (int segment = 0; segment < segments && written + buf.size() < target_bytes; ++segment) {
      if (runs > 0 && run_rows >= rows_per_run) break;
      const bool turn = segment % 2 == 1;
      const double duration = turn ? (kPi / 2) / kTurnRate : kSide / kSpeed;
      const int steps = static_cast<int>(duration / kDt);
      for (int k = 0; k < steps && !(runs > 0 && run_rows >= rows_per_run); ++k) {
        const bool last = runs > 0 ? run_rows + 1 == rows_per_run : k + 1 == steps;
        const double v = turn ? 0.0 : kSpeed;
        const double w = turn ? (cw ? -kTurnRate : kTurnRate) : 0.0;
        const double dl = (v - w * kWheelbase / 2) * kDt * (1 + 0.01 * noise(rng));
        const double dr = (v + w * kWheelbase / 2) * kDt * (1 + 0.01 * noise(rng));
        travel_l += dl;
        travel_r += dr;
        const double dtheta = (dr - dl) / kWheelbase;
        x += (dl + dr) / 2 * std::cos(theta + dtheta / 2);
        y += (dl + dr) / 2 * std::sin(theta + dtheta / 2);
        theta += dtheta;
        t += kDt;
        const auto ticks_l = static_cast<std::int64_t>(std::floor(travel_l / kMetresPerTick));
        const auto ticks_r = static_cast<std::int64_t>(std::floor(travel_r / kMetresPerTick));
        // --generate-runs writes a recorder's log: absolute time stamps (10
        // us), counters that do not start at 0, 7-decimal ground truth.
        const double stamp = runs > 0 ? 1591000000.0 + 1000.0 * run + t : t;
        const std::int64_t offset = runs > 0 ? 1000000 : 0;
        const int t_digits = runs > 0 ? 5 : 3, gt_digits = runs > 0 ? 7 : 6;
        if (rows % 5 == 4 && !last && k + 1 < steps && (segment > 0 || k > 0)) {
          fmt::format_to(std::back_inserter(buf), "{},{},{:.{}f},{},{},,,\n", run, direction, stamp, t_digits,
                         ticks_l + offset, ticks_r + offset);
        } else {
          fmt::format_to(std::back_inserter(buf), "{},{},{:.{}f},{},{},{:.{}f},{:.{}f},{:.{}f}\n", run, direction,
                         stamp, t_digits, ticks_l + offset, ticks_r + offset, x + 2e-4 * noise(rng), gt_digits,
                         y + 2e-4 * noise(rng), gt_digits, WrapAngle(theta + 1.7e-3 * noise(rng)), gt_digits);
        }
        ++rows;
        ++run_rows;
        if (buf.size() > (1u << 22)) {
          written += std::fwrite(buf.data(), 1, buf.size(), f);
          buf.clear();
        }
      }
    }
    // Every run ends on a sample with ground truth (the last one of a leg).
  }
  written += std::fwrite(buf.data(), 1, buf.size(), f);
  if (std::fclose(f) != 0) return 1;
  fmt::print("generated {}: {:.1f} MB, {} rows, {} runs, seed {}\n", path, static_cast<double>(written) / 1e6, rows,
             run, seed);
  return 0;
}

/// User + system CPU time of this process [s].
double CpuSeconds() {
  rusage u {};
  getrusage(RUSAGE_SELF, &u);
  const auto secs = [](const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec); };
  return secs(u.ru_utime) + secs(u.ru_stime);
}

int Time(const std::string& path, int repeats, bool stream) {
  double best = 1e300, best_cpu = 1e300;
  std::size_t samples = 0, runs = 0, gt = 0;
  for (int r = 0; r < repeats; ++r) {
    const double cpu_start = CpuSeconds();
    const auto start = std::chrono::steady_clock::now();
    runs = samples = gt = 0;
    const auto count = [&](const TrajectoryRun& run) {
      ++runs;
      samples += run.size();
      for (std::size_t i = 0; i < run.size(); ++i) gt += run.HasGroundTruth(i) ? 1 : 0;
    };
    if (stream) {
      io::TrajectoryReader reader(path);
      TrajectoryRun run;
      while (reader.NextRun(run)) count(run);
    } else {
      const TrajectoryData data = io::ReadTrajectoryCsv(path);
      for (const auto& run : data.runs) count(run);
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    best = std::min(best, seconds);
    best_cpu = std::min(best_cpu, CpuSeconds() - cpu_start);
  }
  std::FILE* f = std::fopen(path.c_str(), "rb");
  std::fseek(f, 0, SEEK_END);
  const auto bytes = static_cast<double>(std::ftell(f));
  std::fclose(f);
  // One line, key=value, for scripts (best of `repeats`, read + parse; wall
  // clock and CPU time, the latter robust to other load on the machine).
  fmt::print("bytes={:.0f} runs={} samples={} with_ground_truth={} seconds={:.4f} MB_per_s={:.1f} cpu_seconds={:.4f} "
             "MB_per_cpu_s={:.1f}\n",
             bytes, runs, samples, gt, best, bytes / 1e6 / best, best_cpu, bytes / 1e6 / best_cpu);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const std::string first = argc > 1 ? argv[1] : "";
    constexpr std::uint64_t kSeed = 20240611u;
    if (first == "--generate" && argc >= 4) {
      return Generate(argv[2], std::atof(argv[3]), 0, 0, argc > 4 ? std::strtoull(argv[4], nullptr, 10) : kSeed);
    }
    if (first == "--generate-runs" && argc >= 5) {
      return Generate(argv[2], 0.0, std::atoi(argv[3]), std::atoi(argv[4]),
                      argc > 5 ? std::strtoull(argv[5], nullptr, 10) : kSeed);
    }
    if (first == "--stream" && argc >= 3) return Time(argv[2], argc > 3 ? std::atoi(argv[3]) : 3, true);
    if (argc >= 2 && first[0] != '-') return Time(first, argc > 2 ? std::atoi(argv[2]) : 3, false);
    fmt::print(stderr,
               "usage: bench_parse --generate FILE SIZE_MB [SEED] | --generate-runs FILE RUNS ROWS [SEED] | "
               "[--stream] FILE [REPEATS]\n");
    return 2;
  } catch (const InputError& e) {
    fmt::print(stderr, "{}\n", e.what());
    return 1;
  }
}
