// The streaming CSV path (formats/csv_table.hpp, formats/trajectory_csv.hpp): every
// result and every error message must be the same whatever the read()
// chunking, including a token, a CRLF or a BOM split across chunks and a last
// line without newline; runs come one at a time with the capacity of the
// caller's vectors reused; the size limits and the reader's messages for
// CR-only line ends, a double BOM and invisible characters.
#include <catch2/catch.hpp>

#include <cstdio>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "formats/csv_table.hpp"
#include "formats/data_file.hpp"
#include "formats/endpoint_csv.hpp"
#include "formats/file_text.hpp"
#include "formats/trajectory_csv.hpp"
#include "support/run_cli.hpp"

using namespace umbmark;
using umbmark::testing::Q;
using umbmark::testing::RunCli;

namespace {

const std::string kHeader = "run,direction,t_s,ticks_left,ticks_right,x_gt_m,y_gt_m,theta_gt_rad";

/// Every field of every run, as text, to compare two readings exactly.
std::string Dump(const TrajectoryData& d) {
  std::string out;
  for (const auto& r : d.runs) {
    out += r.run + "|" + r.direction + "\n";
    for (std::size_t i = 0; i < r.size(); ++i) {
      char buf[256];
      std::snprintf(buf, sizeof buf, "%zu %.17g %lld %lld %.17g %.17g %.17g %.17g %.17g\n", r.lines[i], r.t_s[i],
                    r.has_ticks() ? static_cast<long long>(r.ticks_left[i]) : 0LL,
                    r.has_ticks() ? static_cast<long long>(r.ticks_right[i]) : 0LL,
                    r.has_ticks() ? 0.0 : r.dist_left_m[i], r.has_ticks() ? 0.0 : r.dist_right_m[i], r.gt_x_m[i],
                    r.gt_y_m[i], r.gt_theta_rad[i]);
      out += buf;
    }
  }
  return out;
}

void WriteText(const std::string& path, const std::string& text) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  REQUIRE(f != nullptr);
  std::fwrite(text.data(), 1, text.size(), f);
  std::fclose(f);
}

/// Result (or error message) of reading `text` with the given chunking.
std::string ReadWith(const std::string& text, std::size_t chunk, std::size_t buffer) {
  try {
    return Dump(io::TrajectoryReader(text, "s.csv", chunk, buffer).ReadAll());
  } catch (const InputError& e) {
    return std::string("error: ") + e.what();
  }
}

void CheckAllChunkings(const std::string& text) {
  const std::string whole = ReadWith(text, 0, 0);
  for (std::size_t chunk = 1; chunk <= 19; ++chunk) {
    for (const std::size_t buffer : {std::size_t{1}, std::size_t{2}, std::size_t{7}, std::size_t{64}}) {
      INFO("chunk " << chunk << ", buffer " << buffer);
      REQUIRE(ReadWith(text, chunk, buffer) == whole);
    }
  }
}

}  // namespace

TEST_CASE("streaming: same runs whatever the chunking (BOM, CRLF, comments, no final newline)", "[io][stream]") {
  const std::string text = "\xEF\xBB\xBF# log\r\n\r\n" + kHeader +
                           "\r\n"
                           "1,cw,0.0,0,0,0,0,0\r\n"
                           "  # comment inside\r\n"
                           "1,cw,0.01,123456789,-42,,,\r\n"
                           "\r\n"
                           "1,cw,0.02, 17 ,18,0.5,-0.25,1.5e-3\r\n"
                           "2,ccw,0,5,5,0,0,0\n"
                           "2,ccw,1.25,6,7,1.125,2.0625,-0.5";
  const std::string whole = ReadWith(text, 0, 0);
  REQUIRE(whole.rfind("error", 0) != 0);
  const TrajectoryData d = io::ParseTrajectoryCsv(text, "s.csv");
  REQUIRE(d.runs.size() == 2);
  CHECK(d.runs[0].size() == 3);
  CHECK(d.runs[0].lines == std::vector<std::size_t>{4, 6, 8});
  CHECK(d.runs[0].ticks_left[1] == 123456789);
  CHECK(d.runs[0].ticks_left[2] == 17);
  CHECK(d.runs[1].lines == std::vector<std::size_t>{9, 10});
  CHECK(d.runs[1].gt_y_m[1] == 2.0625);  // last line, no newline
  CheckAllChunkings(text);
}

TEST_CASE("streaming: the same error message whatever the chunking", "[io][stream]") {
  const std::vector<std::string> bad = {
      kHeader + "\n1,cw,0,0,0,0,0,0\n1,cw,1,1,1\n",                                   // truncated row
      kHeader + "\n1,cw,0,0,0,0,0,0\n1,cw,1,x,1,0,0,0\n",                             // text in a count
      kHeader + "\n1,cw,0,0,0,0,0,0\n1,cw,1,1,1,,,\n",                                // no gt at the end
      kHeader + "\n1,cw,0,0,0,0,0,0\n1,cw,1,1,1,0,0,0\n2,cw,0,0,0,0,0,0\n1,cw,2,1,1,0,0,0\n",  // run comes back
      kHeader + "\r\n1,cw,0,0,0,0,0,0\r\n1,ccw,1,1,1,0,0,0\r\n",                      // direction change
      kHeader + "\n1,cw,0,0,0,0,0,0\n1,cw,0,1,1,0,0,0",                               // time does not increase
      kHeader + "\n",                                                                  // no data rows
      "run,direction,t_s,t_s\n",                                                       // duplicated column
  };
  for (const auto& text : bad) {
    INFO(text);
    REQUIRE(ReadWith(text, 0, 0).rfind("error: s.csv:", 0) == 0);
    CheckAllChunkings(text);
  }
}

TEST_CASE("streaming: a run id that comes back after another run is an error naming both lines", "[io][stream]") {
  const std::string text = kHeader + "\n7,cw,0,0,0,0,0,0\n7,cw,1,1,1,0,0,0\n8,cw,0,0,0,0,0,0\n8,cw,1,1,1,0,0,0\n"
                                     "7,cw,5,1,1,0,0,0\n";
  try {
    (void)io::ParseTrajectoryCsv(text, "back.csv");
    FAIL("no error");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()) ==
          "back.csv:6:1: run '7' appears again after run '8': the rows of a run must be contiguous (its first block "
          "ended on line 3)");
  }
}

TEST_CASE("streaming: NextRun hands out one run at a time and reuses the caller's vectors", "[io][stream]") {
  std::string text = kHeader + "\n";
  for (int r = 1; r <= 3; ++r) {
    for (int i = 0; i < 100; ++i) text += std::to_string(r) + ",cw," + std::to_string(i) + ",0,0,0,0,0\n";
  }
  io::TrajectoryReader reader(text, "runs.csv", 13, 16);
  CHECK(reader.has_ticks());
  TrajectoryRun run;
  std::vector<std::string> ids;
  std::vector<const double*> storage;
  while (reader.NextRun(run)) {
    ids.push_back(run.run);
    CHECK(run.size() == 100);
    CHECK(run.t_s.back() == 99.0);
    CHECK(run.lines.front() == 2 + 100 * (ids.size() - 1));
    storage.push_back(run.t_s.data());
  }
  CHECK(ids == std::vector<std::string>{"1", "2", "3"});
  // Run 3 is read into the storage run 1 was handed out in (swapped back).
  CHECK(storage[2] == storage[0]);
  CHECK_FALSE(reader.NextRun(run));
}

TEST_CASE("ReadRunFile and OpenRunFile read a file once, by its header", "[io][stream]") {
  const auto dir = umbmark::testing::TempDir("open");
  const std::string path = (dir / "t.csv").string();
  WriteText(path, kHeader + "\n1,cw,0,0,0,0,0,0\n1,cw,1,1,1,0,0,0\n2,ccw,0,0,0,0,0,0\n2,ccw,1,1,1,0,0,0\n");
  io::OpenedRunFile opened = io::OpenRunFile(path);
  auto* reader = std::get_if<io::TrajectoryReader>(&opened);
  REQUIRE(reader != nullptr);
  CHECK(reader->path() == path);
  TrajectoryRun run;
  REQUIRE(reader->NextRun(run));
  CHECK(run.run == "1");
  REQUIRE(reader->NextRun(run));
  CHECK(run.run == "2");
  CHECK_FALSE(reader->NextRun(run));
  const io::RunFile all = io::ReadRunFile(path);
  CHECK(std::get<TrajectoryData>(all).runs.size() == 2);
}

TEST_CASE("line limit: a line over 1 MiB is rejected, blaming CR-only line ends or binary data", "[io][stream]") {
  const std::string long_header(io::detail::kMaxLineBytes + 10, 'a');
  const auto message = [](const std::string& text) {
    try {
      (void)io::ParseTrajectoryCsv(text, "big.csv");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CHECK(message(long_header) == "big.csv:1: line is longer than the 1 MiB limit (not a CSV file of this format?)");
  CHECK(message(std::string(io::detail::kMaxLineBytes + 10, '\0')) ==
        "big.csv:1: line is longer than the 1 MiB limit (binary data (NUL bytes)?)");
  // A long CR-only file is one line for the reader.
  std::string cr_only = kHeader + "\r";
  while (cr_only.size() <= io::detail::kMaxLineBytes) cr_only += "1,cw,0,0,0,0,0,0\r";
  CHECK(message(cr_only) ==
        "big.csv:1: line is longer than the 1 MiB limit (the file uses CR-only line ends (classic Mac OS)? convert "
        "them to \\n or \\r\\n)");
  // A data row over the limit, after valid rows, names its line.
  const std::string long_row = kHeader + "\n1,cw,0,0,0,0,0,0\n1,cw," + std::string(io::detail::kMaxLineBytes, '9');
  CHECK(message(long_row) == "big.csv:3: line is longer than the 1 MiB limit (not a CSV file of this format?)");
  // A comment line is skipped whatever its length (nothing of it is kept).
  const std::string long_comment = "#" + std::string(3 * io::detail::kMaxLineBytes, 'c') + "\n" + kHeader +
                                   "\n1,cw,0,0,0,0,0,0\n";
  CHECK(io::ParseTrajectoryCsv(long_comment, "c.csv").runs.at(0).lines.at(0) == 3);
}

TEST_CASE("header check is linear: many columns, a duplicate at the end", "[io][stream]") {
  std::string header;
  for (int i = 0; i < 100000; ++i) header += "c" + std::to_string(i) + ",";
  header += "c5\n";
  try {
    (void)io::ParseEndpointCsv(header, "wide.csv");
    FAIL("no error");
  } catch (const InputError& e) {
    CHECK(e.line() == 1);
    CHECK(e.column() == header.size() - 2);  // the last name, counted in characters
    CHECK(e.message() == "duplicated column 'c5' (also at column 16)");
  }
}

TEST_CASE("reader messages: CR-only line ends, a double BOM, invisible characters", "[io][stream]") {
  const auto message = [](const std::string& text) {
    try {
      (void)io::ParseEndpointCsv(text, "m.csv");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CHECK(message("run,direction,ex_m,ey_m\r1,cw,0,0\r2,cw,0,0\r") ==
        "m.csv:1:24: carriage return (\\r) inside the line: the file uses CR-only line ends (classic Mac OS); "
        "convert them to \\n or \\r\\n");
  CHECK(message("\xEF\xBB\xBF\xEF\xBB\xBFrun,direction,ex_m,ey_m\n1,cw,0,0\n") ==
        "m.csv:1:1: the file starts with two byte-order marks (\\uFEFF\\uFEFF); remove the second one");
  // A BOM elsewhere (here: after a comment line) is shown, not printed invisibly.
  CHECK(message("# x\n\xEF\xBB\xBFrun,direction,ex_m,ey_m\n1,cw,0,0\n") ==
        "m.csv:2:1: unknown column '\\uFEFFrun' (expected columns: run, direction, ex_m, ey_m, etheta_rad, x_abs_m, "
        "y_abs_m, theta_abs_rad, x_odo_m, y_odo_m, theta_odo_rad)");
  // Invalid UTF-8 and control characters are escaped.
  CHECK(message("run,direction,ex_m,e\xFFy_m\x01\n1,cw,0,0\n") ==
        "m.csv:1:20: unknown column 'e\\xFFy_m\\x01' (expected columns: run, direction, ex_m, ey_m, etheta_rad, "
        "x_abs_m, y_abs_m, theta_abs_rad, x_odo_m, y_odo_m, theta_odo_rad)");
  CHECK(io::detail::QuoteForMessage("a\xC2\xA0" "b\xE2\x80\x8B") == "'a\\u00A0b\\u200B'");
  CHECK(io::detail::QuoteForMessage("\xC0\xAF\xED\xA0\x80") == "'\\xC0\\xAF\\xED\\xA0\\x80'");  // overlong, surrogate
}

TEST_CASE("size limits: non-regular inputs stop early with a clear message", "[io][stream]") {
  // /dev/zero as a data file: one endless line of NUL bytes, rejected at 1 MiB.
  try {
    (void)io::ReadRunFile("/dev/zero");
    FAIL("no error");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()) == "/dev/zero:1: line is longer than the 1 MiB limit (binary data (NUL bytes)?)");
  }
  // /dev/zero read whole (a TOML or JSON input): stops at the 64 MiB limit.
  try {
    (void)io::detail::ReadLimitedFile("/dev/zero", 1 << 16);
    FAIL("no error");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()) ==
          "/dev/zero: input goes on past the 65536 bytes limit for this kind of input (a device or a pipe that does "
          "not end?)");
  }
  CHECK(io::detail::FormatBytes(io::detail::kMaxWholeFileBytes) == "64 MiB");
  CHECK(io::detail::FormatBytes(io::detail::kMaxStreamBytes) == "4 GiB");
  CHECK(io::detail::ReadLimitedFile("/dev/null").empty());
}

TEST_CASE("CLI: a manifest whose file is /dev/zero fails at once with exit 1", "[io][stream][cli]") {
  const auto dir = umbmark::testing::TempDir("devzero");
  WriteText((dir / "m.toml").string(),
            "[robot]\nwheelbase_m = 0.2\nwheel_diameter_left_m = 0.084\nwheel_diameter_right_m = 0.084\n"
            "ticks_per_rev = 2796.8\n\n[[experiment]]\nkind = \"free\"\nfile = \"/dev/zero\"\n");
  for (const char* command : {"evaluate", "calibrate", "fit-noise"}) {
    INFO(command);
    const auto r = RunCli(std::string(command) + " " + Q(dir / "m.toml"));
    CHECK(r.status == 1);
    if (std::string(command) != "calibrate") {  // calibrate: no square experiment in this manifest
      CHECK(r.err.find("/dev/zero:1: line is longer than the 1 MiB limit (binary data (NUL bytes)?)") !=
            std::string::npos);
    }
  }
  const auto robot = RunCli("evaluate " + Q(dir / "m.toml") + " --robot /dev/zero");
  CHECK(robot.status == 1);
  CHECK(robot.err.find("/dev/zero: input goes on past the 64 MiB limit") != std::string::npos);
}

TEST_CASE("CLI: evaluate streams a file and names it in reader messages", "[io][stream][cli]") {
  const auto dir = umbmark::testing::TempDir("evalstream");
  const std::string csv = (dir / "cr.csv").string();
  WriteText(csv, kHeader + "\r1,cw,0,0,0,0,0,0\r1,cw,1,10,10,0,0,0\r");
  const auto r = RunCli("evaluate " + Q(csv) + " --wheelbase 0.2 --diameter-left 0.084 --diameter-right 0.084");
  CHECK(r.status == 1);
  CHECK(r.err.find(csv + ":1:68: carriage return (\\r) inside the line: the file uses CR-only line ends") !=
        std::string::npos);
}

TEST_CASE("CLI: a robot fault found while reading a file names the file, not <input>", "[io][stream][cli]") {
  const auto dir = umbmark::testing::TempDir("inputname");
  const std::string csv = (dir / "ticks.csv").string();
  WriteText(csv, kHeader + "\n1,cw,0,0,0,0,0,0\n1,cw,1,10,10,0,0,0\n");
  // Ticks in the file but no ticks_per_rev given.
  const auto r = RunCli("evaluate " + Q(csv) + " --wheelbase 0.2 --diameter-left 0.084 --diameter-right 0.084");
  CHECK(r.status == 1);
  CHECK(r.err.find(csv + ":2: run 1: ticks_per_rev is required") != std::string::npos);
  CHECK(r.err.find("<input>") == std::string::npos);
}

TEST_CASE("streaming: a row starting with blanks after a buffer refill is split where it starts", "[io][stream]") {
  // fuzz_csv found it: Next() kept a pointer to the row taken before
  // SkipIfBlankOrComment() refilled (moved or grew) the buffer, so the cells
  // and the error column came from stale bytes (heap-use-after-free when
  // the buffer grew).
  const std::string header = "run,direction,t_s,ticks_left,ticks_right,x_gt_m,y_gt_m,theta_gt_rad\n";
  // The input it found (read whole: column 8 of line 9; 7-byte chunks
  // through a 1-byte buffer: column 2).
  CheckAllChunkings(std::string(
      "# trajecticks; ground truer sample ()CF\x0dLR\x0arun,direction,t_s,ticks_left,ticks_right,x_gt_m,y_g"
      "t_m,theta_gt_rad\x0d\x0a" "1,cw,0.00,1000,-5,0,0,0\x0d\x0a" "1,cw,0.05,1010,6,,,\x0d\x0a# nohing mea"
      "su\x05" "ed yet\xe9\xe9\xe9\xe9\xe9\xe9\xe9\xe9\xe9\xe9\xe9\xe9\xe9\xe9\xe9\xe9\xe9\xe9\xe9\xe9\xe9\xe9"
      "\xe9\xe9\xe9\xe9\xe9\xe9\xe9\x0a   \x0a#\xa9\xa9\xa9\xa9\xa9\xff\xa9\xa9\xa9\xa9\xa9\xb9\xa9\xa9vvvv"
      "vvvvvvvvvvvvvvvvvvvvvvvvvvvvvvvv\xa9\xa9\xa9\xa9\xa9\xa9\xa9\xa9\x0a\x0a  \xff\xff\xff\x02 \x0a\x00\x00"
      "\x0a\x00=====3========\x0d=\x0a===u\x8c\xd1",
      309));
  CheckAllChunkings(header + "1,cw,0,0,0,0,0,0\n   \t  1,cw,0.1,5,6,0.01,0,0\n");
  CheckAllChunkings(header + "\n      \"r,1\",cw,0,0,0,0,0,0\n   \"r,1\" ,cw,0.1,1,1,0,0,0\n");
}
