// umbmark: entry point. Registers the subcommands, requires exactly one, and
// maps errors to the contract's exit codes in one place:
//   0 success, 1 bad input or data, 2 usage error, 3 failed quality gate.
#include <cstdio>
#include <exception>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "commands.hpp"
#include "core/errors.hpp"

int main(int argc, char** argv) {
  using namespace umbmark;
  CLI::App app{"umbmark: odometry calibration and sim-to-real diagnosis for differential-drive robots"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "umbmark 0.1.0");

  std::vector<cli::Command> commands;
  // Registered subcommands (one cmd_*.cpp each).
  commands.push_back(cli::SetupCalibrate(app));
  commands.push_back(cli::SetupEvaluate(app));
  commands.push_back(cli::SetupImport(app));
  commands.push_back(cli::SetupSimulate(app));
  commands.push_back(cli::SetupDiagnose(app));
  commands.push_back(cli::SetupPredict(app));
  commands.push_back(cli::SetupFitNoise(app));

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);  // prints help or the error message
    return code == 0 ? 0 : 2;
  }
  try {
    for (const auto& c : commands) {
      if (c.app->parsed()) return c.run();
    }
    // Nested subcommands (e.g. `import optiodom`) register under their parent.
    fmt::print(stderr, "umbmark: no subcommand given\n");
    return 2;
  } catch (const InputError& e) {
    fmt::print(stderr, "{}\n", e.what());
    return 1;
  } catch (const InvalidOptions& e) {
    fmt::print(stderr, "umbmark: {}\n", e.what());
    return 2;
  } catch (const QualityGateError& e) {
    fmt::print(stderr, "umbmark: quality gate failed: {}\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    fmt::print(stderr, "umbmark: internal error: {}\n", e.what());
    return 4;
  }
}
