// The Python module `umbmark` (docs/python.md): one function per command,
// named as the command with `-` as `_` (`import optiodom` ->
// import_optiodom), positional inputs as the command's, options as keyword
// arguments named as the long options. Each returns a Result whose
// to_dict() is the command's JSON; a failure raises InputError (exit 1),
// UsageError (2) or QualityGateError (3) with the command's message.
// calibrate, predict, simulate, diagnose, fit_noise and summarize run in
// this process over the library (lib/api: api::Calibrate, ...; calibrate's
// trajectory arrays handed over in memory; inprocess.cpp). The others, and
// those calls that write a plot, report, --ros2 or CSV file, run the
// `umbmark` executable with `--json -` (the same parsing, checks,
// computation and JSON as the command line, in a process of its own); their
// trajectory arrays (`runs=`) are checked here, with messages naming the
// array cell, and handed over as a temporary trajectory CSV.
#include <dlfcn.h>
#include <poll.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <glog/logging.h>
#include <pybind11/pybind11.h>

#include "arrays.hpp"
#include "inprocess.hpp"
#include "result.hpp"
#include "core/errors.hpp"
#include "umbmark/version.hpp"

extern char** environ;

namespace py = pybind11;

namespace umbmark::python {

[[noreturn]] void Raise(int status, const std::string& message, const std::optional<std::string>& json,
                        const std::string& command) {
  const Errors& e = ErrorClasses();
  const py::object cls = status == 2 ? e.usage : status == 3 ? e.quality_gate : e.input;
  py::object error = cls(message);
  error.attr("exit_status") = status;
  // A batch that failed in part still has its JSON (per input: result or error).
  error.attr("result") = json ? py::cast(Result{command, *json}) : py::none();
  PyErr_SetObject(cls.ptr(), error.ptr());
  throw py::error_already_set();
}


Errors& ErrorClasses() {
  static Errors e;
  return e;
}

namespace {

/// The umbmark executable: $UMBMARK_EXE, else the one beside this module
/// (the build tree), else the installed one, else `umbmark` on PATH.
std::string Executable() {
  if (const char* env = std::getenv("UMBMARK_EXE"); env != nullptr && *env != '\0') return env;
  static const int anchor = 0;  // an address inside this module, for dladdr
  Dl_info info{};
  if (dladdr(&anchor, &info) != 0 && info.dli_fname != nullptr) {
    const std::filesystem::path beside = std::filesystem::path(info.dli_fname).parent_path() / "umbmark";
    if (::access(beside.c_str(), X_OK) == 0) return beside.string();
  }
  if (::access(UMBMARK_INSTALLED_EXE, X_OK) == 0) return UMBMARK_INSTALLED_EXE;
  return "umbmark";
}

/// What a run of the executable gave.
struct Completed {
  int status = 0;
  std::string out, err;
};

/// Runs `exe args...`, collecting stdout and stderr (both read as they come,
/// so neither pipe fills up). Throws InputError when it cannot be started.
Completed Spawn(const std::string& exe, const std::vector<std::string>& args) {
  int out_pipe[2], err_pipe[2];
  if (::pipe(out_pipe) != 0 || ::pipe(err_pipe) != 0) throw InputError("umbmark", std::strerror(errno));
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, out_pipe[1], 1);
  posix_spawn_file_actions_adddup2(&actions, err_pipe[1], 2);
  for (const int fd : {out_pipe[0], out_pipe[1], err_pipe[0], err_pipe[1]}) posix_spawn_file_actions_addclose(&actions, fd);
  std::vector<std::string> words = {exe, "--quiet"};
  words.insert(words.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, exe.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(out_pipe[1]);
  ::close(err_pipe[1]);
  Completed c;
  if (spawned != 0) {
    ::close(out_pipe[0]);
    ::close(err_pipe[0]);
    throw InputError(exe, std::string("cannot run the umbmark executable: ") + std::strerror(spawned) +
                              " (set UMBMARK_EXE to its path)");
  }
  pollfd fds[2] = {{out_pipe[0], POLLIN, 0}, {err_pipe[0], POLLIN, 0}};
  std::string* sinks[2] = {&c.out, &c.err};
  int open_pipes = 2;
  char buffer[65536];
  while (open_pipes > 0) {
    if (::poll(fds, 2, -1) < 0) {
      if (errno == EINTR) continue;
      break;
    }
    for (int k = 0; k < 2; ++k) {
      if (fds[k].fd < 0 || fds[k].revents == 0) continue;
      const ssize_t n = ::read(fds[k].fd, buffer, sizeof buffer);
      if (n > 0) {
        sinks[k]->append(buffer, static_cast<std::size_t>(n));
      } else if (n == 0 || errno != EINTR) {
        ::close(fds[k].fd);
        fds[k].fd = -1;
        --open_pipes;
      }
    }
  }
  int wstatus = 0;
  while (::waitpid(pid, &wstatus, 0) < 0 && errno == EINTR) {
  }
  c.status = WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : 1;
  if (WIFSIGNALED(wstatus)) c.err += "umbmark: the command was ended by signal " + std::to_string(WTERMSIG(wstatus));
  return c;
}

/// `value` as command-line words: a path or text as is, a number as Python
/// prints it (repr round-trips a float), a list or tuple item by item.
void AppendValue(std::vector<std::string>& args, const py::handle& value) {
  if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
    for (const py::handle item : value) AppendValue(args, item);
    return;
  }
  if (py::isinstance<py::float_>(value)) {
    args.push_back(py::repr(py::float_(py::cast<double>(value))));  // numpy float64 too
    return;
  }
  if (py::hasattr(value, "__fspath__")) {
    args.push_back(py::str(py::module_::import("os").attr("fspath")(value)));
    return;
  }
  args.push_back(py::str(value));
}

void ReplaceAll(std::string& text, const std::string& from, const std::string& to) {
  if (from.empty()) return;
  for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
}

/// The command's message: its stderr without the warnings and the "wrote"
/// lines (a warning is not the failure).
std::string FailureMessage(const std::string& err) {
  std::string message;
  std::size_t begin = 0;
  while (begin < err.size()) {
    std::size_t end = err.find('\n', begin);
    if (end == std::string::npos) end = err.size();
    const std::string line = err.substr(begin, end - begin);
    begin = end + 1;
    const bool warning = line.rfind("warning: ", 0) == 0 || line.find(": warning: ") != std::string::npos ||
                         line.rfind("wrote ", 0) == 0;
    if (!line.empty() && !warning) message += (message.empty() ? "" : "\n") + line;
  }
  return message.empty() ? std::string("umbmark: the command failed and said nothing on stderr") : message;
}

/// The arrays of `runs=` in a temporary folder, removed with this object.
struct TemporaryRuns {
  std::filesystem::path dir, csv;
  explicit TemporaryRuns(const std::string& text) {
    std::string pattern = (std::filesystem::temp_directory_path() / "umbmark-runs-XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) throw InputError(pattern, std::strerror(errno));
    dir = pattern;
    csv = dir / "arrays.csv";
    std::ofstream f(csv, std::ios::binary);
    f.write(text.data(), static_cast<std::streamsize>(text.size()));
    if (!f.flush()) throw InputError(csv.string(), "cannot write the arrays (disk full?)");
  }
  ~TemporaryRuns() {
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
  }
  TemporaryRuns(const TemporaryRuns&) = delete;
  TemporaryRuns& operator=(const TemporaryRuns&) = delete;
};

/// Runs `words` (e.g. {"import", "optiodom"}) with these inputs and options.
Result Run(const std::vector<std::string>& words, const py::args& inputs, const py::kwargs& options) {
  std::string command;
  for (const auto& w : words) command += (command.empty() ? "" : " ") + w;
  std::vector<std::string> args = words;
  std::optional<TemporaryRuns> runs;
  for (const auto& [key_handle, value] : options) {
    const std::string key = py::str(key_handle);
    if (key == "runs") {
      runs.emplace(TrajectoryCsv(TrajectoryFromArrays(value)));
      continue;
    }
    if (key == "json")
      throw InvalidOptions("json=: the module returns the JSON (result.to_dict()); write it with the json module");
    if (value.is_none() || (py::isinstance<py::bool_>(value) && !value.cast<bool>())) continue;
    std::string flag = "--" + key;
    for (char& c : flag) c = c == '_' ? '-' : c;
    args.push_back(flag);
    if (!py::isinstance<py::bool_>(value)) AppendValue(args, value);
  }
  args.insert(args.end(), {"--json", "-", "--"});
  for (const py::handle input : inputs) AppendValue(args, input);
  if (runs) args.push_back(runs->csv.string());

  const std::string exe = Executable();
  Completed done;
  {
    const py::gil_scoped_release release;
    done = Spawn(exe, args);
  }
  if (runs) {  // the arrays are called <runs> where a file's path would be
    ReplaceAll(done.out, runs->csv.string(), kRunsName);
    ReplaceAll(done.err, runs->csv.string(), kRunsName);
  }
  const bool has_json = !done.out.empty() && (done.out.front() == '{' || done.out.front() == '[');
  std::optional<std::string> json;
  if (has_json) json = done.out;
  if (done.status != 0) Raise(done.status, FailureMessage(done.err), json, command);
  if (!json) Raise(1, "umbmark: the command gave no JSON result: " + done.err, std::nullopt, command);
  return {command, *json};
}

/// The commands of the contract (docs/formats.md), as command-line words.
const std::vector<std::vector<std::string>>& Commands() {
  static const std::vector<std::vector<std::string>> commands = {
      {"calibrate"}, {"evaluate"}, {"fit-noise"}, {"predict"}, {"simulate"}, {"diagnose"}, {"summarize"},
      {"import", "optiodom"}, {"import", "rosbag2"}, {"plan"}, {"calibrate-lidar"}};
  return commands;
}

using InProcessFunction = Result (*)(const py::args&, const py::kwargs&);

/// The functions that run in this process (inprocess.hpp), else null.
const InProcessFunction* InProcess(const std::string& name) {
  static const std::map<std::string, InProcessFunction> functions = {{"calibrate", &CalibrateInProcess},
                                                                     {"predict", &PredictInProcess},
                                                                     {"fit_noise", &FitNoiseInProcess},
                                                                     {"summarize", &SummarizeInProcess},
                                                                     {"simulate", &SimulateInProcess},
                                                                     {"diagnose", &DiagnoseInProcess}};
  const auto it = functions.find(name);
  return it == functions.end() ? nullptr : &it->second;
}

std::string FunctionName(const std::vector<std::string>& words) {
  std::string name;
  for (const auto& w : words) name += (name.empty() ? "" : "_") + w;
  for (char& c : name) c = c == '-' ? '_' : c;
  return name;
}

}  // namespace

/// Translates the errors Run() raises before the command runs.
Result RunExecutable(const std::vector<std::string>& words, const py::args& inputs, const py::kwargs& options) {
  std::string command;
  for (const auto& w : words) command += (command.empty() ? "" : " ") + w;
  try {
    return Run(words, inputs, options);
  } catch (const InputError& e) {
    Raise(1, e.what(), std::nullopt, command);
  } catch (const InvalidOptions& e) {
    Raise(2, std::string("umbmark: ") + e.what(), std::nullopt, command);
  }
}

}  // namespace umbmark::python

PYBIND11_MODULE(umbmark, m) {
  using namespace umbmark::python;
  m.doc() = "umbmark: odometry calibration and sim-to-real diagnosis for differential-drive robots. One function "
            "per command (docs/python.md); each returns a Result whose to_dict() is the command's JSON.";
  m.attr("__version__") = umbmark::kVersion;
  // Ceres (the refined fit, in this process for the in-process functions)
  // logs through glog; its warnings would interleave with the caller's output.
  FLAGS_minloglevel = google::GLOG_FATAL;

  Errors& e = ErrorClasses();
  e.base = py::reinterpret_steal<py::object>(PyErr_NewExceptionWithDoc(
      "umbmark.Error", "An umbmark command failed; exit_status is the command line's exit status.", nullptr, nullptr));
  auto sub = [&](const char* name, const char* doc) {
    return py::reinterpret_steal<py::object>(PyErr_NewExceptionWithDoc(name, doc, e.base.ptr(), nullptr));
  };
  e.input = sub("umbmark.InputError", "Bad input or data (exit status 1); the message names the file and line.");
  e.usage = sub("umbmark.UsageError", "A bad option or argument (exit status 2).");
  e.quality_gate = sub("umbmark.QualityGateError", "The computation ran but failed a quality gate (exit status 3).");
  m.attr("Error") = e.base;
  m.attr("InputError") = e.input;
  m.attr("UsageError") = e.usage;
  m.attr("QualityGateError") = e.quality_gate;

  py::class_<Result>(m, "Result", "A command's result: to_dict() is its JSON; r['key'] and r.key read a top-level key.")
      .def_readonly("command", &Result::command, "The command that made it, e.g. 'calibrate'")
      .def_readonly("json", &Result::json, "The JSON text, exactly as `--json -` prints it")
      .def("to_dict", &Result::ToDict, "The JSON as Python objects (a new dict at every call)")
      .def("__getitem__",
           [](const Result& r, const std::string& key) -> py::object { return r.ToDict()[py::str(key)]; })
      .def("__contains__", [](const Result& r, const std::string& key) { return r.ToDict().contains(key); })
      .def("keys", [](const Result& r) { return r.ToDict().attr("keys")(); })
      .def("__getattr__",
           [](const Result& r, const std::string& key) -> py::object {
             const py::object d = r.ToDict();
             if (!d.contains(key)) throw py::attribute_error(key);
             return d[py::str(key)];
           })
      .def("__repr__", [](const Result& r) { return "<umbmark.Result of " + r.command + ">"; });

  py::list names;
  for (const auto& words : Commands()) {
    const std::string name = FunctionName(words);
    if (const auto* f = InProcess(name)) {
      m.def(name.c_str(), *f,
            ("Runs `umbmark " + name + "` in this process (umbmark's library, lib/api): the same as the command "
             "with `--json -` (`umbmark help " + name + "` lists the options). Positional arguments are the "
             "command's inputs; options are keyword arguments named as the long options with '-' as '_' (True for "
             "a flag); `runs=` gives trajectories as arrays, without a file (docs/python.md). Returns a Result "
             "whose to_dict() is the command's JSON.")
                .c_str());
      names.append(name);
      continue;
    }
    std::string command;
    for (const auto& w : words) command += (command.empty() ? "" : " ") + w;
    m.def(
        name.c_str(), [words](const py::args& a, const py::kwargs& k) { return RunExecutable(words, a, k); },
        ("Runs `umbmark " + command + "` and returns its JSON as a Result (`umbmark help " + command +
         "` lists the options). Positional arguments are the command's inputs; options are keyword arguments named "
         "as the long options with '-' as '_' (True for a flag); `runs=` gives trajectories as arrays "
         "(docs/python.md).")
            .c_str());
    names.append(name);
  }
  m.attr("commands") = names;
  m.attr("executable") = Executable();
}
