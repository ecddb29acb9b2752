// ReadRunFile: one entry point for both data formats, choosing the reader by
// the header row (ticks_* / dist_* / t_* columns -> trajectory CSV).
#include "io/data_file.hpp"

#include "io/file_text.hpp"
#include "io/csv_table.hpp"
#include "io/endpoint_csv.hpp"
#include "io/trajectory_csv.hpp"

namespace umbmark::io {
namespace {

bool StartsWith(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

}  // namespace

RunFile ReadRunFile(const std::string& path) {
  const detail::FileText file(path);
  const std::string_view text = file.view();
  bool trajectory = false;
  {
    const detail::CsvReader csv(text, path);  // throws for an empty file
    for (std::size_t i = 0; i < csv.num_columns(); ++i) {
      const std::string_view h = csv.header(i);
      // t_s (any t_* spelling, so a wrong time unit is reported by the
      // trajectory reader) or wheel columns mark a trajectory file.
      if (StartsWith(h, "ticks_") || StartsWith(h, "dist_") || StartsWith(h, "t_") || h == "t") trajectory = true;
    }
  }
  if (trajectory) return ParseTrajectoryCsv(text, path);
  return ParseEndpointCsv(text, path);
}

}  // namespace umbmark::io
