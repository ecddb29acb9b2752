// libFuzzer target for the CDR decoder and the ROS 2 message decoders: the
// input is decoded as every supported type. Only CdrError may escape; a
// decoded message never reads past the input (ASan) and never allocates
// more elements than the input could hold.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "ros2/cdr.hpp"
#include "ros2/messages.hpp"

using namespace umbmark::io::rosbag2;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  JointStateMsg js;
  std::vector<PoseMsg> tf;
  auto run = [&](auto&& decode) {
    try {
      CdrReader r(data, size);
      decode(r);
      if (r.offset() > size) __builtin_trap();
    } catch (const CdrError& e) {
      if (e.offset() > size) __builtin_trap();
    }
  };
  run([&](CdrReader& r) {
    DecodeJointState(r, js);
    if (js.name.size() > size || js.position.size() > size) __builtin_trap();
  });
  run([&](CdrReader& r) { DecodePoseStamped(r).Yaw(); });
  run([&](CdrReader& r) { DecodePoseWithCovarianceStamped(r); });
  run([&](CdrReader& r) { DecodeOdometry(r); });
  run([&](CdrReader& r) {
    DecodeTfMessage(r, tf);
    if (tf.size() > size) __builtin_trap();
  });
  return 0;
}
