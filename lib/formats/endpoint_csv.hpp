// Reader for the contract's endpoint CSV:
//   run,direction,ex_m,ey_m,etheta_rad            (etheta_rad cell may be empty)
// or, instead of errors, both poses:
//   run,direction,x_abs_m,y_abs_m,theta_abs_rad,x_odo_m,y_odo_m,theta_odo_rad
// Columns are found by name (any order); unit suffixes _m/_mm, _rad/_deg are
// converted to SI. Comments (#), blank lines, BOM and CRLF are accepted.
// The etheta_rad column may be left out altogether (tape measure: x, y only);
// in the both-poses form the two heading cells may be empty together.
// etheta is wrapped to (-pi, pi]. A column no form knows is an error (a typo
// must not silently drop data), and so is a (run, direction) given twice.
#pragma once

#include <string>
#include <string_view>

#include "core/runs.hpp"

namespace umbmark::io {

/// Reads an endpoint CSV file. Throws InputError (file, line, column) on any
/// fault: unreadable file, missing/duplicated/unknown/unknown-unit column,
/// text or NaN/Inf in a number, a row with too few or too many cells, an
/// empty run or direction cell, a repeated run, an empty file or no data rows
/// (the last two are whole-file faults: line and column 0).
EndpointData ReadEndpointCsv(const std::string& path);

/// Same, from text already in memory; `name` is used in error messages.
EndpointData ParseEndpointCsv(std::string_view text, const std::string& name);

namespace detail {
class CsvReader;
/// The rows after the header, from a tokenizer whose header has been read
/// (ReadRunFile decides the format by the header, then continues here).
EndpointData ReadEndpointRows(CsvReader& csv);
}  // namespace detail

}  // namespace umbmark::io
