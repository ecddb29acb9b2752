// Shared command-line plumbing for the subcommands: robot parameters from a
// robot file and/or flags, JSON output to a file or stdout, and input
// resolution (DATA.csv + --robot, or a campaign manifest).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "api/json.hpp"
#include "api/robot_source.hpp"
#include "core/robot.hpp"
#include "core/runs.hpp"
#include "evaluation/trajectory_eval.hpp"
#include "output/output_set.hpp"

namespace umbmark::cli {

/// Binds --robot, --wheelbase, --diameter-left, --diameter-right,
/// --ticks-per-rev to `robot` (lib/api/robot_source.hpp).
void BindRobot(CLI::App& app, api::RobotSource& robot);

/// --robot FILE and the per-field override flags of the contract
/// (api::RobotSource: Given(), Resolve()).
struct RobotFlags : api::RobotSource {
  void Bind(CLI::App& app) { BindRobot(app, *this); }
};

/// Where the machine-readable result goes: "" = nowhere, "-" = stdout alone.
struct JsonFlag {
  std::string path;
  void Bind(CLI::App& app);
  bool ToStdout() const { return path == "-"; }
  /// True when the human-readable text should be printed (not `--json -`).
  bool PrintText() const { return !ToStdout(); }
  /// Writes `j` (pretty, 2-space indent) to stdout or atomically to the file
  /// through CommandOutputs(). Adds an empty top-level `warnings` list when
  /// `j` is an object without one (the contract: every command's JSON has
  /// it); invalid UTF-8 in strings is escaped (see DumpJson).
  void Emit(const nlohmann::json& j) const;
  /// The tail of every command that writes files: Emit(j), then "wrote
  /// FILE (what)" for each of `written` and for the JSON file
  /// (PrintWritten; on stderr with `--json -`).
  void EmitAndListOutputs(const nlohmann::json& j, std::vector<std::string> written) const;
};

/// Validator for a number in [lo, hi]; the message quotes the value as the
/// user typed it and the bounds with sensible precision (CLI::Range prints
/// them with six decimals, or 300 digits for the largest double).
CLI::Validator NumberIn(double lo, double hi);

/// Validators for a finite number > 0, resp. >= 0, with short messages that
/// quote the user's value (replacing CLI::PositiveNumber/NonNegativeNumber,
/// whose messages print the largest double in 300 digits).
CLI::Validator Positive();
CLI::Validator NonNegative();

/// A finite number > 0 inside the plausible range of `key`
/// (core/plausible_units.hpp: wheelbase_m, side_m, ...): refuses unit
/// mix-ups such as `--side 4000` (millimetres) with the range and a hint.
CLI::Validator Plausible(std::string_view key);

/// Validator for --seed: a whole number in [0, 2^64), quoted back as given
/// (CLI11 would turn "-1" silently into 2^64-1).
CLI::Validator SeedValidator();

/// Refuses (InvalidOptions, exit 2) an empty value given to a file or folder
/// option or argument of the parsed command (`--json ""` would otherwise
/// mean "not requested" and the output would silently not be written;
/// `--out ""`, `--report ""`, `DATA ""` likewise) and a path holding a NUL
/// byte. Walks the parsed subcommands of `app`; main() calls it before the
/// command runs.
void CheckPathArguments(const CLI::App& app);

/// The process's output set: every command registers its inputs and outputs
/// here, calls Check() before writing anything, and writes through Write()
/// (see output/output_set.hpp). One command runs per process.
io::OutputSet& CommandOutputs();

/// Registers the command's input files with CommandOutputs(): each path, and
/// for a manifest (.toml) every experiment file it names (a manifest that
/// cannot be read is left to the command's own reader to report), plus the
/// robot file of `robot` when given.
void RegisterInputs(const std::vector<std::string>& inputs, const RobotFlags* robot = nullptr);

/// The JSON building blocks of the results (lib/api/json.hpp).
using api::DumpJson;
using api::JsonEvaluationRuns;
using api::JsonEvaluationSummary;
using api::JsonNumber;
using api::JsonParams;

/// Inserts "-<tag>" before the extension: ("out.svg", "run1") -> "out-run1.svg".
/// Used when one flag names an output and several inputs are processed.
std::string TaggedPath(const std::string& path, const std::string& tag);

/// "wrote FILE (what)" for every output file, on stdout when the readable
/// text goes there, else on stderr (so `--json -` keeps stdout pure JSON).
void PrintWritten(const std::vector<std::string>& files, bool to_stdout);

}  // namespace umbmark::cli
