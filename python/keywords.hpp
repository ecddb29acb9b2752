// Keyword arguments as option values (the in-process functions of the
// Python module): each converter names the option as the command line's
// flag in its message (a usage error, InvalidOptions), so `side="x"` says
// what `--side x` would.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <pybind11/pybind11.h>

namespace umbmark::python {

/// "--no-heldout" for "no_heldout"; "--E-d" for "E_d".
std::string FlagOf(const std::string& key);

/// A text: str, or anything with __fspath__ (a path).
std::string Text(const std::string& key, const pybind11::handle& value);
/// A path option: as Text, never empty (the command line's rule).
std::string Path(const std::string& key, const pybind11::handle& value);
/// A number: int, float (numpy's too) or a text holding one; never a bool.
double Number(const std::string& key, const pybind11::handle& value);
/// A whole number of int's range.
int WholeNumber(const std::string& key, const pybind11::handle& value);
/// A seed: a whole number from 0 to 2^64 - 1 (the command line's message).
std::uint64_t Seed(const std::string& key, const pybind11::handle& value);
/// A flag: Python's truth of the value (True gives it).
bool Truth(const pybind11::handle& value);
/// A list option: a text (split at commas, as the command line's
/// delimiter), or a list or tuple of them.
std::vector<std::string> List(const std::string& key, const pybind11::handle& value);
/// Numbers: a list or tuple of numbers, or a text of comma-separated ones.
std::vector<double> Numbers(const std::string& key, const pybind11::handle& value);

/// Throws InvalidOptions: `command` has no option `key`.
[[noreturn]] void UnknownKeyword(const std::string& command, const std::string& key);

/// How one keyword sets an options struct O.
template <class O>
using Setter = std::function<void(O&, const std::string& key, const pybind11::handle& value)>;

/// Applies every keyword of `kwargs` but those in `skip` with its setter;
/// None leaves the default. Throws InvalidOptions for an unknown keyword,
/// naming it as a flag.
template <class O>
void ApplyKeywords(O& options, const pybind11::kwargs& kwargs, const std::map<std::string, Setter<O>>& setters,
                   const std::string& command, const std::vector<std::string>& skip = {}) {
  for (const auto& [key_handle, value] : kwargs) {
    const std::string key = pybind11::str(key_handle);
    if (value.is_none() || std::find(skip.begin(), skip.end(), key) != skip.end()) continue;
    const auto it = setters.find(key);
    if (it == setters.end()) UnknownKeyword(command, key);
    it->second(options, key, value);
  }
}

}  // namespace umbmark::python
