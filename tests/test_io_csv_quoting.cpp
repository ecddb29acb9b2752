// RFC 4180 quoting: the writer (formats/csv_writer.hpp, used by the endpoint and
// trajectory writers) quotes exactly the cells that need it, and the readers
// (formats/csv_table.hpp) read every quoted cell back as written: run ids with a
// comma, a double quote, a line break, blanks at the ends or a leading `#`
// round-trip through files, at every read-chunk boundary; bad quoting is an
// error at its line and column.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "formats/campaign_writer.hpp"
#include "formats/csv_table.hpp"
#include "formats/csv_writer.hpp"
#include "formats/endpoint_csv.hpp"
#include "formats/trajectory_csv.hpp"
#include "support/bits.hpp"

using namespace umbmark;

namespace {

using test::Bits;

// Run ids a user may give (the first one is the case named in issue 11).
const std::vector<std::string> kIds = {"run 3, \"left\"", "plain", "a\nb", "c\r\nd", " padded\t", "#7", "\"\"", ",",
                                       "x\"y"};

std::string TempFile(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() / ("umbmark_quoting_" + name);
  std::ofstream(path, std::ios::binary) << text;
  return path.string();
}

}  // namespace

TEST_CASE("CsvField quotes only the cells that need it", "[io][csv][quoting]") {
  CHECK(io::CsvField("cw") == "cw");
  CHECK(io::CsvField("run 3") == "run 3");
  CHECK(io::CsvField("") == "");
  CHECK(io::CsvField("a,b") == "\"a,b\"");
  CHECK(io::CsvField("say \"hi\"") == "\"say \"\"hi\"\"\"");
  CHECK(io::CsvField("a\nb") == "\"a\nb\"");
  CHECK(io::CsvField("a\rb") == "\"a\rb\"");
  CHECK(io::CsvField(" a") == "\" a\"");
  CHECK(io::CsvField("a\t") == "\"a\t\"");
  CHECK(io::CsvField("#1") == "\"#1\"");
  CHECK(io::CsvField("1#") == "1#");
}

TEST_CASE("endpoint CSV: run ids with commas and quotes round-trip through a file", "[io][csv][quoting]") {
  EndpointData data;
  for (std::size_t i = 0; i < kIds.size(); ++i) {
    ReturnError r;
    r.run = kIds[i];
    r.direction = i % 2 ? "cw" : "ccw";
    r.ex_m = 0.1 / static_cast<double>(i + 3);
    r.ey_m = -1e-7 * static_cast<double>(i);
    if (i != 2) r.etheta_rad = 0.001 * static_cast<double>(i);
    data.runs.push_back(r);
  }
  const std::string text = io::FormatEndpointCsv(data, {"written by test_io_csv_quoting"});
  const EndpointData back = io::ReadEndpointCsv(TempFile("endpoint.csv", text));
  REQUIRE(back.runs.size() == data.runs.size());
  for (std::size_t i = 0; i < data.runs.size(); ++i) {
    INFO(i);
    CHECK(back.runs[i].run == data.runs[i].run);
    CHECK(back.runs[i].direction == data.runs[i].direction);
    CHECK(Bits(back.runs[i].ex_m) == Bits(data.runs[i].ex_m));
    CHECK(Bits(back.runs[i].ey_m) == Bits(data.runs[i].ey_m));
    REQUIRE(back.runs[i].etheta_rad.has_value() == data.runs[i].etheta_rad.has_value());
    if (data.runs[i].etheta_rad) CHECK(Bits(*back.runs[i].etheta_rad) == Bits(*data.runs[i].etheta_rad));
  }
  // Line numbers count the line breaks inside quotes: "a\nb" is run 3 on
  // lines 5-6 (comment, header, two one-line rows before it).
  CHECK(back.runs[2].line == 5);
  CHECK(back.runs[3].line == 7);
}

TEST_CASE("trajectory CSV: quoted run ids round-trip at every read-chunk boundary", "[io][csv][quoting]") {
  TrajectoryData data;
  for (std::size_t k = 0; k < 3; ++k) {
    TrajectoryRun r;
    r.run = kIds[k];
    r.direction = "free, \"drawn\"";
    for (int i = 0; i < 4; ++i) {
      r.t_s.push_back(0.1 * i);
      r.ticks_left.push_back(10 * i + static_cast<int>(k));
      r.ticks_right.push_back(-7 * i);
      r.gt_x_m.push_back(i == 2 ? std::nan("") : 0.01 * i);
      r.gt_y_m.push_back(i == 2 ? std::nan("") : -0.002 * i);
      r.gt_theta_rad.push_back(i == 2 ? std::nan("") : 0.3 * i);
    }
    data.runs.push_back(r);
  }
  const std::string text = io::FormatTrajectoryCsv(data);
  for (std::size_t chunk : {std::size_t{0}, std::size_t{1}, std::size_t{2}, std::size_t{3}, std::size_t{5},
                            std::size_t{7}, std::size_t{16}, std::size_t{17}}) {
    INFO("chunk " << chunk);
    const TrajectoryData back = io::TrajectoryReader(text, "t.csv", chunk, chunk ? 8 : 0).ReadAll();
    REQUIRE(back.runs.size() == 3);
    for (std::size_t k = 0; k < 3; ++k) {
      CHECK(back.runs[k].run == data.runs[k].run);
      CHECK(back.runs[k].direction == data.runs[k].direction);
      CHECK(back.runs[k].ticks_left == data.runs[k].ticks_left);
      REQUIRE(back.runs[k].size() == 4);
      for (int i = 0; i < 4; ++i) {
        CHECK(Bits(back.runs[k].t_s[i]) == Bits(data.runs[k].t_s[i]));
        CHECK(back.runs[k].HasGroundTruth(i) == data.runs[k].HasGroundTruth(i));
      }
    }
  }
}

TEST_CASE("quoted cells: blanks outside the quotes are trimmed, numbers may be quoted", "[io][csv][quoting]") {
  const std::string text = "a_m,t\n \"1.5\" ,  \"  x, y  \"\t\n2,\"\"\"\"\n";
  io::detail::CsvReader csv(text, "q.csv");
  const io::detail::ColumnSpec specs[] = {{"a", io::detail::Quantity::kLength}, {"t", io::detail::Quantity::kText}};
  const auto cols = csv.Resolve(specs);
  REQUIRE(csv.Next());
  CHECK(csv.Number(cols[0]) == 1.5);
  CHECK(csv.Text(cols[1]) == "  x, y  ");
  REQUIRE(csv.Next());
  CHECK(csv.line() == 3);
  CHECK(csv.Text(cols[1]) == "\"");
  CHECK_FALSE(csv.Next());
}

TEST_CASE("bad quoting is an error at its line and column", "[io][csv][quoting]") {
  struct Case {
    std::string text;
    std::size_t line, column;
    std::string message;
  };
  const std::vector<Case> cases = {
      {"run,direction,ex_m,ey_m\n1,cw,0,0\n2,\"ccw,0,0\n3,cw,0,0\n", 3, 3, "quoted cell has no closing quote"},
      {"run,direction,ex_m,ey_m\n\"1\"x,cw,0,0\n", 2, 4, "text after the closing quote"},
      {"run,direction,ex_m,ey_m\n1,c\"w,0,0\n", 2, 4, "double quote inside an unquoted cell"},
      {"run,direction,ex_m,ey_m\n\"a,b\",cw,0\n", 2, 11, "row has 3 cells but the header has 4"},
  };
  for (const Case& c : cases) {
    INFO(c.text);
    try {
      (void)io::ParseEndpointCsv(c.text, "bad.csv");
      FAIL("no error");
    } catch (const InputError& e) {
      CHECK(e.line() == c.line);
      CHECK(e.column() == c.column);
      CHECK(e.message().find(c.message) != std::string::npos);
    }
  }
}
