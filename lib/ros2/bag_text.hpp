// Text about a recording for error messages and warnings, shared by the
// importer and the ground-truth sources: where a message is (topic, number,
// byte offset), a ROS stamp, a list cut to a readable length, the topic
// list, and the topic lookup that names the topics there when one is missing.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "ros2/bag.hpp"

namespace umbmark::io::rosbag2 {

/// "topic /joint_states (sensor_msgs/msg/JointState), message 12 (record at
/// byte 4711)", or inside a compressed chunk the record's offset in the
/// decompressed chunk and the chunk's byte. `index`: the message's number.
std::string WhereInBag(const BagMessage& m, const TopicInfo& t, std::size_t index);

/// "1700000012.350000000" (seconds.nanoseconds of a ROS stamp).
std::string StampText(std::int64_t ns);

/// "a, b, c, ... and 999997 more": at most `max` items, for messages that
/// must stay one readable line whatever the recording holds.
std::string TrimmedList(const std::vector<std::string>& items, std::size_t max = 20);
std::string TrimmedList(const std::vector<std::string_view>& items, std::size_t max = 20);

/// "  /topic  type  (N messages)" lines of every topic, for error messages.
std::string DescribeTopics(const Bag& bag);

/// The index of topic `name`, which must exist and be CDR. Throws
/// InputError naming the file, `flag` ("--wheels") and the topics there.
std::size_t RequireTopic(const Bag& bag, const std::string& name, const char* flag);

/// A stamp that does not increase on a stream read with header stamps
/// (`log_time` false) or receive times: InputError naming the message and
/// what to try. (Equal stamps with equal values are dropped by the caller.)
[[noreturn]] void StampGoesBack(std::int64_t prev, std::int64_t t, const BagMessage& m, const TopicInfo& topic,
                                std::size_t index, bool log_time, bool equal_values);

}  // namespace umbmark::io::rosbag2
