// libFuzzer target for the MCAP reader: the input is written to a temporary
// file and read both ways (summary, then a full stream delivering every
// channel). Only InputError may escape; every delivered message must lie
// inside the buffer it points into (checked by ASan when touched).
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "core/errors.hpp"
#include "ros2/mcap_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = "/tmp/umbmark-fuzz-mcap-" + std::to_string(::getpid()) + ".mcap";
  // Removed when the fuzzer exits (it ends by exit() after -max_total_time).
  static const struct Remove {
    ~Remove() { std::remove(path.c_str()); }
  } remove_at_exit;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return 0;
  std::fwrite(data, 1, size, f);
  std::fclose(f);
  try {
    umbmark::io::rosbag2::McapReader reader(path);
    umbmark::io::rosbag2::McapSummary summary;
    try {
      reader.ReadSummary(summary);
    } catch (const umbmark::InputError&) {
    }
    volatile std::uint8_t sink = 0;
    reader.Stream([](const umbmark::io::rosbag2::McapChannel&) { return true; },
                  [&](const umbmark::io::rosbag2::McapMessage& m) {
                    if (m.size > 0) sink = static_cast<std::uint8_t>(sink ^ m.data[0] ^ m.data[m.size - 1]);
                  });
  } catch (const umbmark::InputError&) {
  }
  return 0;
}
