// Error types thrown by the library. Every loader and check reports faults by
// throwing one of these (documented on each API); apps map them to exit codes:
//   InputError       -> exit 1 (bad input or data; names file, line, column)
//   QualityGateError -> exit 3 (the computation ran but failed a quality gate)
// Nothing else in lib/ is meant to escape to the user.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>

namespace umbmark {

/// A fault in input data. line/column are 1-based; 0 means "not applicable"
/// (a whole-file fault). what() is formatted per the contract:
/// "FILE:LINE:COLUMN: message" or "FILE: message".
class InputError : public std::runtime_error {
 public:
  InputError(std::string file, std::size_t line, std::size_t column, std::string message)
      : std::runtime_error(Format(file, line, column, message)),
        file_(std::move(file)), line_(line), column_(column), message_(std::move(message)) {}
  InputError(std::string file, std::string message) : InputError(std::move(file), 0, 0, std::move(message)) {}

  const std::string& file() const { return file_; }
  std::size_t line() const { return line_; }
  std::size_t column() const { return column_; }
  const std::string& message() const { return message_; }

 private:
  static std::string Format(const std::string& file, std::size_t line, std::size_t column,
                            const std::string& message) {
    std::string out = file.empty() ? std::string("<input>") : file;
    // Appended piecewise: `":" + std::to_string(n)` trips GCC 12's -Wrestrict
    // false positive (GCC bug 105329) at -O3.
    if (line > 0) {
      out += ':';
      out += std::to_string(line);
      if (column > 0) {
        out += ':';
        out += std::to_string(column);
      }
    }
    out += ": ";
    out += message;
    return out;
  }
  std::string file_;
  std::size_t line_;
  std::size_t column_;
  std::string message_;
};

/// The computation ran but its result is not usable (solver failure,
/// rank-deficient problem, ...). Apps exit with status 3.
class QualityGateError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// An options struct holds an invalid value; the message names the field,
/// its value and the rule it broke (Ceres style). Apps treat it as usage (2)
/// when it comes from flags and as input (1) when it comes from a file.
class InvalidOptions : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

}  // namespace umbmark
