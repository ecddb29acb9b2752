// The bit pattern of a double, for tests that require results bit for bit
// (a written value read back, a refactoring that must not move one bit).
#pragma once

#include <cstdint>
#include <cstring>

namespace umbmark::test {

inline std::uint64_t Bits(double v) {
  std::uint64_t b = 0;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

}  // namespace umbmark::test
