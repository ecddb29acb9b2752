// Streaming reader for MCAP files (https://mcap.dev/spec, format version 0),
// the default rosbag2 storage since ROS 2 Iron. Layout:
//   magic "\x89MCAP0\r\n", records, magic.
//   record = opcode (uint8), content length (uint64 LE), content.
// Records used here: Header (0x01), Footer (0x02: summary_start,
// summary_offset_start, summary_crc), Schema (0x03: id u16, name, encoding,
// data), Channel (0x04: id u16, schema_id u16, topic, message_encoding,
// metadata), Message (0x05: channel_id u16, sequence u32, log_time u64,
// publish_time u64, data), Chunk (0x06: start/end time, uncompressed size
// u64, uncompressed CRC-32 u32, compression "" | "zstd" | "lz4" (LZ4 frame
// format), records u64-prefixed), Statistics (0x0B, summary) and DataEnd
// (0x0F: data-section CRC-32). Strings are u32-length-prefixed; all integers
// little-endian. A CRC of 0 means "not computed" and is not checked.
// Streaming keeps one chunk (compressed and decompressed) in memory.
#pragma once

#include <cstdint>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace umbmark::io::rosbag2 {

struct McapSchema {
  std::uint16_t id = 0;
  std::string name;      ///< e.g. sensor_msgs/msg/JointState
  std::string encoding;  ///< ros2msg | ros2idl | ...
};

struct McapChannel {
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;
  std::string topic;
  std::string message_encoding;  ///< cdr for rosbag2
  std::string schema_name;       ///< resolved from schema_id ("" when 0)
};

/// One message; `data` points into the reader's buffer and is valid only
/// during the callback. `offset` is the file offset of the record (inside
/// an uncompressed chunk too); inside a compressed chunk it is the chunk's,
/// and `chunk_byte` the record's offset in the decompressed chunk.
struct McapMessage {
  std::uint16_t channel_id = 0;
  std::uint64_t log_time_ns = 0;
  const std::uint8_t* data = nullptr;
  std::size_t size = 0;
  std::uint64_t offset = 0;
  bool compressed_chunk = false;
  std::uint64_t chunk_byte = 0;
};

/// What the summary section tells without reading the data.
struct McapSummary {
  std::vector<McapChannel> channels;
  std::map<std::uint16_t, std::uint64_t> message_counts;  ///< per channel (Statistics)
  std::uint64_t start_ns = 0, end_ns = 0;
};

class McapReader {
 public:
  /// Opens the file and checks the leading magic. Throws InputError.
  explicit McapReader(std::string path);
  ~McapReader();
  McapReader(const McapReader&) = delete;
  McapReader& operator=(const McapReader&) = delete;

  /// Reads the footer and the summary section. Returns false when the file
  /// has no summary or no Statistics record (then Stream() must be used to
  /// learn the channels). Throws InputError on a corrupt footer/summary.
  bool ReadSummary(McapSummary& out);

  /// Reads every record from the start in file order. `on_channel` is called
  /// once per channel as it appears and returns whether its messages are
  /// wanted; `on_message` gets the wanted messages. Throws InputError (with
  /// the byte offset) for a truncated file, bad record lengths, failed
  /// decompression or a non-zero CRC that does not match.
  void Stream(const std::function<bool(const McapChannel&)>& on_channel,
              const std::function<void(const McapMessage&)>& on_message);

  const std::string& path() const { return path_; }
  std::uint64_t file_size() const { return size_; }
  /// The largest chunk (decompressed) the reader allocates: half the
  /// physical memory, at most 16 GiB. Limited by memory, not by ratio.
  static std::uint64_t MaxChunkBytes();

 private:
  [[noreturn]] void Fail(std::uint64_t offset, const std::string& what) const;
  void ReadExact(void* dst, std::size_t n, std::uint64_t record_offset);
  void HandleRecord(std::uint8_t op, const std::uint8_t* content, std::size_t n, std::uint64_t base,
                    std::size_t chunk_at, bool in_chunk, const std::function<bool(const McapChannel&)>& on_channel,
                    const std::function<void(const McapMessage&)>& on_message);
  void DecompressChunk(const std::uint8_t* content, std::size_t size, std::uint64_t offset);
  bool GrowChunk(std::size_t claimed);
  std::size_t Unzstd(const std::uint8_t* in, std::size_t n, std::size_t claimed, std::uint64_t offset);
  std::size_t Unlz4(const std::uint8_t* in, std::size_t n, std::size_t claimed, std::uint64_t offset);

  std::string path_;
  struct FileCloser {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  std::unique_ptr<std::FILE, FileCloser> file_;  ///< closed however the reader ends
  std::uint64_t size_ = 0;
  std::uint64_t pos_ = 0;
  std::vector<std::uint8_t> record_;  ///< current record's content
  std::vector<std::uint8_t> chunk_;   ///< current chunk, decompressed
  bool chunk_compressed_ = false;     ///< current chunk's compression is not ""
  std::size_t chunk_records_at_ = 0;  ///< offset of its records in the chunk record's content
  std::map<std::uint16_t, McapSchema> schemas_;
  std::vector<std::int8_t> channel_state_;  ///< by id: -1 unknown, 0 unwanted, 1 wanted
};

}  // namespace umbmark::io::rosbag2
