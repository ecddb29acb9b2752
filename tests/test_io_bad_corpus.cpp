// The bad-input corpus: every file in tests/data/bad/ is listed in
// EXPECTED.tsv (file, kind, line, column, message substring) and the matching
// reader must throw InputError naming exactly that file, line and column with
// that message (column 0 = no column; line 0 = whole-file fault). Endpoint and
// trajectory files must also fail identically through ReadRunFile, which is
// what the commands use. Run under ASan/UBSan this also shows no reader
// crashes or reads out of bounds on malformed input.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "formats/data_file.hpp"
#include "formats/endpoint_csv.hpp"
#include "formats/manifest.hpp"
#include "formats/robot_toml.hpp"
#include "formats/trajectory_csv.hpp"

using namespace umbmark;

namespace {

const std::string kBadDir = std::string(UMBMARK_SOURCE_DIR) + "/tests/data/bad/";

struct Expected {
  std::string file, kind, message;
  std::size_t line = 0, column = 0;
};

std::vector<Expected> LoadExpected() {
  std::ifstream in(kBadDir + "EXPECTED.tsv");
  REQUIRE(in.good());
  std::string line;
  std::getline(in, line);
  REQUIRE(line == "file\tkind\tline\tcolumn\tmessage");
  std::vector<Expected> out;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, '\t');) f.push_back(cell);
    INFO(line);
    REQUIRE(f.size() == 5);
    out.push_back({f[0], f[1], f[4], std::stoul(f[2]), std::stoul(f[3])});
  }
  return out;
}

/// Runs `read` and checks it throws the expected InputError.
void ExpectFault(const Expected& x, const std::string& via, const std::function<void(const std::string&)>& read) {
  const std::string path = kBadDir + x.file;
  INFO(x.file << " via " << via);
  try {
    read(path);
    FAIL_CHECK("no InputError thrown");
  } catch (const InputError& e) {
    INFO("got: " << e.what());
    CHECK(e.file() == path);
    CHECK(e.line() == x.line);
    CHECK(e.column() == x.column);
    CHECK_THAT(e.message(), Catch::Contains(x.message));
  }
}

}  // namespace

TEST_CASE("every bad file is rejected with the expected file, line, column and message", "[io][bad]") {
  const std::vector<Expected> expected = LoadExpected();
  CHECK(expected.size() >= 25);
  for (const Expected& x : expected) {
    if (x.kind == "endpoint") {
      ExpectFault(x, "ReadEndpointCsv", [](const std::string& p) { (void)io::ReadEndpointCsv(p); });
      ExpectFault(x, "ReadRunFile", [](const std::string& p) { (void)io::ReadRunFile(p); });
    } else if (x.kind == "trajectory") {
      ExpectFault(x, "ReadTrajectoryCsv", [](const std::string& p) { (void)io::ReadTrajectoryCsv(p); });
      ExpectFault(x, "ReadRunFile", [](const std::string& p) { (void)io::ReadRunFile(p); });
    } else if (x.kind == "any") {
      ExpectFault(x, "ReadRunFile", [](const std::string& p) { (void)io::ReadRunFile(p); });
      // Neither CSV reader may accept it either.
      CHECK_THROWS_AS(io::ReadEndpointCsv(kBadDir + x.file), InputError);
      CHECK_THROWS_AS(io::ReadTrajectoryCsv(kBadDir + x.file), InputError);
    } else if (x.kind == "robot") {
      ExpectFault(x, "ReadRobotToml", [](const std::string& p) { (void)io::ReadRobotToml(p); });
    } else if (x.kind == "manifest") {
      ExpectFault(x, "ReadManifest", [](const std::string& p) { (void)io::ReadManifest(p); });
    } else {
      FAIL_CHECK("unknown kind '" << x.kind << "' for " << x.file);
    }
  }
}

TEST_CASE("EXPECTED.tsv lists exactly the files of the corpus", "[io][bad]") {
  std::set<std::string> listed;
  for (const Expected& x : LoadExpected()) {
    INFO(x.file);
    CHECK(listed.insert(x.file).second);  // no file listed twice
  }
  std::set<std::string> present;
  for (const auto& entry : std::filesystem::directory_iterator(kBadDir)) {
    const std::string name = entry.path().filename().string();
    if (name != "EXPECTED.tsv" && name != "README.md") present.insert(name);
  }
  CHECK(listed == present);
}

TEST_CASE("every CSV reader rejects every bad CSV file without crashing", "[io][bad]") {
  // Cross-feeding: a bad file for one reader must also be rejected (cleanly,
  // as InputError) by the other one.
  for (const Expected& x : LoadExpected()) {
    if (x.kind != "endpoint" && x.kind != "trajectory") continue;
    INFO(x.file);
    CHECK_THROWS_AS(io::ReadEndpointCsv(kBadDir + x.file), InputError);
    CHECK_THROWS_AS(io::ReadTrajectoryCsv(kBadDir + x.file), InputError);
  }
}
