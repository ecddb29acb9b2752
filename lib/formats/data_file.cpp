// ReadRunFile / OpenRunFile: one entry point for both data formats, choosing
// the reader by the header row (ticks_* / dist_* / t_* columns -> trajectory
// CSV). The file is read once: the header decides, the chosen reader goes on.
#include "formats/data_file.hpp"

#include <memory>

#include "formats/csv_table.hpp"
#include "formats/endpoint_csv.hpp"
#include "formats/file_text.hpp"
#include "formats/trajectory_csv.hpp"

namespace umbmark::io {
namespace {

bool StartsWith(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

bool IsTrajectoryHeader(const detail::CsvReader& csv) {
  for (std::size_t i = 0; i < csv.num_columns(); ++i) {
    const std::string_view h = csv.header(i);
    // t_s (any t_* spelling, so a wrong time unit is reported by the
    // trajectory reader) or wheel columns mark a trajectory file.
    if (StartsWith(h, "ticks_") || StartsWith(h, "dist_") || StartsWith(h, "t_") || h == "t") return true;
  }
  return false;
}

}  // namespace

OpenedRunFile OpenRunFile(const std::string& path) {
  // Throws for an empty file or a bad header line.
  auto csv = std::make_unique<detail::CsvReader>(detail::InputStream(path), path);
  if (IsTrajectoryHeader(*csv)) return TrajectoryReader(std::move(csv));
  return detail::ReadEndpointRows(*csv);
}

RunFile ReadRunFile(const std::string& path) {
  OpenedRunFile file = OpenRunFile(path);
  if (auto* reader = std::get_if<TrajectoryReader>(&file)) return reader->ReadAll();
  return std::move(std::get<EndpointData>(file));
}

}  // namespace umbmark::io
