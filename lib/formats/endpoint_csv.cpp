// Endpoint CSV reader (contract: run,direction,ex_m,ey_m,etheta_rad, or the
// both-poses form x_abs_m,y_abs_m,theta_abs_rad,x_odo_m,y_odo_m,theta_odo_rad
// giving e = absolute - odometry, Borenstein & Feng eq. 3.1).
#include "formats/endpoint_csv.hpp"

#include <unordered_map>

#include <fmt/format.h>

#include "core/angles.hpp"
#include "core/errors.hpp"
#include "formats/file_text.hpp"
#include "formats/csv_table.hpp"

namespace umbmark::io {
namespace {

using detail::ColumnSpec;
using detail::CsvReader;
using detail::Quantity;
using detail::ResolvedColumn;

enum Col : std::size_t { kRun, kDirection, kEx, kEy, kEtheta, kXAbs, kYAbs, kThetaAbs, kXOdo, kYOdo, kThetaOdo };

constexpr ColumnSpec kSpecs[] = {
    {"run", Quantity::kText},         {"direction", Quantity::kText}, {"ex", Quantity::kLength},
    {"ey", Quantity::kLength},        {"etheta", Quantity::kAngle},   {"x_abs", Quantity::kLength},
    {"y_abs", Quantity::kLength},     {"theta_abs", Quantity::kAngle}, {"x_odo", Quantity::kLength},
    {"y_odo", Quantity::kLength},     {"theta_odo", Quantity::kAngle},
};

void RequireColumns(const CsvReader& csv, const std::vector<ResolvedColumn>& cols,
                    std::initializer_list<Col> required, const char* hint) {
  for (const Col c : required) {
    if (!cols[c].present()) {
      const auto& spec = kSpecs[c];
      const char* unit = spec.quantity == Quantity::kLength  ? "_m"
                         : spec.quantity == Quantity::kAngle ? "_rad"
                                                             : "";
      csv.FailLine(csv.header_line(), fmt::format("missing column '{}{}'{}", spec.base, unit, hint));
    }
  }
}

}  // namespace

namespace detail {

EndpointData ReadEndpointRows(CsvReader& csv) {
  const std::vector<ResolvedColumn> cols = csv.Resolve(kSpecs);

  const bool error_form = cols[kEx].present() || cols[kEy].present() || cols[kEtheta].present();
  const bool pose_form = cols[kXAbs].present() || cols[kYAbs].present() || cols[kThetaAbs].present() ||
                         cols[kXOdo].present() || cols[kYOdo].present() || cols[kThetaOdo].present();
  if (error_form && pose_form) {
    csv.FailLine(csv.header_line(),
                 "header mixes the return-error columns (ex_m, ey_m, etheta_rad) with the both-poses columns "
                 "(x_abs_m, ..., theta_odo_rad); give one form");
  }
  RequireColumns(csv, cols, {kRun, kDirection}, "");
  if (pose_form) {
    RequireColumns(csv, cols, {kXAbs, kYAbs, kThetaAbs, kXOdo, kYOdo, kThetaOdo}, " (both-poses form)");
  } else {
    // etheta_rad is optional as a column too: a tape measure gives only x, y.
    RequireColumns(csv, cols, {kEx, kEy},
                   " (or give both poses: x_abs_m,y_abs_m,theta_abs_rad,x_odo_m,y_odo_m,theta_odo_rad)");
  }
  if (csv.HasNoDataRows()) csv.FailFile("no data rows after the header");

  EndpointData data;
  data.path = csv.name();
  // (run, direction) -> line, to reject a run given twice.
  std::unordered_map<std::string, std::size_t> seen;
  while (csv.Next()) {
    ReturnError r;
    r.line = csv.line();
    r.run = std::string(csv.Text(cols[kRun]));
    r.direction = CanonicalDirection(csv.Text(cols[kDirection]));
    if (pose_form) {
      r.ex_m = csv.Number(cols[kXAbs]) - csv.Number(cols[kXOdo]);  // eq. 3.1: e = absolute - odometry
      r.ey_m = csv.Number(cols[kYAbs]) - csv.Number(cols[kYOdo]);
      double theta_abs = 0.0, theta_odo = 0.0;
      const bool has_abs = csv.OptionalNumber(cols[kThetaAbs], theta_abs);
      const bool has_odo = csv.OptionalNumber(cols[kThetaOdo], theta_odo);
      if (has_abs != has_odo) {
        const Col empty = has_abs ? kThetaOdo : kThetaAbs;
        csv.FailCell(cols[empty].index, fmt::format("{}: empty cell while {} is given (give both headings or none)",
                                                    cols[empty].header, cols[has_abs ? kThetaAbs : kThetaOdo].header));
      }
      if (has_abs) r.etheta_rad = WrapAngle(theta_abs - theta_odo);
    } else {
      r.ex_m = csv.Number(cols[kEx]);
      r.ey_m = csv.Number(cols[kEy]);
      double etheta = 0.0;
      if (cols[kEtheta].present() && csv.OptionalNumber(cols[kEtheta], etheta)) r.etheta_rad = WrapAngle(etheta);
    }
    std::string key = r.run;
    key += '\0';
    key += r.direction;
    const auto [it, inserted] = seen.emplace(std::move(key), r.line);
    if (!inserted) {
      csv.FailCell(cols[kRun].index, fmt::format("run {} ({}) appears twice (first on line {})",
                                                 detail::QuoteForMessage(r.run), detail::QuoteForMessage(r.direction), it->second));
    }
    data.runs.push_back(std::move(r));
  }
  return data;
}

}  // namespace detail

EndpointData ParseEndpointCsv(std::string_view text, const std::string& name) {
  CsvReader csv(text, name);
  return detail::ReadEndpointRows(csv);
}

EndpointData ReadEndpointCsv(const std::string& path) {
  CsvReader csv(detail::InputStream(path), path);
  return detail::ReadEndpointRows(csv);
}

}  // namespace umbmark::io
