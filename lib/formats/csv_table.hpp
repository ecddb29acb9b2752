// Internal to formats/: the shared CSV tokenizer and column resolver behind the
// endpoint and trajectory readers. Format (contract): comma separated, one
// header row, a line whose first non-blank character is `#` is a comment,
// blank lines are ignored, optional UTF-8 BOM, `\n` or `\r\n` line ends.
// Cells are trimmed of spaces and tabs. A cell may be quoted as RFC 4180
// says: "..." holding commas, line breaks and doubled quotes ("") for one
// `"`; blanks around the quotes are ignored, inside them kept. A `"` inside
// an unquoted cell, text after a closing quote and an unterminated quote
// are errors. (Data rows only: header names are never quoted.)
//
// The reader streams: it read()s the input into one buffer (1 MiB, grown
// only for a longer line, up to kMaxLineBytes) and hands out one row at a
// time as string_views into it, so memory does not grow with the file. It
// never allocates per cell; delimiters are found 16 bytes at a time (SSE2).
// Line numbers are tracked per row; the column of a cell (1-based, in UTF-8
// characters) is computed only when an error is reported.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <span>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "formats/file_text.hpp"

namespace umbmark::io::detail {

/// Physical kind of a column, deciding which unit suffixes it accepts.
enum class Quantity {
  kText,    ///< free text, no suffix (run, direction)
  kCount,   ///< signed 64-bit integer, no suffix (ticks_left)
  kLength,  ///< _m, or _mm (divided by 1000)
  kAngle,   ///< _rad, or _deg (times pi/180)
  kTime,    ///< _s
};

/// The largest magnitudes a number cell may have, in SI units: no robot run
/// measures 10,000 km or turns 1.6 million times, and 1e12 s (31,700 years)
/// still holds any time stamp in seconds (ROS epoch stamps are ~1.7e9 s).
/// Beyond them a value is an export or unit error, refused with its cell.
inline constexpr double kMaxLengthM = 1e7;
inline constexpr double kMaxAngleRad = 1e7;
inline constexpr double kMaxTimeS = 1e12;

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
  /// Largest |SI value| accepted (kMaxLengthM, ... by quantity): beyond it a
  /// number is no measurement (1e308 m) and would overflow the statistics.
  double max_abs = std::numeric_limits<double>::infinity();
  bool present() const { return index != kAbsent; }
};

/// Quotes a piece of input for an error message: printable ASCII and valid
/// UTF-8 pass through, other bytes become \xNN; long text is shortened.
std::string QuoteForMessage(std::string_view text);

class CsvReader {
 public:
  /// Read buffer of a file (grown for a longer line, up to kMaxLineBytes).
  static constexpr std::size_t kDefaultBufferBytes = std::size_t{1} << 20;

  /// Skips BOM, comments and blank lines and splits the header row. Throws
  /// InputError(name, ...) for an empty file (no header), an empty or
  /// duplicated header name, a second BOM, CR-only line ends, and a line
  /// longer than kMaxLineBytes. `buffer_bytes` is the initial read buffer
  /// (tests use a few bytes to exercise every chunk boundary).
  CsvReader(InputStream in, std::string name, std::size_t buffer_bytes = kDefaultBufferBytes);
  /// Text in memory, read through the same buffer (in chunks of at most
  /// `max_chunk` bytes when given).
  CsvReader(std::string_view text, std::string name, std::size_t max_chunk = 0, std::size_t buffer_bytes = 0);
  /// A part of a file that starts at a row boundary: no header of its own,
  /// `header_from`'s header instead, and `first_line` the file's line number
  /// of its first byte (messages name the file's lines).
  CsvReader(InputStream in, std::string name, const CsvReader& header_from, std::size_t first_line);
  CsvReader(const CsvReader&) = delete;
  CsvReader& operator=(const CsvReader&) = delete;

  const std::string& name() const { return name_; }
  std::size_t num_columns() const { return header_.size(); }
  std::string_view header(std::size_t i) const { return header_[i]; }
  std::size_t header_line() const { return header_line_; }

  /// Resolves every header name against `specs` (one result per spec, same
  /// order). Throws InputError at the header cell for a known quantity with a
  /// missing or unknown unit suffix, for the same quantity given twice (e.g.
  /// ex_m and ex_mm), and for a column no spec knows. Unknown columns are an
  /// error on purpose: a typo (`ex_n`, `ticks_lef`) must not silently drop data.
  std::vector<ResolvedColumn> Resolve(std::span<const ColumnSpec> specs) const;

  /// Advances to the next data row; false at the end of the input. The
  /// cells stay valid until the next call. Throws InputError at the row when
  /// its cell count differs from the header's or it is too long.
  inline bool Next();
  /// True when no data row follows (call before Next(); skips the blank and
  /// comment lines in between).
  bool HasNoDataRows();

  std::size_t line() const { return line_; }
  /// Byte offset in the input of the next unread byte, and the line number there.
  std::uint64_t offset() const { return in_.bytes_read() - (len_ - pos_); }
  std::size_t next_line() const { return next_line_; }
  std::string_view cell(std::size_t i) const { return cells_[i]; }

  /// 1-based column (UTF-8 characters) of cell i of the current row.
  std::size_t Column(std::size_t i) const;
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
  /// A non-empty text cell (unquoted).
  inline std::string_view Text(const ResolvedColumn& c) const;

 private:
  /// Bytes of padding after the buffer, so the delimiter scan may load a
  /// whole vector past the last byte.
  static constexpr std::size_t kPadding = 64;

  /// Makes room and reads more input, keeping the bytes from pos_ on (the
  /// line being scanned); pos_ becomes 0. False at the end of the input.
  /// Fails when the kept line has reached kMaxLineBytes.
  bool Fill();
  /// The line at pos_ is blank or a comment: skips it and returns true;
  /// false when it holds content. Reads more input as needed.
  bool SkipIfBlankOrComment();
  /// Skips blank and comment lines; false at the end of the input.
  bool SkipToContent();
  /// Next() for a row holding a '"' (the slow path): reads the whole row,
  /// line breaks inside quotes included, and unquotes its cells in place.
  bool NextQuotedRow();
  /// End of the row at pos_ (its '\n', or the end of the input), reading
  /// more as needed; counts the line breaks inside quotes into `breaks`.
  const char* QuotedRowEnd(std::size_t& breaks);
  /// Reads the next content line whole (header): sets line_, line_begin_,
  /// line_end_ (without \r) and advances pos_. False at the end.
  bool NextContentLine();
  void CheckHeader();
  [[noreturn]] void FailLongLine() const;
  std::size_t ColumnOf(const char* p) const;
  /// The general number parser (fast_float) with all the checks.
  double ParseNumberSlow(const ResolvedColumn& c, std::string_view s) const;
  std::int64_t ParseCountSlow(const ResolvedColumn& c, std::string_view s) const;
  [[noreturn]] void FailCellCount(std::size_t n) const;
  [[noreturn]] void FailEmpty(const ResolvedColumn& c) const;
  [[noreturn]] void FailHeader(std::size_t i, const std::string& message) const;
  [[noreturn]] void FailNumber(const ResolvedColumn& c, std::string_view cell, const char* what) const;
  /// A finite number beyond the column's max_abs.
  [[noreturn]] void FailMagnitude(const ResolvedColumn& c, std::string_view cell) const;

  InputStream in_;
  std::string name_;
  std::unique_ptr<char[]> buf_;
  std::size_t capacity_ = 0;  ///< usable bytes of buf_ (kPadding more are allocated)
  std::size_t len_ = 0;       ///< bytes of input in buf_
  std::size_t pos_ = 0;       ///< offset of the next unread line in buf_
  bool eof_ = false;
  bool bom_checked_ = false;
  std::size_t line_ = 0;
  std::size_t next_line_ = 1;  ///< number of the line at pos_
  const char* line_begin_ = nullptr;
  const char* line_end_ = nullptr;
  const char* extra_ = nullptr;
  std::size_t header_line_ = 0;
  std::string header_text_;  ///< the header line (header_ views into it)
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

/// First ',', '\n' or '"' in [p, end), or end. Reads up to 15 bytes past `end`
/// (the reader's buffer is padded for that); what lies there is ignored.
inline const char* FindDelimiter(const char* p, const char* end) {
#if defined(__SSE2__)
  const __m128i comma = _mm_set1_epi8(',');
  const __m128i newline = _mm_set1_epi8('\n');
  const __m128i quote = _mm_set1_epi8('"');
  for (; p < end; p += 16) {
    const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p));
    const auto mask = static_cast<unsigned>(_mm_movemask_epi8(_mm_or_si128(
        _mm_or_si128(_mm_cmpeq_epi8(v, comma), _mm_cmpeq_epi8(v, newline)), _mm_cmpeq_epi8(v, quote))));
    if (mask != 0) {
      const char* const q = p + __builtin_ctz(mask);
      return q < end ? q : end;
    }
  }
  return end;
#else
  while (p < end && *p != ',' && *p != '\n' && *p != '"') ++p;
  return p;
#endif
}

}  // namespace csv_internal

inline bool CsvReader::Next() {
  using csv_internal::IsBlank;
  for (;;) {
    if (pos_ == len_ && !Fill()) return false;
    const char c0 = buf_[pos_];
    if ((c0 == '#' || c0 == '\n' || c0 == '\r' || IsBlank(c0)) && SkipIfBlankOrComment()) continue;
    // Taken only now: SkipIfBlankOrComment may have refilled (moved or
    // grown) the buffer even when the line holds content.
    const char* const b = buf_.get() + pos_;
    // One pass: split at commas up to the line end.
    const char* const end = buf_.get() + len_;
    const std::size_t expected = cells_.size();
    std::string_view* const cells = cells_.data();
    std::size_t n = 0;
    const char* c = b;
    const char* e = b;
    for (;;) {
      e = csv_internal::FindDelimiter(c, end);
      if (e < end && *e == '"') return NextQuotedRow();
      if (e == end && !eof_) break;  // the line goes on past the buffer
      if (n < expected) {
        cells[n] = std::string_view(c, static_cast<std::size_t>(e - c));
      } else if (n == expected) {
        extra_ = c;
      }
      ++n;
      if (e == end || *e == '\n') break;
      c = e + 1;
    }
    if (e == end && !eof_) {
      Fill();  // keeps this line, then scans it again
      continue;
    }
    line_ = next_line_++;
    pos_ = static_cast<std::size_t>(e - buf_.get()) + (e < end ? 1 : 0);
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
  if (!(std::abs(v) <= c.max_abs)) FailMagnitude(c, s);
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
  return s;
}

}  // namespace umbmark::io::detail
