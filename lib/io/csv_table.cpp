// Shared CSV tokenizer and column resolver of the io/ readers (see
// csv_table.hpp for the format it accepts).
#include "io/csv_table.hpp"

#include <charconv>
#include <cmath>
#include <cstring>
#include <system_error>

#include <fast_float/fast_float.h>
#include <fmt/format.h>

#include "core/angles.hpp"
#include "core/errors.hpp"

namespace umbmark::io::detail {
namespace {

constexpr std::string_view kBom = "\xEF\xBB\xBF";

using csv_internal::IsBlank;

inline std::string_view Trim(const char* b, const char* e) {
  while (b < e && IsBlank(*b)) ++b;
  while (e > b && IsBlank(e[-1])) --e;
  return {b, static_cast<std::size_t>(e - b)};
}

/// Unit suffixes a quantity accepts, with their factor to SI.
struct UnitSuffix {
  std::string_view suffix;
  double multiply;
  double divide;
};

std::span<const UnitSuffix> SuffixesOf(Quantity q) {
  static constexpr UnitSuffix kLength[] = {{"m", 1.0, 1.0}, {"mm", 1.0, 1000.0}};
  static constexpr UnitSuffix kAngle[] = {{"rad", 1.0, 1.0}, {"deg", kPi, 180.0}};
  static constexpr UnitSuffix kTime[] = {{"s", 1.0, 1.0}};
  switch (q) {
    case Quantity::kLength: return kLength;
    case Quantity::kAngle: return kAngle;
    case Quantity::kTime: return kTime;
    case Quantity::kText:
    case Quantity::kCount: break;
  }
  return {};
}

bool IsUnitSuffix(std::string_view suffix) {
  for (const Quantity q : {Quantity::kLength, Quantity::kAngle, Quantity::kTime}) {
    for (const auto& u : SuffixesOf(q)) {
      if (u.suffix == suffix) return true;
    }
  }
  return false;
}

/// "ex_m or ex_mm" for messages.
std::string AcceptedNames(const ColumnSpec& spec) {
  std::string out;
  const auto suffixes = SuffixesOf(spec.quantity);
  for (std::size_t k = 0; k < suffixes.size(); ++k) {
    if (k > 0) out += k + 1 == suffixes.size() ? " or " : ", ";
    out += fmt::format("{}_{}", spec.base, suffixes[k].suffix);
  }
  return out;
}

std::string PrimaryName(const ColumnSpec& spec) {
  const auto suffixes = SuffixesOf(spec.quantity);
  if (suffixes.empty()) return std::string(spec.base);
  return fmt::format("{}_{}", spec.base, suffixes[0].suffix);
}

}  // namespace

std::string QuoteForMessage(std::string_view text) {
  constexpr std::size_t kMaxBytes = 48;
  std::string out = "'";
  std::size_t i = 0;
  while (i < text.size()) {
    if (i >= kMaxBytes) {
      out += "...";
      break;
    }
    const auto c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7F) {
      out += static_cast<char>(c);
      ++i;
      continue;
    }
    // Pass a well-formed UTF-8 sequence through; escape anything else.
    std::size_t len = c >= 0xF0 && c < 0xF5 ? 4 : c >= 0xE0 ? 3 : c >= 0xC2 && c < 0xE0 ? 2 : 0;
    bool valid = len > 0 && i + len <= text.size();
    for (std::size_t k = 1; valid && k < len; ++k) {
      valid = (static_cast<unsigned char>(text[i + k]) & 0xC0) == 0x80;
    }
    if (valid) {
      out.append(text.substr(i, len));
      i += len;
    } else {
      out += fmt::format("\\x{:02X}", static_cast<unsigned>(c));
      ++i;
    }
  }
  return out + "'";
}

CsvReader::CsvReader(std::string_view text, std::string name) : text_(text), name_(std::move(name)) {
  if (text_.substr(0, kBom.size()) == kBom) text_.remove_prefix(kBom.size());
  if (!NextContentLine()) FailFile("empty file: no header row");
  header_line_ = line_;
  header_bytes_ = static_cast<std::size_t>(line_end_ - line_begin_) + 1;
  const char* c = line_begin_;
  for (;;) {
    const char* e = c;
    while (e < line_end_ && *e != ',') ++e;
    const std::string_view cell = Trim(c, e);
    header_.push_back(cell);
    header_columns_.push_back(ColumnOf(cell.data()));
    if (e == line_end_) break;
    c = e + 1;
  }
  for (std::size_t i = 0; i < header_.size(); ++i) {
    if (header_[i].empty()) FailHeader(i, fmt::format("empty column name in header (column {})", i + 1));
    for (std::size_t j = 0; j < i; ++j) {
      if (header_[j] == header_[i]) {
        FailHeader(i, fmt::format("duplicated column {} (also at column {})", QuoteForMessage(header_[i]),
                                  header_columns_[j]));
      }
    }
  }
  cells_.resize(header_.size());
}

std::size_t CsvReader::EstimatedRows() const { return text_.size() / header_bytes_ + 1; }

std::vector<ResolvedColumn> CsvReader::Resolve(std::span<const ColumnSpec> specs) const {
  std::vector<ResolvedColumn> out(specs.size());
  for (std::size_t i = 0; i < header_.size(); ++i) {
    const std::string_view name = header_[i];
    // The longest base that is the whole name or the name up to a '_'.
    std::size_t best = specs.size();
    for (std::size_t s = 0; s < specs.size(); ++s) {
      const std::string_view base = specs[s].base;
      const bool match = name == base || (name.size() > base.size() + 1 && name.substr(0, base.size()) == base &&
                                          name[base.size()] == '_');
      if (match && (best == specs.size() || base.size() > specs[best].base.size())) best = s;
    }
    // A text or count column followed by something other than a unit
    // (run_id, ticks_left_raw) is just an unknown column.
    if (best < specs.size() && SuffixesOf(specs[best].quantity).empty() && name != specs[best].base &&
        !IsUnitSuffix(name.substr(specs[best].base.size() + 1))) {
      best = specs.size();
    }
    if (best == specs.size()) {
      std::string expected;
      for (const auto& spec : specs) expected += (expected.empty() ? "" : ", ") + PrimaryName(spec);
      FailHeader(i, fmt::format("unknown column {} (expected columns: {})", QuoteForMessage(name), expected));
    }
    const ColumnSpec& spec = specs[best];
    const auto suffixes = SuffixesOf(spec.quantity);
    double multiply = 1.0, divide = 1.0;
    if (suffixes.empty()) {
      if (name != spec.base) {
        FailHeader(i, fmt::format("column {}: {} takes no unit suffix (expected '{}')", QuoteForMessage(name),
                                  spec.base, spec.base));
      }
    } else if (name == spec.base) {
      FailHeader(i, fmt::format("column {} has no unit suffix (expected {})", QuoteForMessage(name),
                                AcceptedNames(spec)));
    } else {
      const std::string_view suffix = name.substr(spec.base.size() + 1);
      bool known = false;
      for (const auto& u : suffixes) {
        if (u.suffix == suffix) {
          known = true;
          multiply = u.multiply;
          divide = u.divide;
        }
      }
      if (!known) {
        FailHeader(i, fmt::format("column {} has an unknown unit suffix {} (expected {})", QuoteForMessage(name),
                                  QuoteForMessage(fmt::format("_{}", suffix)), AcceptedNames(spec)));
      }
    }
    ResolvedColumn& r = out[best];
    if (r.present()) {
      FailHeader(i, fmt::format("column {} gives {} a second time (already column {}, {})", QuoteForMessage(name),
                                spec.base, header_columns_[r.index], QuoteForMessage(r.header)));
    }
    r.index = i;
    r.header = std::string(name);
    r.multiply = multiply;
    r.divide = divide;
  }
  return out;
}

bool CsvReader::NextContentLine() {
  const char* const data = text_.data();
  const std::size_t size = text_.size();
  while (pos_ < size) {
    const char* b = data + pos_;
    const auto* nl = static_cast<const char*>(std::memchr(b, '\n', size - pos_));
    const char* e = nl != nullptr ? nl : data + size;
    pos_ = nl != nullptr ? static_cast<std::size_t>(nl - data) + 1 : size;
    line_ = next_line_++;
    const char* le = e;
    if (le > b && le[-1] == '\r') --le;
    const char* q = b;
    while (q < le && IsBlank(*q)) ++q;
    if (q == le || *q == '#') continue;
    line_begin_ = b;
    line_end_ = le;
    return true;
  }
  return false;
}

bool CsvReader::HasNoDataRows() const {
  CsvReader copy = *this;
  return !copy.NextContentLine();
}

bool CsvReader::SkipIfBlankOrComment(const char* b) {
  const char* const end = text_.data() + text_.size();
  const char* q = b;
  while (q < end && IsBlank(*q)) ++q;
  if (q < end && *q == '\r' && (q + 1 == end || q[1] == '\n')) ++q;
  if (q < end && *q != '#' && *q != '\n') return false;
  const auto* nl = static_cast<const char*>(std::memchr(q, '\n', static_cast<std::size_t>(end - q)));
  pos_ = nl != nullptr ? static_cast<std::size_t>(nl - text_.data()) + 1 : text_.size();
  return true;
}

void CsvReader::FailCellCount(std::size_t n) const {
  const std::size_t expected = cells_.size();
  const char* at = line_end_;
  if (n > expected) {
    at = extra_;
    while (at < line_end_ && IsBlank(*at)) ++at;
  }
  throw InputError(name_, line_, ColumnOf(at),
                   fmt::format("row has {} cells but the header has {}{}", n, expected,
                               n < expected ? " (truncated row?)" : ""));
}

std::size_t CsvReader::ColumnIn(const char* row_begin, const char* p) {
  std::size_t column = 1;
  for (const char* q = row_begin; q < p; ++q) {
    if ((static_cast<unsigned char>(*q) & 0xC0) != 0x80) ++column;
  }
  return column;
}

std::size_t CsvReader::ColumnOf(const char* p) const { return ColumnIn(line_begin_, p); }

std::size_t CsvReader::Column(std::size_t i) const { return ColumnOf(cells_[i].data()); }

void CsvReader::FailCell(std::size_t i, const std::string& message) const {
  throw InputError(name_, line_, Column(i), message);
}

void CsvReader::FailLine(std::size_t line, const std::string& message) const {
  throw InputError(name_, line, 0, message);
}

void CsvReader::FailAt(std::size_t line, std::size_t column, const std::string& message) const {
  throw InputError(name_, line, column, message);
}

void CsvReader::FailFile(const std::string& message) const { throw InputError(name_, message); }

void CsvReader::FailHeader(std::size_t i, const std::string& message) const {
  throw InputError(name_, header_line_, header_columns_[i], message);
}

void CsvReader::FailNumber(const ResolvedColumn& c, std::string_view cell, const char* what) const {
  FailCell(c.index, fmt::format("{}: {} {}", c.header, QuoteForMessage(cell), what));
}

void CsvReader::FailEmpty(const ResolvedColumn& c) const {
  FailCell(c.index, fmt::format("{}: empty cell", c.header));
}

void CsvReader::FailQuoted(const ResolvedColumn& c) const {
  FailCell(c.index,
           fmt::format("{}: quoted cells are not supported ({})", c.header, QuoteForMessage(cells_[c.index])));
}

double CsvReader::ParseNumberSlow(const ResolvedColumn& c, std::string_view s) const {
  double v = 0.0;
  const char* const end = s.data() + s.size();
  const auto r = fast_float::from_chars(s.data(), end, v);
  if (r.ptr != end || (r.ec != std::errc() && r.ec != std::errc::result_out_of_range)) {
    FailNumber(c, s, "is not a number");
  }
  if (std::isnan(v)) FailNumber(c, s, "is NaN, which is not allowed (leave the cell empty if unknown)");
  if (!std::isfinite(v)) FailNumber(c, s, "is infinite or out of range");
  return v;
}

std::int64_t CsvReader::ParseCountSlow(const ResolvedColumn& c, std::string_view s) const {
  if (s.empty()) FailEmpty(c);
  std::int64_t v = 0;
  const char* const end = s.data() + s.size();
  const auto r = std::from_chars(s.data(), end, v);
  if (r.ec == std::errc::result_out_of_range) FailNumber(c, s, "is out of the signed 64-bit range");
  if (r.ec != std::errc() || r.ptr != end) FailNumber(c, s, "is not an integer count");
  return v;
}

}  // namespace umbmark::io::detail
