// Subcommand registry. Each subcommand lives in its own cmd_*.cpp with an
// options struct, a Setup*(CLI::App&) that binds flags, and a run function
// that only calls the library and prints. main.cpp registers them all.
#pragma once

#include <functional>

#include <CLI/CLI.hpp>

namespace umbmark::cli {

/// What a Setup function hands back: the subcommand and how to run it once
/// parsing succeeded. run() returns the process exit status.
struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};


Command SetupCalibrate(CLI::App& parent);
Command SetupEvaluate(CLI::App& parent);
Command SetupImport(CLI::App& parent);
Command SetupSimulate(CLI::App& parent);
Command SetupDiagnose(CLI::App& parent);
Command SetupPredict(CLI::App& parent);
Command SetupFitNoise(CLI::App& parent);
Command SetupSummarize(CLI::App& parent);
Command SetupCalibrateLidar(CLI::App& parent);
Command SetupPlan(CLI::App& parent);

}  // namespace umbmark::cli
