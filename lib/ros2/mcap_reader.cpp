// MCAP streaming reader (see mcap_reader.hpp for the format).
#include "ros2/mcap_reader.hpp"

#include <cerrno>
#include <algorithm>
#include <cstring>
#include <string_view>

#include <unistd.h>

#include <fmt/format.h>
#include <isa-l/crc.h>
#include <lz4frame.h>
#include <zstd.h>

#include "core/errors.hpp"

namespace umbmark::io::rosbag2 {

namespace {

constexpr std::uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
enum Opcode : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kStatistics = 0x0B,
  kDataEnd = 0x0F,
};
constexpr std::size_t kRecordHeader = 9;  // opcode + uint64 length
constexpr std::size_t kFooterRecord = kRecordHeader + 20;

const char* OpcodeName(std::uint8_t op) {
  switch (op) {
    case 0x01: return "Header";
    case 0x02: return "Footer";
    case 0x03: return "Schema";
    case 0x04: return "Channel";
    case 0x05: return "Message";
    case 0x06: return "Chunk";
    case 0x07: return "MessageIndex";
    case 0x08: return "ChunkIndex";
    case 0x09: return "Attachment";
    case 0x0A: return "AttachmentIndex";
    case 0x0B: return "Statistics";
    case 0x0C: return "Metadata";
    case 0x0D: return "MetadataIndex";
    case 0x0E: return "SummaryOffset";
    case 0x0F: return "DataEnd";
    default: return "unknown";
  }
}

std::uint64_t Le64(const std::uint8_t* p) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

// CRC-32 (IEEE 802.3, reflected, as zlib and MCAP compute it), continued
// from `crc`; ISA-L's carry-less-multiply kernel runs at memory speed.
std::uint32_t Crc32(std::uint32_t crc, const std::uint8_t* p, std::size_t n) { return crc32_gzip_refl(crc, p, n); }

// Little-endian field cursor over one record's content; any read past the
// end reports the record's offset and kind.
class Fields {
 public:
  Fields(const std::uint8_t* p, std::size_t n, std::uint64_t offset, std::uint8_t op, const McapReader& r)
      : p_(p), n_(n), offset_(offset), op_(op), reader_(r) {}
  std::uint8_t U8() { return *Take(1); }
  std::uint16_t U16() {
    const auto* b = Take(2);
    return static_cast<std::uint16_t>(b[0] | (b[1] << 8));
  }
  std::uint32_t U32() {
    const auto* b = Take(4);
    return static_cast<std::uint32_t>(b[0]) | (static_cast<std::uint32_t>(b[1]) << 8) |
           (static_cast<std::uint32_t>(b[2]) << 16) | (static_cast<std::uint32_t>(b[3]) << 24);
  }
  std::uint64_t U64() { return Le64(Take(8)); }
  std::string Str() {
    const std::uint32_t len = U32();
    const auto* b = Take(len);
    return {reinterpret_cast<const char*>(b), len};
  }
  /// A byte block with a u32 (or u64) length prefix.
  std::pair<const std::uint8_t*, std::size_t> Bytes32() {
    const std::uint32_t len = U32();
    return {Take(len), len};
  }
  std::pair<const std::uint8_t*, std::size_t> Bytes64() {
    const std::uint64_t len = U64();
    if (len > n_ - pos_) Short(len);
    return {Take(static_cast<std::size_t>(len)), static_cast<std::size_t>(len)};
  }
  std::pair<const std::uint8_t*, std::size_t> Rest() { return {p_ + pos_, n_ - pos_}; }
  std::size_t left() const { return n_ - pos_; }

 private:
  const std::uint8_t* Take(std::size_t k) {
    if (k > n_ - pos_) Short(k);
    const auto* b = p_ + pos_;
    pos_ += k;
    return b;
  }
  [[noreturn]] void Short(std::uint64_t k) const {
    throw InputError(reader_.path(), fmt::format("byte {}: {} record is too short ({} bytes, a field at {} needs {} more)",
                                                 offset_, OpcodeName(op_), n_, pos_, k));
  }
  const std::uint8_t* p_;
  std::size_t n_;
  std::size_t pos_ = 0;
  std::uint64_t offset_;
  std::uint8_t op_;
  const McapReader& reader_;
};

}  // namespace

McapReader::McapReader(std::string path) : path_(std::move(path)) {
  // The file is owned by file_ as soon as it is open, so a constructor that
  // throws below (a rejected file) still closes it: a throwing constructor
  // runs no destructor, and the MCAP fuzzer ran out of descriptors after
  // ~1e6 non-MCAP inputs when the file was closed only there.
  file_.reset(std::fopen(path_.c_str(), "rb"));
  if (!file_) throw InputError(path_, fmt::format("cannot open: {}", std::strerror(errno)));
  std::setvbuf(file_.get(), nullptr, _IOFBF, 1 << 20);
  if (std::fseek(file_.get(), 0, SEEK_END) != 0) Fail(0, "cannot seek (not a regular file?)");
  const long end = std::ftell(file_.get());
  if (end < 0) Fail(0, "cannot tell the file size");
  size_ = static_cast<std::uint64_t>(end);
  std::rewind(file_.get());
  std::uint8_t magic[8] = {};
  if (size_ < 8 || std::fread(magic, 1, 8, file_.get()) != 8 || std::memcmp(magic, kMagic, 8) != 0)
    Fail(0, "not an MCAP file (the magic bytes \\x89MCAP0\\r\\n are missing)");
  pos_ = 8;
}

McapReader::~McapReader() = default;

// Half the physical memory, at most 16 GiB: what one chunk may take.
std::uint64_t McapReader::MaxChunkBytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  const std::uint64_t phys = pages > 0 && page > 0 ? static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(page)
                                                   : (1ull << 32);
  return std::min<std::uint64_t>(phys / 2, 1ull << 34);
}

void McapReader::Fail(std::uint64_t offset, const std::string& what) const {
  throw InputError(path_, fmt::format("byte {}: {}", offset, what));
}

void McapReader::ReadExact(void* dst, std::size_t n, std::uint64_t record_offset) {
  if (n == 0) return;
  if (std::fread(dst, 1, n, file_.get()) != n)
    Fail(record_offset, fmt::format("read error or file truncated (file is {} bytes)", size_));
  pos_ += n;
}

bool McapReader::ReadSummary(McapSummary& out) {
  if (size_ < 8 + kFooterRecord + 8) return false;
  std::uint8_t tail[kFooterRecord + 8];
  const std::uint64_t footer_at = size_ - sizeof(tail);
  if (std::fseek(file_.get(), static_cast<long>(footer_at), SEEK_SET) != 0 || std::fread(tail, 1, sizeof(tail), file_.get()) != sizeof(tail))
    Fail(footer_at, "cannot read the footer");
  std::fseek(file_.get(), static_cast<long>(pos_), SEEK_SET);
  if (std::memcmp(tail + kFooterRecord, kMagic, 8) != 0 || tail[0] != kFooter || Le64(tail + 1) != 20) return false;
  const std::uint64_t summary_start = Le64(tail + kRecordHeader);
  const std::uint32_t summary_crc = static_cast<std::uint32_t>(Le64(tail + kRecordHeader + 16) & 0xffffffffu);
  if (summary_start == 0) return false;
  if (summary_start < 8 || summary_start > footer_at) Fail(footer_at, fmt::format("footer's summary start {} is outside the file", summary_start));
  std::vector<std::uint8_t> summary(static_cast<std::size_t>(footer_at - summary_start));
  std::fseek(file_.get(), static_cast<long>(summary_start), SEEK_SET);
  if (std::fread(summary.data(), 1, summary.size(), file_.get()) != summary.size()) Fail(summary_start, "cannot read the summary");
  std::fseek(file_.get(), static_cast<long>(pos_), SEEK_SET);
  if (summary_crc != 0) {
    // CRC of the summary section and the footer's fields before the CRC.
    std::uint32_t crc = Crc32(0, summary.data(), summary.size());
    crc = Crc32(crc, tail, kRecordHeader + 16);
    if (crc != summary_crc) Fail(summary_start, fmt::format("summary CRC mismatch (stored {:08x}, computed {:08x})", summary_crc, crc));
  }
  std::map<std::uint16_t, McapSchema> schemas;
  bool have_stats = false;
  std::size_t at = 0;
  while (at < summary.size()) {
    const std::uint64_t offset = summary_start + at;
    if (summary.size() - at < kRecordHeader) Fail(offset, "summary record header runs past the footer");
    const std::uint8_t op = summary[at];
    const std::uint64_t len = Le64(&summary[at + 1]);
    if (len > summary.size() - at - kRecordHeader) Fail(offset, fmt::format("{} record length {} runs past the footer", OpcodeName(op), len));
    Fields f(&summary[at + kRecordHeader], static_cast<std::size_t>(len), offset, op, *this);
    if (op == kSchema) {
      McapSchema s;
      s.id = f.U16();
      s.name = f.Str();
      s.encoding = f.Str();
      schemas[s.id] = s;
    } else if (op == kChannel) {
      McapChannel c;
      c.id = f.U16();
      c.schema_id = f.U16();
      c.topic = f.Str();
      c.message_encoding = f.Str();
      out.channels.push_back(c);
    } else if (op == kStatistics) {
      have_stats = true;
      f.U64();  // message_count
      f.U16();  // schema_count
      f.U32();  // channel_count
      f.U32();  // attachment_count
      f.U32();  // metadata_count
      f.U32();  // chunk_count
      out.start_ns = f.U64();
      out.end_ns = f.U64();
      const std::uint32_t map_bytes = f.U32();
      if (map_bytes > f.left() || map_bytes % 10 != 0) Fail(offset, "Statistics record: bad channel_message_counts length");
      for (std::uint32_t i = 0; i < map_bytes / 10; ++i) {
        const std::uint16_t ch = f.U16();
        out.message_counts[ch] = f.U64();
      }
    }
    at += kRecordHeader + static_cast<std::size_t>(len);
  }
  for (auto& c : out.channels) {
    if (c.schema_id == 0) continue;
    auto it = schemas.find(c.schema_id);
    if (it == schemas.end()) Fail(summary_start, fmt::format("channel {} ({}) refers to schema {} which is not in the summary", c.id, c.topic, c.schema_id));
    c.schema_name = it->second.name;
  }
  return have_stats;
}

// Grows chunk_ for a decompression that has filled it: doubling, at most
// to the claimed size. Returns false when it is already that large.
bool McapReader::GrowChunk(std::size_t claimed) {
  if (chunk_.size() >= claimed) return false;
  chunk_.resize(std::min(claimed, std::max<std::size_t>(2 * chunk_.size(), 1 << 20)));
  return true;
}

// Streaming zstd into chunk_ (one or more frames); returns the bytes
// produced, or claimed + 1 when the data would exceed the claim.
std::size_t McapReader::Unzstd(const std::uint8_t* in, std::size_t n, std::size_t claimed, std::uint64_t offset) {
  std::unique_ptr<ZSTD_DCtx, std::size_t (*)(ZSTD_DCtx*)> z(ZSTD_createDCtx(), ZSTD_freeDCtx);
  if (!z) Fail(offset, "cannot create a zstd context");
  chunk_.resize(std::min<std::size_t>(claimed, (1 << 20) + 16 * n));
  ZSTD_inBuffer src{in, n, 0};
  std::size_t produced = 0, left = 1;
  while (src.pos < src.size || left != 0) {
    ZSTD_outBuffer dst{chunk_.data(), chunk_.size(), produced};
    left = ZSTD_decompressStream(z.get(), &dst, &src);
    if (ZSTD_isError(left)) Fail(offset, fmt::format("zstd decompression of the chunk failed: {}", ZSTD_getErrorName(left)));
    const bool progressed = dst.pos > produced;
    produced = dst.pos;
    if (produced == chunk_.size() && (left != 0 || src.pos < src.size) && !GrowChunk(claimed)) return claimed + 1;
    if (!progressed && src.pos == src.size && left != 0) Fail(offset, "zstd chunk ends inside a frame (truncated)");
  }
  chunk_.resize(produced);
  return produced;
}

std::size_t McapReader::Unlz4(const std::uint8_t* in, std::size_t n, std::size_t claimed, std::uint64_t offset) {
  LZ4F_dctx* raw = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&raw, LZ4F_VERSION))) Fail(offset, "cannot create an LZ4 context");
  std::unique_ptr<LZ4F_dctx, LZ4F_errorCode_t (*)(LZ4F_dctx*)> dctx(raw, LZ4F_freeDecompressionContext);
  chunk_.resize(std::min<std::size_t>(claimed, (1 << 20) + 16 * n));
  std::size_t in_pos = 0, out_pos = 0, hint = 1;
  while (hint != 0 && in_pos < n) {
    if (out_pos == chunk_.size() && !GrowChunk(claimed)) return claimed + 1;
    std::size_t in_n = n - in_pos, out_n = chunk_.size() - out_pos;
    hint = LZ4F_decompress(dctx.get(), chunk_.data() + out_pos, &out_n, in + in_pos, &in_n, nullptr);
    if (LZ4F_isError(hint)) Fail(offset, std::string("lz4 decompression of the chunk failed: ") + LZ4F_getErrorName(hint));
    in_pos += in_n;
    out_pos += out_n;
    if (in_n == 0 && out_n == 0 && out_pos < chunk_.size()) break;  // no progress
  }
  if (hint != 0) Fail(offset, fmt::format("lz4 chunk ends inside its frame after {} bytes (truncated)", out_pos));
  chunk_.resize(out_pos);
  return out_pos;
}

void McapReader::DecompressChunk(const std::uint8_t* content, std::size_t size, std::uint64_t offset) {
  Fields f(content, size, offset, kChunk, *this);
  f.U64();  // message_start_time
  f.U64();  // message_end_time
  const std::uint64_t uncompressed_size = f.U64();
  const std::uint32_t crc = f.U32();
  const std::string compression = f.Str();
  const auto [records, records_size] = f.Bytes64();
  // Limited by memory, not by ratio (zstd legitimately expands a black
  // camera image more than 1000x): the claimed size must fit in memory, and
  // the buffer grows with what the codec actually produces, so a small
  // chunk that claims gigabytes costs only what it really expands to.
  chunk_compressed_ = !compression.empty();
  chunk_records_at_ = static_cast<std::size_t>(records - content);
  if (uncompressed_size > MaxChunkBytes())
    Fail(offset, fmt::format("chunk claims {} uncompressed bytes (from {} compressed), more than this reader takes in "
                             "memory ({} bytes)", uncompressed_size, records_size, MaxChunkBytes()));
  const auto claimed = static_cast<std::size_t>(uncompressed_size);
  if (compression.empty()) {
    if (records_size != uncompressed_size)
      Fail(offset, fmt::format("uncompressed chunk holds {} bytes but says {}", records_size, uncompressed_size));
    chunk_.resize(claimed);
    if (records_size > 0) std::memcpy(chunk_.data(), records, records_size);
  } else if (compression == "zstd" || compression == "lz4") {
    const std::size_t got = compression == "zstd" ? Unzstd(records, records_size, claimed, offset)
                                                  : Unlz4(records, records_size, claimed, offset);
    if (got > claimed)
      Fail(offset, fmt::format("{} chunk decompresses to more than the {} bytes its header says", compression, claimed));
    if (got != claimed)
      Fail(offset, fmt::format("{} chunk decompressed to {} bytes, header says {}", compression, got, uncompressed_size));
  } else {
    Fail(offset, fmt::format("unsupported chunk compression '{}' (zstd, lz4 or none expected)", compression));
  }
  if (crc != 0) {
    const std::uint32_t got = Crc32(0, chunk_.data(), chunk_.size());
    if (got != crc) Fail(offset, fmt::format("chunk CRC mismatch (stored {:08x}, computed {:08x})", crc, got));
  }
}

void McapReader::HandleRecord(std::uint8_t op, const std::uint8_t* content, std::size_t n, std::uint64_t base,
                              std::size_t chunk_at, bool in_chunk,
                              const std::function<bool(const McapChannel&)>& on_channel,
                              const std::function<void(const McapMessage&)>& on_message) {
  const std::string where = in_chunk ? fmt::format(" at chunk byte {}", chunk_at) : std::string();
  if (op == kMessage) {
    if (n < 22) Fail(base, fmt::format("Message record{} is too short ({} bytes)", where, n));
    const std::uint16_t ch = static_cast<std::uint16_t>(content[0] | (content[1] << 8));
    if (ch >= channel_state_.size() || channel_state_[ch] < 0)
      Fail(base, fmt::format("message{} on channel {} before that channel's record", where, ch));
    if (channel_state_[ch] > 0) {
      // Inside an uncompressed chunk the record's file offset is exact;
      // inside a compressed one, its offset in the decompressed chunk.
      const bool compressed = in_chunk && chunk_compressed_;
      const std::uint64_t at = !in_chunk ? base : compressed ? base : base + kRecordHeader + chunk_records_at_ + chunk_at;
      on_message({ch, Le64(content + 6), content + 22, n - 22, at, compressed, compressed ? chunk_at : 0});
    }
  } else if (op == kSchema) {
    Fields f(content, n, base, op, *this);
    McapSchema s;
    s.id = f.U16();
    s.name = f.Str();
    s.encoding = f.Str();
    schemas_[s.id] = std::move(s);
  } else if (op == kChannel) {
    Fields f(content, n, base, op, *this);
    McapChannel c;
    c.id = f.U16();
    c.schema_id = f.U16();
    c.topic = f.Str();
    c.message_encoding = f.Str();
    if (c.schema_id != 0) {
      auto it = schemas_.find(c.schema_id);
      if (it == schemas_.end())
        Fail(base, fmt::format("channel {} ({}){} refers to schema {} before that schema's record", c.id, c.topic, where,
                               c.schema_id));
      c.schema_name = it->second.name;
    }
    if (c.id >= channel_state_.size()) channel_state_.resize(static_cast<std::size_t>(c.id) + 1, -1);
    if (channel_state_[c.id] < 0) channel_state_[c.id] = on_channel(c) ? 1 : 0;
  } else if (op == kChunk) {
    if (in_chunk) Fail(base, "chunk inside a chunk");
    DecompressChunk(content, n, base);
    std::size_t at = 0;
    while (at < chunk_.size()) {
      if (chunk_.size() - at < kRecordHeader) Fail(base, fmt::format("chunk record at chunk byte {} is cut off", at));
      const std::uint8_t inner = chunk_[at];
      const std::uint64_t len = Le64(chunk_.data() + at + 1);
      if (len > chunk_.size() - at - kRecordHeader)
        Fail(base, fmt::format("{} record at chunk byte {} claims {} bytes, the chunk has {} left", OpcodeName(inner), at,
                               len, chunk_.size() - at - kRecordHeader));
      HandleRecord(inner, chunk_.data() + at + kRecordHeader, static_cast<std::size_t>(len), base, at, true, on_channel,
                   on_message);
      at += kRecordHeader + static_cast<std::size_t>(len);
    }
  }
}

// Top-level loop: one record at a time from the file; the data-section CRC
// is accumulated over every byte before DataEnd.
void McapReader::Stream(const std::function<bool(const McapChannel&)>& on_channel,
                        const std::function<void(const McapMessage&)>& on_message) {
  std::fseek(file_.get(), 8, SEEK_SET);
  pos_ = 8;
  schemas_.clear();
  channel_state_.clear();
  std::uint32_t crc = Crc32(0, kMagic, 8);
  bool data_end = false, first = true;
  std::uint8_t header[kRecordHeader];
  while (true) {
    const std::uint64_t offset = pos_;
    if (size_ - pos_ < kRecordHeader)
      Fail(offset, size_ == pos_ ? "file ends without a Footer record (truncated recording?)"
                                 : "file ends inside a record header (truncated)");
    ReadExact(header, kRecordHeader, offset);
    const std::uint8_t op = header[0];
    const std::uint64_t len = Le64(header + 1);
    if (len > size_ - pos_)
      Fail(offset, fmt::format("{} record (opcode 0x{:02x}) claims {} bytes but the file has {} left (truncated or corrupt)",
                               OpcodeName(op), op, len, size_ - pos_));
    if (first && op != kHeader) Fail(offset, fmt::format("first record is {} (0x{:02x}), not Header", OpcodeName(op), op));
    first = false;
    record_.resize(static_cast<std::size_t>(len));
    ReadExact(record_.data(), record_.size(), offset);
    if (op == kFooter) {
      std::uint8_t magic[8] = {};
      if (size_ - pos_ != 8 || std::fread(magic, 1, 8, file_.get()) != 8 || std::memcmp(magic, kMagic, 8) != 0)
        Fail(pos_, "the Footer is not followed by the closing magic bytes at the end of the file");
      return;
    }
    if (data_end) continue;  // summary section: duplicates and indexes
    if (op == kDataEnd) {
      Fields f(record_.data(), record_.size(), offset, op, *this);
      const std::uint32_t stored = f.U32();
      if (stored != 0 && stored != crc)
        Fail(offset, fmt::format("data section CRC mismatch (stored {:08x}, computed {:08x})", stored, crc));
      data_end = true;
      continue;
    }
    crc = Crc32(crc, header, kRecordHeader);
    crc = Crc32(crc, record_.data(), record_.size());
    HandleRecord(op, record_.data(), record_.size(), offset, 0, false, on_channel, on_message);
  }
}

}  // namespace umbmark::io::rosbag2
