// RFC 4180 quoting of CSV cells (see csv_writer.hpp).
#include "formats/csv_writer.hpp"

namespace umbmark::io {

bool CsvNeedsQuotes(std::string_view text) {
  if (text.empty()) return false;
  auto blank = [](char c) { return c == ' ' || c == '\t'; };
  if (blank(text.front()) || blank(text.back()) || text.front() == '#') return true;
  return text.find_first_of(",\"\r\n") != std::string_view::npos;
}

std::string CsvField(std::string_view text) {
  if (!CsvNeedsQuotes(text)) return std::string(text);
  std::string out;
  out.reserve(text.size() + 2);
  out += '"';
  for (char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  out += '"';
  return out;
}

}  // namespace umbmark::io
