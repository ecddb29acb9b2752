// Injects contract effects into a REAL recording's trajectory CSV (issue 28):
// the encoders stay as recorded, the ground truth changes as the robot's path
// would have with the effect (bench/injection.hpp says how; written from the
// contract's definitions, independently of lib/simulation). Used by
// bench/injection_recovery.sh, which scores `umbmark diagnose` on the result.
//
// Usage: inject_recordings --in RUNS.csv --out OUT.csv [--effect NAME:k=v,...]...
//   [--seed S] [--wheelbase M] [--diameter M | --diameter-left M --diameter-right M]
//   [--ticks-per-rev N] [--first-run-index I] [--min-still S] [--min-travel M]
// Prints one JSON line: what was injected (motions, spot turns, kicked
// starts, standstills, bumps, the per-run clock offsets drawn) and its
// footprint (largest change of a ground-truth sample's position and heading).
#include <cstdio>
#include <exception>
#include <string>

#include <fmt/format.h>

#include "injection.hpp"

namespace {

int Usage(const std::string& why) {
  fmt::print(stderr,
             "inject_recordings: {}\nusage: inject_recordings --in RUNS.csv --out OUT.csv [--effect NAME:k=v,...]... "
             "[--seed S] [--wheelbase M] [--diameter M] [--diameter-left M] [--diameter-right M] "
             "[--ticks-per-rev N] [--first-run-index I] [--min-still S] [--min-travel M]\n",
             why);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  umbmark_bench::InjectOptions o;
  std::string in, out;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string k = argv[i];
      if (i + 1 >= argc) return Usage("missing value after " + k);
      const std::string v = argv[++i];
      if (k == "--in") in = v;
      else if (k == "--out") out = v;
      else if (k == "--effect") o.effects.push_back(umbmark_bench::ParseEffect(v));
      else if (k == "--seed") o.seed = std::stoull(v);
      else if (k == "--wheelbase") o.wheelbase_m = std::stod(v);
      else if (k == "--diameter") o.diameter_left_m = o.diameter_right_m = std::stod(v);
      else if (k == "--diameter-left") o.diameter_left_m = std::stod(v);
      else if (k == "--diameter-right") o.diameter_right_m = std::stod(v);
      else if (k == "--ticks-per-rev") o.ticks_per_rev = std::stod(v);
      else if (k == "--first-run-index") o.first_run_index = std::stoi(v);
      else if (k == "--min-still") o.min_still_s = std::stod(v);
      else if (k == "--min-travel") o.min_travel_m = std::stod(v);
      else return Usage("unknown option " + k);
    }
  } catch (const std::exception& e) {
    return Usage(e.what());
  }
  if (in.empty() || out.empty()) return Usage("--in and --out are required");
  try {
    auto tab = umbmark_bench::ReadTrajectory(in);
    const auto s = umbmark_bench::InjectTable(tab, o);
    umbmark_bench::WriteTrajectory(tab, out);
    std::string taus;
    for (double t : s.run_taus_s) taus += fmt::format("{}{:.4f}", taus.empty() ? "" : ", ", t);
    fmt::print("{{\"seed\": {}, \"runs\": {}, \"motions\": {}, \"spot_turns\": {}, \"starts_kicked\": {}, "
               "\"standstills\": {}, \"bumps\": {}, \"run_taus_s\": [{}], \"max_position_change_m\": {:.6g}, "
               "\"max_heading_change_rad\": {:.6g}}}\n",
               o.seed, s.runs, s.motions, s.spot_turns, s.starts_kicked, s.standstills, s.bumps, taus,
               s.max_position_change_m, s.max_heading_change_rad);
  } catch (const std::exception& e) {
    fmt::print(stderr, "inject_recordings: {}\n", e.what());
    return 1;
  }
  return 0;
}
