// The documented examples run: every `umbmark ...` command in docs/formats.md
// and docs/tutorial.md that works on data/examples/ is executed (outputs into
// a temporary directory) and must succeed, and every example file the
// formats page quotes says what the file under data/examples/ says.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "support/run_cli.hpp"

using namespace umbmark::testing;
namespace fs = std::filesystem;

namespace {
const fs::path kSrc = UMBMARK_SOURCE_DIR;

struct Block {
  std::string lang, text, context;  // context: the paragraph before the fence
};

std::vector<Block> FencedBlocks(const fs::path& md) {
  std::istringstream in(Slurp(md.string()));
  std::vector<Block> blocks;
  std::string line, paragraph;
  bool inside = false, paragraph_ended = false;
  Block cur;
  while (std::getline(in, line)) {
    if (line.rfind("```", 0) == 0) {
      if (!inside) {
        cur = Block{line.substr(3), "", paragraph};
      } else {
        blocks.push_back(cur);
        paragraph.clear();
        paragraph_ended = false;
      }
      inside = !inside;
      continue;
    }
    if (inside) {
      cur.text += line + "\n";
    } else if (line.empty()) {
      paragraph_ended = true;  // the paragraph stays the context of a fence that follows
    } else {
      if (paragraph_ended) paragraph.clear();
      paragraph_ended = false;
      paragraph += line + " ";
    }
  }
  REQUIRE_FALSE(inside);
  return blocks;
}

/// Shell commands of a block with `\` continuations joined.
std::vector<std::string> Commands(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  std::string line, cur;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\\') {
      cur += line.substr(0, line.size() - 1);
      continue;
    }
    cur += line;
    if (cur.rfind("umbmark ", 0) == 0) out.push_back(cur);
    cur.clear();
  }
  return out;
}

/// Lines that carry content: comments and blank lines dropped, trailing
/// comments and spaces stripped.
std::vector<std::string> ContentLines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    while (!line.empty() && (line.back() == ' ' || line.back() == '\r')) line.pop_back();
    if (!line.empty()) out.push_back(line);
  }
  return out;
}
}  // namespace

TEST_CASE("every documented command on data/examples runs", "[examples]") {
  const fs::path work = TempDir("examples");
  int ran = 0;
  for (const char* doc : {"docs/formats.md", "docs/tutorial.md"}) {
    for (const auto& b : FencedBlocks(kSrc / doc)) {
      if (b.lang != "sh") continue;
      for (std::string cmd : Commands(b.text)) {
        // Only commands whose inputs ship with the repository.
        const bool examples = cmd.find("data/examples/") != std::string::npos;
        const bool made_here = cmd.find("/tmp/campaign") != std::string::npos;
        if (!examples && !made_here) continue;
        cmd = std::regex_replace(cmd, std::regex("data/examples/"), (kSrc / "data/examples").string() + "/");
        cmd = std::regex_replace(cmd, std::regex("/tmp/campaign"), (work / "campaign").string());
        cmd = std::regex_replace(cmd, std::regex("#.*$"), "");
        INFO(doc << ": " << cmd);
        // Relative output paths land in the temporary directory.
        const auto res = RunCliIn(work, cmd.substr(std::string("umbmark ").size()));
        INFO(res.err);
        CHECK(res.status == 0);
        ++ran;
      }
    }
  }
  CHECK(ran >= 8);
}

TEST_CASE("the example files quoted in docs/formats.md are the files in data/examples", "[examples]") {
  const std::regex file_re("`data/examples/([A-Za-z0-9_.-]+)`");
  int checked = 0;
  for (const auto& b : FencedBlocks(kSrc / "docs/formats.md")) {
    if (b.lang != "toml" && !b.lang.empty()) continue;  // manifests and CSV (no language)
    std::string quoted;
    for (auto it = std::sregex_iterator(b.context.begin(), b.context.end(), file_re); it != std::sregex_iterator(); ++it)
      quoted = (*it)[1];  // the last file named before the block
    if (quoted.empty()) continue;
    const fs::path file = kSrc / "data/examples" / quoted;
    INFO(file);
    REQUIRE(fs::exists(file));
    const auto shown = ContentLines(b.text), actual = ContentLines(Slurp(file.string()));
    if (b.lang == "toml") {
      CHECK(shown == actual);  // a manifest is quoted whole
    } else {
      // A CSV is quoted by its first lines (header included).
      REQUIRE(shown.size() <= actual.size());
      CHECK(std::equal(shown.begin(), shown.end(), actual.begin()));
    }
    ++checked;
  }
  CHECK(checked >= 7);
}

TEST_CASE("docs/diagnosis.md's option table agrees with `umbmark diagnose --help`", "[examples]") {
  // Every option of the help is in the page's table, and a numeric default
  // the help states is the default the table gives.
  const auto help = RunCli("diagnose --help");
  REQUIRE(help.status == 0);
  std::vector<std::string> table;
  {
    std::istringstream in(Slurp((kSrc / "docs/diagnosis.md").string()));
    std::string line;
    while (std::getline(in, line))
      if (line.rfind("| `--", 0) == 0) table.push_back(line);
  }
  REQUIRE(table.size() >= 15);
  // Option name -> its help text (CLI11 wraps a long name's text onto the next line).
  std::vector<std::pair<std::string, std::string>> options;
  {
    std::istringstream in(help.out);
    std::string line;
    const std::regex opt(R"(^\s+(--[a-z0-9-]+))");
    std::smatch m;
    while (std::getline(in, line)) {
      if (std::regex_search(line, m, opt)) {
        options.emplace_back(m[1].str(), line);
      } else if (!options.empty()) {
        options.back().second += " " + line;
      }
    }
  }
  REQUIRE(options.size() >= 20);
  int with_default = 0;
  for (const auto& [name, text] : options) {
    if (name == "--help") continue;
    INFO(name << ": " << text);
    const std::string cell = "`" + name;
    const std::string* row = nullptr;
    for (const auto& r : table) {
      // The name as a whole word: `--seed N` or `--seed`, in the first cell.
      const auto at = r.substr(0, r.find(" | ")).find(cell);
      if (at == std::string::npos) continue;
      const char next = r[at + cell.size()];
      if (next == ' ' || next == '`') row = &r;
    }
    REQUIRE(row != nullptr);
    std::smatch d;
    if (std::regex_search(text, d, std::regex(R"(\(default ([0-9][0-9.e+-]*)[;)])"))) {
      INFO(*row);
      CHECK(row->find("| " + d[1].str() + " |") != std::string::npos);
      ++with_default;
    }
  }
  CHECK(with_default >= 8);
}
