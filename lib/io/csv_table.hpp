// Internal to io/: the shared CSV tokenizer and column resolver behind the
// endpoint and trajectory readers. Format (contract): comma separated, one
// header row, a line whose first non-blank character is `#` is a comment,
// blank lines are ignored, optional UTF-8 BOM, `\n` or `\r\n` line ends.
// Cells are trimmed of spaces and tabs; quoting is not part of the format
// (a `"` in a text cell is rejected rather than half-interpreted).
//
// The reader works on text already in memory and never allocates per cell:
// a row is a vector of string_views into the text. Line numbers are tracked
// per row; the column of a cell (1-based, in UTF-8 characters) is computed
// only when an error is reported.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace umbmark::io::detail {

/// Physical kind of a column, deciding which unit suffixes it accepts.
enum class Quantity {
  kText,    ///< free text, no suffix (run, direction)
  kCount,   ///< signed 64-bit integer, no suffix (ticks_left)
  kLength,  ///< _m, or _mm (divided by 1000)
  kAngle,   ///< _rad, or _deg (times pi/180)
  kTime,    ///< _s
};

/// A column a reader knows, by its base name (without unit suffix).
struct ColumnSpec {
  std::string_view base;
  Quantity quantity;
};

/// Where a known column sits in the file and how to convert it to SI.
struct ResolvedColumn {
  static constexpr std::size_t kAbsent = static_cast<std::size_t>(-1);
  std::size_t index = kAbsent;  ///< 0-based cell index in each row
  std::string header;           ///< the name as written, for messages
  double multiply = 1.0;        ///< SI value = cell * multiply / divide
  double divide = 1.0;
  bool present() const { return index != kAbsent; }
};

/// Quotes a piece of input for an error message: printable ASCII and valid
/// UTF-8 pass through, other bytes become \xNN; long text is shortened.
std::string QuoteForMessage(std::string_view text);

class CsvReader {
 public:
  /// Skips BOM, comments and blank lines and splits the header row. Throws
  /// InputError(name, ...) for an empty file (no header) and for an empty or
  /// duplicated header name.
  CsvReader(std::string_view text, std::string name);

  const std::string& name() const { return name_; }
  std::size_t num_columns() const { return header_.size(); }
  std::string_view header(std::size_t i) const { return header_[i]; }
  std::size_t header_line() const { return header_line_; }
  /// Rough number of data rows (text size / header-line size), for reserve().
  std::size_t EstimatedRows() const;

  /// Resolves every header name against `specs` (one result per spec, same
  /// order). Throws InputError at the header cell for a known quantity with a
  /// missing or unknown unit suffix, for the same quantity given twice (e.g.
  /// ex_m and ex_mm), and for a column no spec knows. Unknown columns are an
  /// error on purpose: a typo (`ex_n`, `ticks_lef`) must not silently drop data.
  std::vector<ResolvedColumn> Resolve(std::span<const ColumnSpec> specs) const;

  /// Advances to the next data row; false at the end of the text. Throws
  /// InputError at the row when its cell count differs from the header's.
  inline bool Next();
  /// True when no data row follows the header (call before Next()).
  bool HasNoDataRows() const;

  std::size_t line() const { return line_; }
  std::string_view cell(std::size_t i) const { return cells_[i]; }

  /// 1-based column (UTF-8 characters) of cell i of the current row.
  std::size_t Column(std::size_t i) const;
  /// Start of the current row in the text (stays valid while the text does),
  /// for reporting a fault in an earlier row with ColumnIn().
  const char* row_begin() const { return line_begin_; }
  /// 1-based column of `p` in the row starting at `row_begin`.
  static std::size_t ColumnIn(const char* row_begin, const char* p);

  [[noreturn]] void FailCell(std::size_t i, const std::string& message) const;
  [[noreturn]] void FailLine(std::size_t line, const std::string& message) const;
  [[noreturn]] void FailAt(std::size_t line, std::size_t column, const std::string& message) const;
  [[noreturn]] void FailFile(const std::string& message) const;

  /// Numeric cells, converted to SI with the column's factor. Throw InputError
  /// at the cell for an empty cell (except Optional*), text, trailing garbage,
  /// NaN or Inf.
  inline double Number(const ResolvedColumn& c) const;
  /// Returns false (leaving `out` untouched) when the cell is empty.
  inline bool OptionalNumber(const ResolvedColumn& c, double& out) const;
  inline std::int64_t Count(const ResolvedColumn& c) const;
  /// A non-empty text cell without a double quote.
  inline std::string_view Text(const ResolvedColumn& c) const;

 private:
  /// Finds the next line that is neither blank nor a comment, starting at
  /// pos_. Sets line_, line_begin_, line_end_ (without \r). False at end.
  bool NextContentLine();
  /// The line at `b` (whose first byte is a blank, `#` or a line end) is
  /// blank or a comment: skips it (advancing pos_) and returns true.
  bool SkipIfBlankOrComment(const char* b);
  std::size_t ColumnOf(const char* p) const;
  /// The general number parser (fast_float) with all the checks.
  double ParseNumberSlow(const ResolvedColumn& c, std::string_view s) const;
  std::int64_t ParseCountSlow(const ResolvedColumn& c, std::string_view s) const;
  [[noreturn]] void FailCellCount(std::size_t n) const;
  [[noreturn]] void FailEmpty(const ResolvedColumn& c) const;
  [[noreturn]] void FailQuoted(const ResolvedColumn& c) const;
  [[noreturn]] void FailHeader(std::size_t i, const std::string& message) const;
  [[noreturn]] void FailNumber(const ResolvedColumn& c, std::string_view cell, const char* what) const;

  std::string_view text_;
  std::string name_;
  std::size_t pos_ = 0;  ///< offset of the next unread line
  std::size_t line_ = 0;
  std::size_t next_line_ = 1;  ///< number of the line at pos_
  const char* line_begin_ = nullptr;
  const char* line_end_ = nullptr;
  const char* extra_ = nullptr;
  std::size_t header_line_ = 0;
  std::size_t header_bytes_ = 1;
  std::vector<std::string_view> header_;
  std::vector<std::size_t> header_columns_;  ///< 1-based column of each name
  std::vector<std::string_view> cells_;
};

// ---- Hot paths, inline: one call per row / cell of a large log. ----------

namespace csv_internal {

inline bool IsBlank(char c) { return c == ' ' || c == '\t'; }

inline bool IsDigit(char c) { return static_cast<unsigned char>(c - '0') < 10; }

/// Exact powers of ten up to 1e22 (all representable in a double).
inline constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                    1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

/// Fast path for the plain decimals logs are made of: [-]digits[.digits]
/// with at most 15 digits. Then mantissa < 2^53 and the power of ten is
/// exact, so one IEEE division gives the correctly rounded value (Clinger's
/// fast path), identical to what fast_float returns. False for anything else
/// (exponent, NaN, long numbers, garbage), which goes to the slow parser.
inline bool ParseSimpleDecimal(const char* p, const char* end, double& out) {
  const bool negative = p < end && *p == '-';
  if (negative) ++p;
  std::uint64_t mantissa = 0;
  int digits = 0;
  while (p < end && IsDigit(*p)) {
    mantissa = mantissa * 10 + static_cast<std::uint64_t>(*p - '0');
    ++p;
    ++digits;
  }
  int fraction = 0;
  if (p < end && *p == '.') {
    ++p;
    while (p < end && IsDigit(*p)) {
      mantissa = mantissa * 10 + static_cast<std::uint64_t>(*p - '0');
      ++p;
      ++fraction;
    }
    digits += fraction;
  }
  if (p != end || digits == 0 || digits > 15) return false;
  const double v = static_cast<double>(mantissa) / kPow10[fraction];
  out = negative ? -v : v;
  return true;
}

/// Fast path for counts: [-]digits, at most 18 digits (no overflow).
inline bool ParseSimpleCount(const char* p, const char* end, std::int64_t& out) {
  const bool negative = p < end && *p == '-';
  if (negative) ++p;
  const char* const first = p;
  std::uint64_t v = 0;  // unsigned: wraps harmlessly past 18 digits, then rejected
  while (p < end && IsDigit(*p)) {
    v = v * 10 + static_cast<std::uint64_t>(*p - '0');
    ++p;
  }
  if (p != end || p == first || p - first > 18) return false;
  const auto s = static_cast<std::int64_t>(v);
  out = negative ? -s : s;
  return true;
}

}  // namespace csv_internal

inline bool CsvReader::Next() {
  using csv_internal::IsBlank;
  const char* const data = text_.data();
  const char* const end = data + text_.size();
  for (;;) {
    const char* const b = data + pos_;
    if (b >= end) return false;
    line_ = next_line_++;
    const char c0 = *b;
    if ((c0 == '#' || c0 == '\n' || c0 == '\r' || IsBlank(c0)) && SkipIfBlankOrComment(b)) continue;
    // One pass: split at commas up to the line end.
    const std::size_t expected = cells_.size();
    std::string_view* const cells = cells_.data();
    std::size_t n = 0;
    const char* c = b;
    const char* e = b;
    for (;;) {
      while (e < end && *e != ',' && *e != '\n') ++e;
      if (n < expected) {
        cells[n] = std::string_view(c, static_cast<std::size_t>(e - c));
      } else if (n == expected) {
        extra_ = c;
      }
      ++n;
      if (e == end || *e == '\n') break;
      c = ++e;
    }
    pos_ = static_cast<std::size_t>(e - data) + (e < end ? 1 : 0);
    line_begin_ = b;
    line_end_ = e > b && e[-1] == '\r' ? e - 1 : e;
    if (n != expected) FailCellCount(n);
    // Drop the \r of a CRLF line end and blanks around cells.
    std::string_view& last = cells[expected - 1];
    if (!last.empty() && last.back() == '\r') last.remove_suffix(1);
    for (std::size_t i = 0; i < expected; ++i) {
      std::string_view& s = cells[i];
      if (!s.empty() && (IsBlank(s.front()) || IsBlank(s.back()))) {
        while (!s.empty() && IsBlank(s.front())) s.remove_prefix(1);
        while (!s.empty() && IsBlank(s.back())) s.remove_suffix(1);
      }
    }
    return true;
  }
}

inline bool CsvReader::OptionalNumber(const ResolvedColumn& c, double& out) const {
  const std::string_view s = cells_[c.index];
  if (s.empty()) return false;
  double v = 0.0;
  if (!csv_internal::ParseSimpleDecimal(s.data(), s.data() + s.size(), v)) v = ParseNumberSlow(c, s);
  if (c.multiply != 1.0 || c.divide != 1.0) {
    v = v * c.multiply / c.divide;
    if (!std::isfinite(v)) FailNumber(c, s, "is infinite or out of range");
  }
  out = v;
  return true;
}

inline double CsvReader::Number(const ResolvedColumn& c) const {
  double v = 0.0;
  if (!OptionalNumber(c, v)) FailEmpty(c);
  return v;
}

inline std::int64_t CsvReader::Count(const ResolvedColumn& c) const {
  const std::string_view s = cells_[c.index];
  std::int64_t v = 0;
  if (csv_internal::ParseSimpleCount(s.data(), s.data() + s.size(), v)) return v;
  return ParseCountSlow(c, s);
}

inline std::string_view CsvReader::Text(const ResolvedColumn& c) const {
  const std::string_view s = cells_[c.index];
  if (s.empty()) FailEmpty(c);
  if (s.find('"') != std::string_view::npos) FailQuoted(c);
  return s;
}

}  // namespace umbmark::io::detail
