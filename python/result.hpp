// What every function of the Python module returns and raises
// (docs/python.md): a Result holding the command's JSON, and the exception
// classes of the command line's exit statuses.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <pybind11/pybind11.h>

namespace umbmark::python {

/// A command's result: its JSON text (as `--json -` prints it), parsed on
/// demand.
struct Result {
  std::string command;
  std::string json;

  pybind11::object ToDict() const { return pybind11::module_::import("json").attr("loads")(json); }
};

/// The exception classes, created once at import.
struct Errors {
  pybind11::object base, input, usage, quality_gate;
};
Errors& ErrorClasses();

/// Raises the exception of exit status `status` (1 InputError, 2
/// UsageError, 3 QualityGateError) with `message`, `exit_status` and
/// `result` (the JSON the command still gave, else None).
/// Runs `umbmark WORDS... --json -` as a process of its own (the functions
/// not yet in-process): inputs and keyword arguments as command-line words.
Result RunExecutable(const std::vector<std::string>& words, const pybind11::args& inputs,
                     const pybind11::kwargs& options);

[[noreturn]] void Raise(int status, const std::string& message, const std::optional<std::string>& json,
                        const std::string& command);

}  // namespace umbmark::python
