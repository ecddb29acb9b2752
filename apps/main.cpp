// umbmark: entry point. Registers the subcommands, requires exactly one, and
// maps every error to the contract's exit codes in this one place:
//   0 success
//   1 bad input or data (InputError, unreadable JSON/TOML, a file system
//     error, not enough memory for what the input asks, a failed write to
//     standard output, and any other error: never a crash, never exit 4)
//   2 usage error (bad flags, InvalidOptions)
//   3 the computation ran but failed a quality gate (QualityGateError)
// Messages go to stderr with invalid UTF-8 bytes escaped as \xNN. Ceres'
// glog output is silenced so stderr holds only umbmark's messages.
#include <cstdio>
#include <exception>
#include <filesystem>
#include <new>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <glog/logging.h>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "common.hpp"
#include "core/errors.hpp"
#include "core/utf8.hpp"
#include "output/atomic_write.hpp"
#include "umbmark/version.hpp"
#include "progress.hpp"

namespace {

void Report(const std::string& text) { fmt::print(stderr, "{}\n", umbmark::EscapeInvalidUtf8(text)); }

/// Runs the parsed subcommand; every exception becomes a message and a
/// documented exit status.
int RunCommand(const CLI::App& app, const std::vector<umbmark::cli::Command>& commands) {
  using namespace umbmark;
  try {
    cli::CheckPathArguments(app);
    for (const auto& c : commands) {
      if (c.app->parsed()) return c.run();
    }
    Report("umbmark: no subcommand given");
    return 2;
  } catch (const InputError& e) {
    Report(e.what());
    return 1;
  } catch (const InvalidOptions& e) {
    Report(fmt::format("umbmark: {}", e.what()));
    return 2;
  } catch (const QualityGateError& e) {
    Report(fmt::format("umbmark: quality gate failed: {}", e.what()));
    return 3;
  } catch (const CLI::ParseError& e) {
    Report(fmt::format("umbmark: {}", e.what()));
    return 2;
  } catch (const std::bad_alloc&) {
    Report("umbmark: not enough memory for this input or these sizes; reduce the run count, the sample rate or "
           "the sizes given on the command line");
    return 1;
  } catch (const nlohmann::json::exception& e) {
    Report(fmt::format("umbmark: invalid JSON data: {}", e.what()));
    return 1;
  } catch (const std::filesystem::filesystem_error& e) {
    Report(fmt::format("umbmark: {}", e.what()));
    return 1;
  } catch (const std::exception& e) {
    Report(fmt::format("umbmark: error: {}", e.what()));
    return 1;
  } catch (...) {
    Report("umbmark: error: unknown failure");
    return 1;
  }
}

}  // namespace

int main(int argc, char** argv) {
  using namespace umbmark;
  // Ceres logs through glog; its warnings would interleave with ours.
  FLAGS_minloglevel = google::GLOG_FATAL;
  FLAGS_logtostderr = true;
  io::InstallTemporaryFileCleanup();

  CLI::App app{"umbmark: odometry calibration and sim-to-real diagnosis for differential-drive robots"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("umbmark ") + kVersion);
  bool quiet = false;
  app.add_flag("-q,--quiet", quiet, "No progress lines on stderr (they appear only on a terminal, after 2 s)");
  app.fallthrough();  // --quiet may follow the subcommand

  std::vector<cli::Command> commands;
  // Registered subcommands (one cmd_*.cpp each).
  commands.push_back(cli::SetupCalibrate(app));
  commands.push_back(cli::SetupEvaluate(app));
  commands.push_back(cli::SetupImport(app));
  commands.push_back(cli::SetupSimulate(app));
  commands.push_back(cli::SetupDiagnose(app));
  commands.push_back(cli::SetupPredict(app));
  commands.push_back(cli::SetupFitNoise(app));
  commands.push_back(cli::SetupSummarize(app));
  commands.push_back(cli::SetupCalibrateLidar(app));
  commands.push_back(cli::SetupPlan(app));

  // `umbmark import foo DIR`: name the unknown format instead of CLI11's
  // "A subcommand is required".
  if (argc >= 3) {
    const auto all = [](CLI::App*) { return true; };
    for (CLI::App* parent : app.get_subcommands(all)) {
      if (parent->get_subcommands(all).empty()) continue;
      if (parent->get_name() != argv[1] || argv[2][0] == '-') continue;
      std::string known;
      bool found = false;
      for (CLI::App* sub : parent->get_subcommands(all)) {
        known += (known.empty() ? "" : ", ") + sub->get_name();
        found = found || sub->get_name() == argv[2];
      }
      if (!found) {
        Report(fmt::format("umbmark {}: unknown {} format '{}' (known: {})", argv[1], argv[1], argv[2], known));
        return 2;
      }
    }
  }

  // `umbmark help [COMMAND [SUBCOMMAND]]`: the options of a command.
  std::vector<std::string> help_topic;
  auto* help = app.add_subcommand("help", "Show the options of a command: umbmark help [COMMAND]");
  help->add_option("COMMAND", help_topic, "Command (and subcommand, e.g. `import optiodom`)");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);  // prints help or the error message
    return code == 0 ? 0 : 2;
  }
  cli::SetQuiet(quiet);
  if (help->parsed()) {
    CLI::App* topic = &app;
    for (const auto& name : help_topic) {
      try {
        topic = topic->get_subcommand(name);
      } catch (const CLI::OptionNotFound&) {
        fmt::print(stderr, "umbmark help: no command '{}' (see `umbmark help`)\n", name);
        return 2;
      }
    }
    // The formatter directly: App::help() would show the `help` command's own page.
    fmt::print("{}", topic->get_formatter()->make_help(topic, topic->get_name(), CLI::AppFormatMode::Normal));
    return 0;
  }
  int status = RunCommand(app, commands);
  // Output that could not be written (a full disk, `> /dev/full`, a closed
  // pipe) is a failure, never a silent success.
  if (std::fflush(stdout) != 0 || std::ferror(stdout)) {
    Report("umbmark: cannot write to standard output (disk full or output closed)");
    if (status == 0) status = 1;
  }
  return status;
}
