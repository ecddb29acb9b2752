// Keyword arguments as option values (see keywords.hpp).
#include "keywords.hpp"

#include <cmath>

#include <fmt/format.h>

#include "core/errors.hpp"

namespace py = pybind11;

namespace umbmark::python {

namespace {
[[noreturn]] void Usage(const std::string& message) { throw InvalidOptions(message); }
std::string Repr(const py::handle& value) { return py::repr(value); }
}  // namespace

std::string FlagOf(const std::string& key) {
  std::string flag = "--" + key;
  for (char& c : flag) c = c == '_' ? '-' : c;
  return flag;
}

void UnknownKeyword(const std::string& command, const std::string& key) {
  Usage(fmt::format("{} has no option {} (keyword {}=; help(umbmark.{}) lists them)", command, FlagOf(key), key,
                    command));
}

std::string Text(const std::string& key, const py::handle& value) {
  if (py::hasattr(value, "__fspath__")) return py::str(py::module_::import("os").attr("fspath")(value));
  if (!py::isinstance<py::str>(value)) Usage(fmt::format("{}: give a text or a path (got {})", FlagOf(key), Repr(value)));
  return py::str(value);
}

std::string Path(const std::string& key, const py::handle& value) {
  std::string path = Text(key, value);
  if (path.empty()) Usage(fmt::format("{}: empty path; give a file name", FlagOf(key)));
  if (path.find('\0') != std::string::npos) Usage(fmt::format("{}: the path contains a NUL byte", FlagOf(key)));
  return path;
}

double Number(const std::string& key, const py::handle& value) {
  if (py::isinstance<py::bool_>(value)) Usage(fmt::format("{}: give a number (got {})", FlagOf(key), Repr(value)));
  try {
    return py::float_(py::reinterpret_borrow<py::object>(value)).cast<double>();
  } catch (const py::error_already_set&) {
    Usage(fmt::format("{}: give a number (got {})", FlagOf(key), Repr(value)));
  }
}

int WholeNumber(const std::string& key, const py::handle& value) {
  const double x = Number(key, value);
  if (!(std::isfinite(x) && x == std::floor(x) && std::abs(x) < 2e9))
    Usage(fmt::format("{}: {} is not a whole number", FlagOf(key), Repr(value)));
  return static_cast<int>(x);
}

std::uint64_t Seed(const std::string& key, const py::handle& value) {
  // As the command line's validator: digits only, at most 2^64 - 1.
  // An int (numpy's integers too, through __index__) or a text of digits.
  const bool integer = !py::isinstance<py::bool_>(value) && PyIndex_Check(value.ptr());
  const std::string text = integer ? std::string(py::str(py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr()))))
                           : py::isinstance<py::str>(value) ? std::string(py::str(value))
                                                            : Repr(value);
  const bool digits = !text.empty() && text.size() <= 20 && text.find_first_not_of("0123456789") == std::string::npos;
  if (!digits || (text.size() == 20 && text > "18446744073709551615"))
    Usage(fmt::format("{}: the seed must be a whole number from 0 to 18446744073709551615 (got '{}')", FlagOf(key),
                      text));
  return std::stoull(text);
}

bool Truth(const py::handle& value) { return PyObject_IsTrue(value.ptr()) == 1; }

std::vector<std::string> List(const std::string& key, const py::handle& value) {
  std::vector<std::string> items;
  auto add = [&](const std::string& text) {
    std::size_t begin = 0;
    for (std::size_t comma; (comma = text.find(',', begin)) != std::string::npos; begin = comma + 1)
      items.push_back(text.substr(begin, comma - begin));
    items.push_back(text.substr(begin));
  };
  if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
    for (const py::handle item : value) add(py::isinstance<py::int_>(item) ? std::string(py::str(item)) : Text(key, item));
  } else {
    add(py::isinstance<py::int_>(value) ? std::string(py::str(value)) : Text(key, value));
  }
  return items;
}

std::vector<double> Numbers(const std::string& key, const py::handle& value) {
  std::vector<double> out;
  if (py::isinstance<py::str>(value)) {
    for (const std::string& item : List(key, value)) out.push_back(Number(key, py::str(item)));
    return out;
  }
  if (!py::isinstance<py::list>(value) && !py::isinstance<py::tuple>(value) && !py::hasattr(value, "__iter__"))
    return {Number(key, value)};
  for (const py::handle item : value) out.push_back(Number(key, item));
  return out;
}

}  // namespace umbmark::python
