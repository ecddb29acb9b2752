// Shared toml++ helpers of the robot-file and manifest readers (toml_util.hpp).
#include "formats/toml_util.hpp"

#include <cmath>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "formats/csv_table.hpp"

namespace umbmark::io::detail {

toml::table ParseTomlText(std::string_view text, const std::string& name) {
  try {
    return toml::parse(text, std::string_view(name));
  } catch (const toml::parse_error& e) {
    FailAt(name, e.source(), fmt::format("TOML syntax error: {}", e.description()));
  }
}

void FailAt(const std::string& name, const toml::source_region& where, const std::string& message) {
  throw InputError(name, where.begin.line, where.begin.line > 0 ? where.begin.column : 0, message);
}

std::string_view TypeName(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::none: return "nothing";
    case toml::node_type::table: return "a table";
    case toml::node_type::array: return "an array";
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a float";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::date: return "a date";
    case toml::node_type::time: return "a time";
    case toml::node_type::date_time: return "a date-time";
  }
  return "an unknown type";
}

double NumberValue(const toml::node& node, std::string_view key, const std::string& name) {
  double v = 0.0;
  if (const auto* i = node.as_integer()) {
    v = static_cast<double>(i->get());
  } else if (const auto* f = node.as_floating_point()) {
    v = f->get();
  } else {
    FailAt(name, node.source(), fmt::format("{} must be a number, not {}", key, TypeName(node)));
  }
  if (!std::isfinite(v)) FailAt(name, node.source(), fmt::format("{} = {} must be finite", key, v));
  return v;
}

std::string StringValue(const toml::node& node, std::string_view key, const std::string& name) {
  const auto* s = node.as_string();
  if (s == nullptr) FailAt(name, node.source(), fmt::format("{} must be a string, not {}", key, TypeName(node)));
  return s->get();
}

void RejectUnknownKeys(const toml::table& table, std::initializer_list<std::string_view> allowed,
                       std::string_view what, const std::string& name) {
  for (auto&& [key, node] : table) {
    bool known = false;
    for (const auto a : allowed) known = known || key.str() == a;
    if (known) continue;
    std::string expected;
    for (const auto a : allowed) expected += fmt::format("{}{}", expected.empty() ? "" : ", ", a);
    FailAt(name, key.source(),
           fmt::format("unknown key {} in {} (expected {})", QuoteForMessage(key.str()), what, expected));
  }
}

}  // namespace umbmark::io::detail
