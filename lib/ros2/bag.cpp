// rosbag2 recording: file discovery, topic merging, message streaming (see bag.hpp).
#include "ros2/bag.hpp"

#include <algorithm>
#include <filesystem>
#include <limits>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "formats/file_text.hpp"
#include "ros2/mcap_reader.hpp"
#include "ros2/sqlite_reader.hpp"

namespace umbmark::io::rosbag2 {

namespace fs = std::filesystem;

namespace {

bool IsMcap(const std::string& f) { return fs::path(f).extension() == ".mcap"; }
bool IsDb3(const std::string& f) { return fs::path(f).extension() == ".db3"; }

std::string Trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(" \t\r");
  std::string t(s.substr(b, e - b + 1));
  if (t.size() >= 2 && (t.front() == '\'' || t.front() == '"') && t.back() == t.front()) t = t.substr(1, t.size() - 2);
  return t;
}

}  // namespace

double TopicInfo::RateHz() const {
  if (count < 2 || last_ns <= first_ns) return 0.0;
  return static_cast<double>(count - 1) / (static_cast<double>(last_ns - first_ns) * 1e-9);
}

// The list under `relative_file_paths:`; entries are "- name" lines
// indented at least as deep as the key (YAML block sequence).
std::vector<std::string> ReadMetadataFileList(const std::string& metadata_path) {
  const std::string text = ReadWholeFile(metadata_path);
  std::vector<std::string> files;
  std::size_t pos = 0, line = 0, key_line = 0, key_indent = 0;
  bool in_list = false;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    const std::string_view l(text.data() + pos, end - pos);
    ++line;
    pos = end + 1;
    const std::size_t indent = l.find_first_not_of(' ');
    if (indent == std::string_view::npos) continue;
    const std::string_view body = l.substr(indent);
    if (in_list) {
      if (body.starts_with("- ") && indent >= key_indent) {
        files.push_back(Trim(body.substr(2)));
        continue;
      }
      break;
    }
    if (body.starts_with("relative_file_paths:")) {
      in_list = true;
      key_line = line;
      key_indent = indent;
      const std::string rest = Trim(body.substr(20));
      if (rest == "[]") break;
      if (!rest.empty()) {
        // Flow style: [a.mcap, b.mcap]
        std::string inner = rest;
        if (inner.front() == '[' && inner.back() == ']') inner = inner.substr(1, inner.size() - 2);
        std::size_t s = 0;
        while (s <= inner.size()) {
          std::size_t c = inner.find(',', s);
          if (c == std::string::npos) c = inner.size();
          const std::string f = Trim(std::string_view(inner).substr(s, c - s));
          if (!f.empty()) files.push_back(f);
          s = c + 1;
        }
        break;
      }
    }
  }
  if (!in_list) throw InputError(metadata_path, "no relative_file_paths list (is this a rosbag2 metadata.yaml?)");
  // A bag recorded with --compression-mode file|message holds compressed
  // files or messages: refuse it by name rather than misread it.
  if (const auto at = text.find("compression_format:"); at != std::string::npos) {
    const std::size_t eol = text.find('\n', at);
    const std::string format = Trim(std::string_view(text).substr(at + 19, eol == std::string::npos ? std::string::npos : eol - at - 19));
    if (!format.empty()) {
      throw InputError(metadata_path, fmt::format("the bag is compressed by rosbag2 (compression_format: {}); run "
                                                  "`ros2 bag decompress` (or `ros2 bag convert`) first", format));
    }
  }
  if (files.empty()) throw InputError(metadata_path, key_line, 0, "relative_file_paths lists no storage files");
  return files;
}

std::optional<std::size_t> Bag::FindTopic(std::string_view name) const {
  const auto it = index_.find(std::string(name));
  if (it == index_.end()) return std::nullopt;
  return it->second;
}

// Long because it is the one place that knows the three bag layouts (folder
// with metadata.yaml, bare folder, single file) and both storages' topic
// sources (SQLite counts, MCAP summary or one counting pass).
Bag Bag::Open(const std::string& path, std::vector<std::string>& warnings) {
  Bag bag;
  bag.path_ = path;
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    const fs::path meta = fs::path(path) / "metadata.yaml";
    if (fs::exists(meta, ec)) {
      for (const auto& f : ReadMetadataFileList(meta.string())) {
        const fs::path p = fs::path(path) / f;
        if (!fs::exists(p, ec))
          throw InputError(meta.string(), fmt::format("lists '{}', which is not in the folder", f));
        if (!IsMcap(p.string()) && !IsDb3(p.string()))
          throw InputError(meta.string(), fmt::format("lists '{}', which is neither .mcap nor .db3 (compressed bags: "
                                                      "decompress with `ros2 bag decompress` first)", f));
        bag.files_.push_back(p.string());
      }
    } else {
      for (const auto& e : fs::directory_iterator(path, ec)) {
        const std::string f = e.path().string();
        if (e.is_regular_file() && (IsMcap(f) || IsDb3(f))) bag.files_.push_back(f);
      }
      std::sort(bag.files_.begin(), bag.files_.end());
      if (bag.files_.empty()) throw InputError(path, "folder holds no metadata.yaml and no .mcap or .db3 files");
      warnings.push_back(fmt::format("{}: no metadata.yaml (recorder killed?); read its {} storage file(s) in name order",
                                     path, bag.files_.size()));
    }
  } else if (fs::exists(path, ec)) {
    if (!IsMcap(path) && !IsDb3(path))
      throw InputError(path, "not a rosbag2 recording: expected a bag folder, a .mcap or a .db3 file");
    bag.files_.push_back(path);
  } else {
    throw InputError(path, "no such file or folder");
  }

  // Topics merged by name over the files; a type change between files is an error.
  auto add = [&](const std::string& file, const std::string& name, const std::string& type, const std::string& ser,
                 std::uint64_t count, std::int64_t first, std::int64_t last) {
    auto idx = bag.FindTopic(name);
    if (!idx) {
      bag.topics_.push_back({name, type, ser, 0, std::numeric_limits<std::int64_t>::max(),
                             std::numeric_limits<std::int64_t>::min()});
      idx = bag.topics_.size() - 1;
      bag.index_.emplace(name, *idx);
    }
    TopicInfo& t = bag.topics_[*idx];
    if (t.type != type)
      throw InputError(file, fmt::format("topic {} has type {} here but {} in an earlier file", name, type, t.type));
    t.count += count;
    if (count > 0) {
      t.first_ns = std::min(t.first_ns, first);
      t.last_ns = std::max(t.last_ns, last);
    }
  };
  for (const auto& file : bag.files_) {
    if (IsDb3(file)) {
      SqliteBagFile db(file);
      for (const auto& t : db.topics()) add(file, t.name, t.type, t.serialization_format, t.count, t.first_ns, t.last_ns);
      continue;
    }
    McapReader mcap(file);
    McapSummary summary;
    if (mcap.ReadSummary(summary)) {
      for (const auto& c : summary.channels) {
        auto it = summary.message_counts.find(c.id);
        const std::uint64_t n = it == summary.message_counts.end() ? 0 : it->second;
        add(file, c.topic, c.schema_name, c.message_encoding, n, static_cast<std::int64_t>(summary.start_ns),
            static_cast<std::int64_t>(summary.end_ns));
      }
      continue;
    }
    // No summary: one pass counts the messages of every channel.
    struct Count {
      std::string topic, type, encoding;
      std::uint64_t n = 0;
      std::int64_t first = std::numeric_limits<std::int64_t>::max(), last = std::numeric_limits<std::int64_t>::min();
    };
    std::vector<Count> counts(65536);
    std::vector<std::uint16_t> order;
    mcap.Stream(
        [&](const McapChannel& c) {
          counts[c.id] = {c.topic, c.schema_name, c.message_encoding};
          order.push_back(c.id);
          return true;
        },
        [&](const McapMessage& m) {
          Count& c = counts[m.channel_id];
          ++c.n;
          const auto t = static_cast<std::int64_t>(m.log_time_ns);
          c.first = std::min(c.first, t);
          c.last = std::max(c.last, t);
        });
    for (const auto id : order) add(file, counts[id].topic, counts[id].type, counts[id].encoding, counts[id].n,
                                    counts[id].first, counts[id].last);
  }
  for (auto& t : bag.topics_) {
    if (t.count == 0) t.first_ns = t.last_ns = 0;
  }
  return bag;
}

void Bag::Read(const std::vector<bool>& wanted, const std::function<void(const BagMessage&)>& fn) const {
  for (const auto& file : files_) {
    if (IsDb3(file)) {
      SqliteBagFile db(file);
      std::vector<bool> w(db.topics().size(), false);
      std::vector<std::size_t> map(db.topics().size());
      for (std::size_t i = 0; i < db.topics().size(); ++i) {
        const auto idx = FindTopic(db.topics()[i].name);
        map[i] = idx.value_or(0);
        w[i] = idx && *idx < wanted.size() && wanted[*idx];
      }
      db.Stream(w, [&](std::size_t i, std::int64_t ts, const std::uint8_t* d, std::size_t n) {
        fn({map[i], ts, d, n, &file, 0, false, 0});
      });
      continue;
    }
    McapReader mcap(file);
    std::vector<std::size_t> map(65536, 0);
    mcap.Stream(
        [&](const McapChannel& c) {
          const auto idx = FindTopic(c.topic);
          if (!idx || *idx >= wanted.size() || !wanted[*idx]) return false;
          if (topics_[*idx].type != c.schema_name)
            throw InputError(file, fmt::format("topic {} has a second channel of type {} (expected {})", c.topic,
                                               c.schema_name, topics_[*idx].type));
          map[c.id] = *idx;
          return true;
        },
        [&](const McapMessage& m) {
          fn({map[m.channel_id], static_cast<std::int64_t>(m.log_time_ns), m.data, m.size, &file, m.offset,
              m.compressed_chunk, m.chunk_byte});
        });
  }
}

}  // namespace umbmark::io::rosbag2
