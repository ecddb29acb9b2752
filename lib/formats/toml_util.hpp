// Internal to formats/: helpers shared by the robot-file and manifest readers on
// top of toml++ — parse errors and value faults become InputError carrying
// the file name and the 1-based line/column of the offending key or value.
#pragma once

#include <initializer_list>
#include <string>
#include <string_view>

#include <toml++/toml.h>

namespace umbmark::io::detail {

/// Parses TOML text; a syntax error becomes InputError(name, line, column,
/// "TOML syntax error: ...").
toml::table ParseTomlText(std::string_view text, const std::string& name);

/// Throws InputError at the start of `where`; line 0 (no source) -> whole file.
[[noreturn]] void FailAt(const std::string& name, const toml::source_region& where, const std::string& message);

/// "integer", "string", "table", ... for messages.
std::string_view TypeName(const toml::node& node);

/// A TOML integer or float as double; throws InputError at the value for any
/// other type and for NaN/Inf.
double NumberValue(const toml::node& node, std::string_view key, const std::string& name);

/// A TOML string; throws InputError at the value for any other type.
std::string StringValue(const toml::node& node, std::string_view key, const std::string& name);

/// Throws InputError at the first key of `table` not in `allowed`;
/// `what` names the table in the message ("the robot file", "[ground_truth]").
void RejectUnknownKeys(const toml::table& table, std::initializer_list<std::string_view> allowed,
                       std::string_view what, const std::string& name);

}  // namespace umbmark::io::detail
