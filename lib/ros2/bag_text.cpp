// Text about a recording for messages (see bag_text.hpp).
#include "ros2/bag_text.hpp"

#include <fmt/format.h>

#include "core/errors.hpp"
#include "ros2/messages.hpp"

namespace umbmark::io::rosbag2 {

std::string WhereInBag(const BagMessage& m, const TopicInfo& t, std::size_t index) {
  if (m.compressed_chunk)
    return fmt::format("topic {} ({}), message {} (record at byte {} of the decompressed chunk at byte {})", t.name, t.type,
                       index, m.chunk_byte, m.offset);
  return m.offset > 0 ? fmt::format("topic {} ({}), message {} (record at byte {})", t.name, t.type, index, m.offset)
                      : fmt::format("topic {} ({}), message {}", t.name, t.type, index);
}

std::string StampText(std::int64_t ns) {
  const std::int64_t sec = ns / 1000000000, rem = ns % 1000000000;
  return fmt::format("{}{}.{:09d}", ns < 0 && sec == 0 ? "-" : "", sec, rem < 0 ? -rem : rem);
}

template <typename S>
static std::string Trimmed(const std::vector<S>& items, std::size_t max) {
  if (items.empty()) return "none";
  std::string out;
  for (std::size_t i = 0; i < items.size() && i < max; ++i) out += fmt::format("{}{}", i ? ", " : "", items[i]);
  if (items.size() > max) out += fmt::format(", ... and {} more", items.size() - max);
  return out;
}
std::string TrimmedList(const std::vector<std::string>& items, std::size_t max) { return Trimmed(items, max); }
std::string TrimmedList(const std::vector<std::string_view>& items, std::size_t max) { return Trimmed(items, max); }

std::string DescribeTopics(const Bag& bag) {
  // The ones that can serve as a source first; at most 40 lines whatever
  // the recording holds.
  constexpr std::size_t kMax = 40;
  std::string out;
  std::size_t shown = 0;
  for (const bool usable : {true, false})
    for (const auto& t : bag.topics()) {
      const MessageType mt = MessageTypeFromName(t.type);
      if ((mt != MessageType::kOther) != usable) continue;
      if (shown++ < kMax) out += fmt::format("  {}  {}  ({} messages)\n", t.name, t.type, t.count);
    }
  if (shown > kMax) out += fmt::format("  ... and {} more topics (umbmark import rosbag2 BAG --list)\n", shown - kMax);
  if (bag.topics().empty()) out = "  (none)\n";
  out.pop_back();
  return out;
}

std::size_t RequireTopic(const Bag& bag, const std::string& name, const char* flag) {
  const auto idx = bag.FindTopic(name);
  if (!idx)
    throw InputError(bag.path(), fmt::format("{} topic {} is not in the recording; its topics are:\n{}", flag, name,
                                             DescribeTopics(bag)));
  const TopicInfo& t = bag.topics()[*idx];
  if (t.serialization_format != "cdr")
    throw InputError(bag.path(), fmt::format("topic {} is serialized as '{}', only cdr is supported", name,
                                             t.serialization_format));
  return *idx;
}

void StampGoesBack(std::int64_t prev, std::int64_t t, const BagMessage& m, const TopicInfo& topic, std::size_t index,
                   bool log_time, bool equal_values) {
  std::string hint;
  if (!log_time)
    hint = t == prev && !equal_values
               ? "two messages with one header stamp but different values; try --time log (receive time; --time "
                 "WHEELS,GROUND_TRUTH sets each stream)"
               : "try --time log (receive time; --time WHEELS,GROUND_TRUTH sets each stream)";
  else
    hint = "receive times go back: the storage files are out of order (metadata.yaml's relative_file_paths, or the "
           "BAGs given in the wrong order) or the recording machine's clock jumped; try --time header";
  throw InputError(*m.file, fmt::format("{}: {} stamp {} s does not increase (previous {} s); {}", WhereInBag(m, topic, index),
                                        log_time ? "receive" : "header", StampText(t), StampText(prev), hint));
}

}  // namespace umbmark::io::rosbag2
