// Shared CSV tokenizer and column resolver of the readers in formats/ (see
// csv_table.hpp for the format it accepts).
#include "formats/csv_table.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <system_error>
#include <unordered_map>

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

/// Length of the well-formed UTF-8 sequence at text[i] (no overlong forms,
/// surrogates or code points past U+10FFFF), 0 when it is not one.
std::size_t Utf8Length(std::string_view text, std::size_t i) {
  const auto at = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char c = at(i);
  std::size_t n = 0;
  unsigned char lo = 0x80, hi = 0xBF;
  if (c >= 0xC2 && c <= 0xDF) {
    n = 2;
  } else if (c >= 0xE0 && c <= 0xEF) {
    n = 3;
    lo = c == 0xE0 ? 0xA0 : 0x80;
    hi = c == 0xED ? 0x9F : 0xBF;
  } else if (c >= 0xF0 && c <= 0xF4) {
    n = 4;
    lo = c == 0xF0 ? 0x90 : 0x80;
    hi = c == 0xF4 ? 0x8F : 0xBF;
  } else {
    return 0;
  }
  if (i + n > text.size() || at(i + 1) < lo || at(i + 1) > hi) return 0;
  for (std::size_t k = 2; k < n; ++k) {
    if ((at(i + k) & 0xC0) != 0x80) return 0;
  }
  return n;
}

char32_t DecodeUtf8(std::string_view seq) {
  const auto b = [&](std::size_t k) { return static_cast<char32_t>(static_cast<unsigned char>(seq[k])); };
  switch (seq.size()) {
    case 2: return ((b(0) & 0x1F) << 6) | (b(1) & 0x3F);
    case 3: return ((b(0) & 0x0F) << 12) | ((b(1) & 0x3F) << 6) | (b(2) & 0x3F);
    default: return ((b(0) & 0x07) << 18) | ((b(1) & 0x3F) << 12) | ((b(2) & 0x3F) << 6) | (b(3) & 0x3F);
  }
}

/// Characters a terminal shows as nothing (or as a plain space).
bool IsInvisible(char32_t cp) {
  return (cp >= 0x80 && cp <= 0xA0) || cp == 0xAD || (cp >= 0x200B && cp <= 0x200F) ||
         (cp >= 0x2028 && cp <= 0x202E) || (cp >= 0x2060 && cp <= 0x2064) || cp == 0xFEFF;
}

/// Where a line that is really several CR-only lines has its first line
/// end: a carriage return (not of a CRLF) after text with a comma and no
/// control character, as a CSV header is. Null otherwise (binary data keeps
/// the readers' usual messages).
const char* CrOnlyLineEnd(const char* b, const char* e) {
  const auto* cr = static_cast<const char*>(std::memchr(b, '\r', static_cast<std::size_t>(e - b)));
  if (cr == nullptr || cr + 1 == e || cr[1] == '\n') return nullptr;
  bool comma = false;
  for (const char* p = b; p < cr; ++p) {
    const auto c = static_cast<unsigned char>(*p);
    if ((c < 0x20 && c != '\t') || c == 0x7F) return nullptr;
    comma = comma || c == ',';
  }
  return comma ? cr : nullptr;
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
    // Pass a well-formed UTF-8 sequence through, except characters that are
    // invisible in a terminal (a stray BOM, zero-width and bidi marks,
    // no-break space): those are shown as \uXXXX. Escape anything else.
    const std::size_t len = Utf8Length(text, i);
    if (len == 0) {
      out += fmt::format("\\x{:02X}", static_cast<unsigned>(c));
      ++i;
      continue;
    }
    const char32_t cp = DecodeUtf8(text.substr(i, len));
    if (IsInvisible(cp)) {
      out += fmt::format("\\u{:04X}", static_cast<std::uint32_t>(cp));
    } else {
      out.append(text.substr(i, len));
    }
    i += len;
  }
  return out + "'";
}

CsvReader::CsvReader(std::string_view text, std::string name, std::size_t max_chunk, std::size_t buffer_bytes)
    : CsvReader(InputStream(text, max_chunk), std::move(name),
                buffer_bytes > 0 ? buffer_bytes : std::min(kDefaultBufferBytes, text.size() + 1)) {}

CsvReader::CsvReader(InputStream in, std::string name, std::size_t buffer_bytes)
    : in_(std::move(in)), name_(std::move(name)) {
  capacity_ = std::max<std::size_t>(buffer_bytes, 1);
  buf_ = std::make_unique<char[]>(capacity_ + kPadding);
  // One BOM is allowed; a second one (a file saved twice by an editor that
  // adds one) would hide inside the first column name.
  while (len_ < 2 * kBom.size() && Fill()) {
  }
  if (std::string_view(buf_.get(), len_).substr(0, kBom.size()) == kBom) pos_ = kBom.size();
  if (std::string_view(buf_.get() + pos_, len_ - pos_).substr(0, kBom.size()) == kBom) {
    throw InputError(name_, 1, 1,
                     "the file starts with two byte-order marks (\\uFEFF\\uFEFF); remove the second one");
  }
  if (!NextContentLine()) FailFile("empty file: no header row");
  header_line_ = line_;
  header_text_.assign(line_begin_, line_end_);
  CheckHeader();
  cells_.resize(header_.size());
}

CsvReader::CsvReader(InputStream in, std::string name, const CsvReader& header_from, std::size_t first_line)
    : in_(std::move(in)), name_(std::move(name)) {
  capacity_ = kDefaultBufferBytes;
  buf_ = std::make_unique<char[]>(capacity_ + kPadding);
  bom_checked_ = true;
  header_line_ = header_from.header_line_;
  header_text_ = header_from.header_text_;
  CheckHeader();
  cells_.resize(header_.size());
  next_line_ = first_line;
}

void CsvReader::CheckHeader() {
  // Split, keeping each name's 1-based column (counted once, left to right,
  // so a long header costs linear time).
  const char* const begin = header_text_.data();
  const char* const end = begin + header_text_.size();
  const char* c = begin;
  const char* counted = begin;
  std::size_t column = 1;
  for (;;) {
    const char* e = c;
    while (e < end && *e != ',') ++e;
    const std::string_view cell = Trim(c, e);
    column += ColumnIn(counted, cell.data()) - 1;
    counted = cell.data();
    header_.push_back(cell);
    header_columns_.push_back(column);
    if (e == end) break;
    c = e + 1;
  }
  std::unordered_map<std::string_view, std::size_t> first;  // name -> index of its first column
  first.reserve(header_.size());
  for (std::size_t i = 0; i < header_.size(); ++i) {
    if (header_[i].empty()) FailHeader(i, fmt::format("empty column name in header (column {})", i + 1));
    const auto [it, inserted] = first.emplace(header_[i], i);
    if (!inserted) {
      FailHeader(i, fmt::format("duplicated column {} (also at column {})", QuoteForMessage(header_[i]),
                                header_columns_[it->second]));
    }
  }
}

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
    r.max_abs = spec.quantity == Quantity::kLength  ? kMaxLengthM
                : spec.quantity == Quantity::kAngle ? kMaxAngleRad
                : spec.quantity == Quantity::kTime  ? kMaxTimeS
                                                    : std::numeric_limits<double>::infinity();
  }
  return out;
}

bool CsvReader::Fill() {
  if (eof_) return false;
  const std::size_t keep = len_ - pos_;
  if (keep >= kMaxLineBytes) FailLongLine();
  if (keep > 0 && pos_ > 0) std::memmove(buf_.get(), buf_.get() + pos_, keep);
  len_ = keep;
  pos_ = 0;
  if (len_ == capacity_) {  // one line fills the buffer: grow it
    const std::size_t grown = std::max<std::size_t>(2 * capacity_, 64);
    auto bigger = std::make_unique<char[]>(grown + kPadding);
    std::memcpy(bigger.get(), buf_.get(), len_);
    buf_ = std::move(bigger);
    capacity_ = grown;
  }
  const std::size_t n = in_.Read(buf_.get() + len_, capacity_ - len_);
  if (n == 0) {
    eof_ = true;
    return false;
  }
  len_ += n;
  return true;
}

bool CsvReader::SkipIfBlankOrComment() {
  for (;;) {
    const char* const b = buf_.get() + pos_;
    const char* const end = buf_.get() + len_;
    const char* q = b;
    while (q < end && IsBlank(*q)) ++q;
    if ((q == end || (*q == '\r' && q + 1 == end)) && !eof_) {
      Fill();  // undecided until the rest of the line is read
      continue;
    }
    if (q < end && *q == '\r' && (q + 1 == end || q[1] == '\n')) ++q;
    if (q < end && *q != '#' && *q != '\n') return false;
    // Blank or comment: drop it up to its line end, without keeping it.
    for (;;) {
      const char* const stop = buf_.get() + len_;
      const auto* nl = static_cast<const char*>(std::memchr(q, '\n', static_cast<std::size_t>(stop - q)));
      if (nl != nullptr) {
        pos_ = static_cast<std::size_t>(nl - buf_.get()) + 1;
        break;
      }
      pos_ = len_;
      if (!Fill()) break;
      q = buf_.get();
    }
    ++next_line_;
    return true;
  }
}

bool CsvReader::SkipToContent() {
  for (;;) {
    if (pos_ == len_ && !Fill()) return false;
    if (!SkipIfBlankOrComment()) return true;
  }
}

bool CsvReader::NextContentLine() {
  if (!SkipToContent()) return false;
  for (;;) {
    const char* const b = buf_.get() + pos_;
    const auto* nl = static_cast<const char*>(std::memchr(b, '\n', len_ - pos_));
    if (nl == nullptr && !eof_) {
      Fill();
      continue;
    }
    const char* const e = nl != nullptr ? nl : buf_.get() + len_;
    line_ = next_line_++;
    line_begin_ = b;
    line_end_ = e > b && e[-1] == '\r' ? e - 1 : e;
    pos_ = static_cast<std::size_t>(e - buf_.get()) + (nl != nullptr ? 1 : 0);
    if (const char* cr = CrOnlyLineEnd(b, line_end_); cr != nullptr) {
      throw InputError(name_, line_, ColumnOf(cr),
                       "carriage return (\\r) inside the line: the file uses CR-only line ends (classic Mac OS); "
                       "convert them to \\n or \\r\\n");
    }
    return true;
  }
}

bool CsvReader::HasNoDataRows() { return !SkipToContent(); }

const char* CsvReader::QuotedRowEnd(std::size_t& breaks) {
  for (;;) {
    const char* const b = buf_.get() + pos_;
    const char* const end = buf_.get() + len_;
    bool quoted = false, cell_start = true, incomplete = false;
    breaks = 0;
    const char* open = nullptr;
    const char* p = b;
    for (; p < end; ++p) {
      const char ch = *p;
      if (quoted) {
        if (ch == '\n') ++breaks;
        if (ch != '"') continue;
        if (p + 1 == end && !eof_) {  // "" or the closing quote: undecided
          incomplete = true;
          break;
        }
        if (p + 1 < end && p[1] == '"') ++p;
        else quoted = false;
      } else if (ch == '\n') {
        return p;
      } else if (ch == ',') {
        cell_start = true;
      } else if (ch == '"' && cell_start) {
        quoted = true;
        open = p;
      } else if (!IsBlank(ch)) {
        cell_start = false;  // a quote later in this cell is the tokenizer's error
      }
    }
    if (!eof_ || incomplete) {
      Fill();  // keeps the row from pos_ on, then scans it again
      continue;
    }
    if (quoted) {
      // Line and column of the opening quote.
      std::size_t line = next_line_;
      const char* row = b;
      for (const char* q = b; q < open; ++q)
        if (*q == '\n') ++line, row = q + 1;
      throw InputError(name_, line, ColumnIn(row, open), "quoted cell has no closing quote");
    }
    return p;
  }
}

bool CsvReader::NextQuotedRow() {
  std::size_t breaks = 0;
  const char* const row_end = QuotedRowEnd(breaks);
  char* const b = buf_.get() + pos_;
  char* const end = buf_.get() + (row_end - buf_.get());
  line_ = next_line_;
  next_line_ += 1 + breaks;
  pos_ = static_cast<std::size_t>(end - buf_.get()) + (end < buf_.get() + len_ ? 1 : 0);
  line_begin_ = b;
  line_end_ = end > b && end[-1] == '\r' ? end - 1 : end;
  const std::size_t expected = cells_.size();
  std::size_t n = 0;
  char* r = b;  // read position
  char* w = b;  // write position (unquoted cells are copied down in place)
  for (;;) {
    while (r < line_end_ && IsBlank(*r)) ++r;
    char* const cell_begin = w;
    const char* const source = r;
    if (r < line_end_ && *r == '"') {
      for (++r;; ++r) {
        if (r >= end) throw InputError(name_, line_, ColumnOf(source), "quoted cell has no closing quote");
        if (*r == '"') {
          if (r + 1 < end && r[1] == '"') {
            *w++ = '"';
            ++r;
            continue;
          }
          ++r;
          break;
        }
        *w++ = *r;
      }
      while (r < line_end_ && IsBlank(*r)) ++r;
      if (r < line_end_ && *r != ',')
        throw InputError(name_, line_, ColumnOf(r),
                         "text after the closing quote of a quoted cell (a quote inside a cell is written \"\")");
    } else {
      while (r < line_end_ && *r != ',') {
        if (*r == '"')
          throw InputError(name_, line_, ColumnOf(r),
                           "double quote inside an unquoted cell: quote the whole cell and double the quote "
                           "(\"a\"\"b\")");
        *w++ = *r++;
      }
      while (w > cell_begin && IsBlank(w[-1])) --w;
    }
    if (n < expected) {
      cells_[n] = std::string_view(cell_begin, static_cast<std::size_t>(w - cell_begin));
    } else if (n == expected) {
      extra_ = source;
    }
    ++n;
    if (r >= line_end_) break;
    ++r;  // the comma
  }
  if (n != expected) FailCellCount(n);
  return true;
}

void CsvReader::FailLongLine() const {
  const std::string_view rest(buf_.get() + pos_, len_ - pos_);
  const char* what = "not a CSV file of this format?";
  if (CrOnlyLineEnd(rest.data(), rest.data() + rest.size()) != nullptr) {
    what = "the file uses CR-only line ends (classic Mac OS)? convert them to \\n or \\r\\n";
  } else if (rest.find('\0') != std::string_view::npos) {
    what = "binary data (NUL bytes)?";
  }
  throw InputError(name_, next_line_, 0,
                   fmt::format("line is longer than the {} limit ({})", FormatBytes(kMaxLineBytes), what));
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

void CsvReader::FailMagnitude(const ResolvedColumn& c, std::string_view cell) const {
  const char* unit = c.max_abs == kMaxLengthM ? "m" : c.max_abs == kMaxAngleRad ? "rad" : "s";
  FailCell(c.index, fmt::format("{}: {} is beyond any measured value (|value| > {:g} {}): an export or unit error?",
                                c.header, QuoteForMessage(cell), c.max_abs, unit));
}

void CsvReader::FailEmpty(const ResolvedColumn& c) const {
  FailCell(c.index, fmt::format("{}: empty cell", c.header));
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
