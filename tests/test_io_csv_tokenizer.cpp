// The shared CSV tokenizer (formats/csv_table.hpp): its fast number paths must
// agree bit for bit with the reference parsers (strtod, which glibc rounds
// correctly, and std::from_chars), and its line/cell splitting must handle
// the contract's variants (BOM, CRLF, comments, blank lines, blanks around
// cells, last line without newline).
#include <catch2/catch.hpp>

#include <charconv>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>

#include "core/errors.hpp"
#include "formats/csv_table.hpp"
#include "support/bits.hpp"

using namespace umbmark;
using namespace umbmark::io::detail;

namespace {

std::string RandomDecimal(std::mt19937_64& rng) {
  std::uniform_int_distribution<int> len(0, 17), digit(0, 9), coin(0, 3);
  std::string s;
  if (coin(rng) == 0) s += '-';
  const int int_digits = len(rng);
  for (int i = 0; i < int_digits; ++i) s += static_cast<char>('0' + digit(rng));
  if (coin(rng) != 0) {
    s += '.';
    const int frac_digits = len(rng);
    for (int i = 0; i < frac_digits; ++i) s += static_cast<char>('0' + digit(rng));
  }
  return s;
}

using test::Bits;

}  // namespace

TEST_CASE("fast decimal path equals strtod bit for bit", "[io][csv]") {
  std::mt19937_64 rng(12345);  // seed 12345; deterministic
  int fast = 0;
  for (int k = 0; k < 200000; ++k) {
    const std::string s = RandomDecimal(rng);
    double v = 0.0;
    const bool ok = csv_internal::ParseSimpleDecimal(s.data(), s.data() + s.size(), v);
    std::size_t digits = 0;
    for (char c : s) digits += (c >= '0' && c <= '9') ? 1 : 0;
    INFO(s);
    // Accepted exactly when it has 1..15 digits (the Clinger-exact range).
    REQUIRE(ok == (digits >= 1 && digits <= 15));
    if (!ok) continue;
    ++fast;
    REQUIRE(Bits(v) == Bits(std::strtod(s.c_str(), nullptr)));
  }
  CHECK(fast > 50000);
  // Typical log cells.
  for (const char* s : {"0.004058", "-0.000227", "12.350", "-3.141593", "0", "-0", "5.", ".5", "-.5", "999999999999999"}) {
    double v = 0.0;
    INFO(s);
    REQUIRE(csv_internal::ParseSimpleDecimal(s, s + std::strlen(s), v));
    CHECK(Bits(v) == Bits(std::strtod(s, nullptr)));
  }
  for (const char* s : {"", "-", ".", "-.", "1e5", "1.2.3", "+1", "0x10", "1 ", "nan", "1234567890123456"}) {
    double v = 0.0;
    INFO(s);
    CHECK_FALSE(csv_internal::ParseSimpleDecimal(s, s + std::strlen(s), v));
  }
}

TEST_CASE("fast count path equals std::from_chars", "[io][csv]") {
  std::mt19937_64 rng(777);  // seed 777
  std::uniform_int_distribution<int> len(1, 20), digit(0, 9), coin(0, 1);
  for (int k = 0; k < 100000; ++k) {
    std::string s = coin(rng) != 0 ? "-" : "";
    const int n = len(rng);
    for (int i = 0; i < n; ++i) s += static_cast<char>('0' + digit(rng));
    std::int64_t fast = 0, ref = 0;
    const bool ok = csv_internal::ParseSimpleCount(s.data(), s.data() + s.size(), fast);
    INFO(s);
    REQUIRE(ok == (n <= 18));
    if (!ok) continue;
    const auto r = std::from_chars(s.data(), s.data() + s.size(), ref);
    REQUIRE(r.ec == std::errc());
    REQUIRE(fast == ref);
  }
}

TEST_CASE("numbers outside the fast path go through fast_float with full checks", "[io][csv]") {
  const std::string text = "a_m,b_rad\n1.5e-3,-2E2\n0.12345678901234567,1e-320\n";
  CsvReader csv(text, "n.csv");
  const ColumnSpec specs[] = {{"a", Quantity::kLength}, {"b", Quantity::kAngle}};
  const auto cols = csv.Resolve(specs);
  REQUIRE(csv.Next());
  CHECK(Bits(csv.Number(cols[0])) == Bits(std::strtod("1.5e-3", nullptr)));
  CHECK(csv.Number(cols[1]) == -200.0);
  REQUIRE(csv.Next());
  CHECK(Bits(csv.Number(cols[0])) == Bits(std::strtod("0.12345678901234567", nullptr)));
  // A subnormal is a finite number and is accepted as such.
  CHECK(csv.Number(cols[1]) == std::strtod("1e-320", nullptr));
  CHECK_FALSE(csv.Next());
}

TEST_CASE("tokenizer line handling: BOM, CRLF, comments, blanks, no final newline", "[io][csv]") {
  const std::string text =
      "\xEF\xBB\xBF# comment\r\n\r\n  \t \r\n a_m , t \r\n  # indented comment\n\t1.25 ,x y\r\n\n2,  z\n3,w";
  CsvReader csv(text, "t.csv");
  CHECK(csv.header_line() == 4);
  REQUIRE(csv.num_columns() == 2);
  CHECK(csv.header(0) == "a_m");
  CHECK(csv.header(1) == "t");
  const ColumnSpec specs[] = {{"a", Quantity::kLength}, {"t", Quantity::kText}};
  const auto cols = csv.Resolve(specs);
  CHECK_FALSE(csv.HasNoDataRows());
  REQUIRE(csv.Next());
  CHECK(csv.line() == 6);
  CHECK(csv.Number(cols[0]) == 1.25);
  CHECK(csv.Text(cols[1]) == "x y");  // inner blank kept
  CHECK(csv.Column(1) == 8);
  REQUIRE(csv.Next());
  CHECK(csv.line() == 8);
  CHECK(csv.Text(cols[1]) == "z");
  CHECK(csv.Column(1) == 5);
  REQUIRE(csv.Next());
  CHECK(csv.line() == 9);
  CHECK(csv.Number(cols[0]) == 3.0);
  CHECK(csv.Text(cols[1]) == "w");
  CHECK_FALSE(csv.Next());
  CHECK_FALSE(csv.Next());
}

TEST_CASE("tokenizer reports the cell count fault at the row", "[io][csv]") {
  const std::string text = "a_m,b_m,c_m\n1,2,3\r\n4,5\r\n";
  CsvReader csv(text, "c.csv");
  REQUIRE(csv.Next());
  try {
    (void)csv.Next();
    FAIL("no error");
  } catch (const InputError& e) {
    CHECK(e.line() == 3);
    CHECK(e.column() == 4);  // just after "4,5", not counting the \r
    CHECK(e.message() == "row has 2 cells but the header has 3 (truncated row?)");
  }
}

TEST_CASE("QuoteForMessage escapes control bytes and invalid UTF-8, keeps valid UTF-8", "[io][csv]") {
  CHECK(QuoteForMessage("ex_cm") == "'ex_cm'");
  CHECK(QuoteForMessage("a\tb") == "'a\\x09b'");
  CHECK(QuoteForMessage("Zo\xC3\xAB") == "'Zo\xC3\xAB'");
  CHECK(QuoteForMessage("\xFF\xC3") == "'\\xFF\\xC3'");
  CHECK(QuoteForMessage(std::string(100, 'a')) == "'" + std::string(48, 'a') + "...'");
}
