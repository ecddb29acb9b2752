// Writing CSV cells (RFC 4180): a cell that the readers (csv_table.hpp)
// would not read back as written is quoted, with each `"` doubled. That is
// a cell holding a comma, a double quote, CR or LF, starting or ending with
// a space or tab (the readers trim unquoted cells), or starting with `#`
// (a row starting with it would be a comment). Numbers never need it.
#pragma once

#include <string>
#include <string_view>

namespace umbmark::io {

/// True when `text` must be quoted to read back unchanged.
bool CsvNeedsQuotes(std::string_view text);

/// `text` as one CSV cell: unchanged, or "..." with every `"` doubled.
std::string CsvField(std::string_view text);

}  // namespace umbmark::io
