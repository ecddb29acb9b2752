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
  bool Next();
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
  double Number(const ResolvedColumn& c) const;
  /// Returns false (leaving `out` untouched) when the cell is empty.
  bool OptionalNumber(const ResolvedColumn& c, double& out) const;
  std::int64_t Count(const ResolvedColumn& c) const;
  /// A non-empty text cell without a double quote.
  std::string_view Text(const ResolvedColumn& c) const;

 private:
  /// Finds the next line that is neither blank nor a comment, starting at
  /// pos_. Sets line_, line_begin_, line_end_ (without \r). False at end.
  bool NextContentLine();
  /// Splits [line_begin_, line_end_) at commas into `out`; returns the count.
  /// Only the first `max_cells` are stored; extra_ points at the first extra.
  std::size_t Split(std::vector<std::string_view>& out, std::size_t max_cells);
  std::size_t ColumnOf(const char* p) const;
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

}  // namespace umbmark::io::detail
