#include "io/rosbag/bag_structure_check.hpp"

#include "io/input_error.hpp"

// Format: ROS bag 2.0 (a version line, then records [u32 header_len][header][u32 data_len][data],
// little-endian; a header is a list of [u32 len]["name=value"] fields). The walk below reads the
// records in the order and with the framing rosbag_storage 1.15 uses when it opens a bag and
// when it reads a message, so whatever passes here is safe for it to read.

#include <bzlib.h>
#include <roslz4/lz4s.h>

#include <cerrno>
#include <cstdio>
#include <algorithm>
#include <cstring>
#include <map>
#include <set>
#include <vector>

#include <spdlog/fmt/fmt.h>

namespace dynavins::io::detail {

namespace {

constexpr uint8_t kOpMsgDef = 0x01;
constexpr uint8_t kOpMsgData = 0x02;
constexpr uint8_t kOpFileHeader = 0x03;
constexpr uint8_t kOpIndexData = 0x04;
constexpr uint8_t kOpChunk = 0x05;
constexpr uint8_t kOpChunkInfo = 0x06;
constexpr uint8_t kOpConnection = 0x07;
// rosbag's Buffer grows by doubling a uint32: anything above 2 GiB could overflow it.
constexpr uint64_t kMaxBuffer = uint64_t{1} << 31;

using Fields = std::map<std::string, std::string>;

class BagFile {
 public:
  explicit BagFile(const std::string& path) : path_(path) {
    f_ = std::fopen(path.c_str(), "rb");
    if (!f_) throw InputError(path, 0, fmt::format("cannot open: {}", std::strerror(errno)));
    if (fseeko(f_, 0, SEEK_END) != 0) fail(0, "cannot seek");
    const off_t end = ftello(f_);
    if (end < 0) fail(0, "cannot tell the file size");
    size_ = static_cast<uint64_t>(end);
  }
  ~BagFile() { std::fclose(f_); }
  BagFile(const BagFile&) = delete;
  BagFile& operator=(const BagFile&) = delete;

  uint64_t size() const { return size_; }
  const std::string& path() const { return path_; }

  [[noreturn]] void fail(uint64_t pos, const std::string& what) const {
    throw InputError(path_, 0, fmt::format("corrupt or truncated ROS bag at byte {}: {}", pos, what));
  }
  // Throws unless [pos, pos + n) lies inside the file; call before sizing a buffer by n.
  void check_range(uint64_t pos, uint64_t n, const char* what) const {
    if (pos > size_ || n > size_ - pos)
      fail(pos, fmt::format("{} ({} bytes) runs past the end of the file ({} bytes)", what, n, size_));
  }
  void read(uint64_t pos, uint64_t n, void* dst, const char* what) const {
    check_range(pos, n, what);
    if (n == 0) return;
    if (fseeko(f_, static_cast<off_t>(pos), SEEK_SET) != 0 || std::fread(dst, 1, n, f_) != n)
      fail(pos, fmt::format("cannot read {}", what));
  }
  uint32_t u32(uint64_t pos, const char* what) const {
    uint32_t v = 0;
    read(pos, 4, &v, what);
    return v;
  }

 private:
  std::string path_;
  std::FILE* f_ = nullptr;
  uint64_t size_ = 0;
};

// Parses a header with every length checked (ros::Header::parse trusts them); false on error.
bool parse_fields(const uint8_t* p, uint64_t len, Fields* out) {
  uint64_t i = 0;
  while (i < len) {
    if (len - i < 4) return false;
    uint32_t flen = 0;
    std::memcpy(&flen, p + i, 4);
    i += 4;
    if (flen > len - i) return false;
    const std::string field(reinterpret_cast<const char*>(p + i), flen);
    i += flen;
    const auto eq = field.find('=');
    if (eq == std::string::npos) return false;
    (*out)[field.substr(0, eq)] = field.substr(eq + 1);
  }
  return true;
}

struct Record {
  uint64_t pos = 0;
  uint64_t data_pos = 0;
  uint32_t data_len = 0;
  Fields fields;
};

Record read_record(const BagFile& f, uint64_t pos, const char* what) {
  Record r;
  r.pos = pos;
  const uint32_t header_len = f.u32(pos, what);
  if (header_len > f.size() - pos - 4)
    f.fail(pos, fmt::format("{}: header length {} runs past the end", what, header_len));
  std::vector<uint8_t> header(header_len);
  f.read(pos + 4, header_len, header.data(), what);
  if (!parse_fields(header.data(), header_len, &r.fields)) f.fail(pos, fmt::format("{}: malformed header", what));
  r.data_len = f.u32(pos + 4 + header_len, what);
  r.data_pos = pos + 8 + header_len;
  if (r.data_len > kMaxBuffer || r.data_len > f.size() - r.data_pos)
    f.fail(pos, fmt::format("{}: data length {} runs past the end of the file", what, r.data_len));
  return r;
}

// A fixed-size little-endian field, as rosbag's readField requires it (present, exact size).
template <typename T>
T field(const BagFile& f, const Record& r, const char* name, const char* what) {
  const auto it = r.fields.find(name);
  if (it == r.fields.end() || it->second.size() != sizeof(T))
    f.fail(r.pos, fmt::format("{}: field '{}' missing or not {} bytes", what, name, sizeof(T)));
  T v{};
  std::memcpy(&v, it->second.data(), sizeof(T));
  return v;
}

void expect_op(const BagFile& f, const Record& r, uint8_t op, const char* what) {
  const auto got = field<uint8_t>(f, r, "op", what);
  if (got != op) f.fail(r.pos, fmt::format("expected {} (op {:#04x}), found op {:#04x}", what, op, got));
}

// A chunk's bytes as rosbag will hold them: read from the file (uncompressed) or decompressed.
class ChunkData {
 public:
  ChunkData(const BagFile& f, const Record& chunk) : f_(f), pos_(chunk.pos) {
    const auto it = chunk.fields.find("compression");
    const std::string compression = it == chunk.fields.end() ? "" : it->second;
    const uint32_t size = field<uint32_t>(f, chunk, "size", "chunk record");
    if (compression == "none") {
      base_ = chunk.data_pos;
      size_ = chunk.data_len;
      return;
    }
    if (compression != "bz2" && compression != "lz4")
      f.fail(pos_, fmt::format("unknown chunk compression '{}'", compression));
    if (size > kMaxBuffer) f.fail(pos_, fmt::format("chunk size {} too large", size));
    std::vector<char> packed(chunk.data_len);
    f.read(chunk.data_pos, chunk.data_len, packed.data(), "chunk data");
    mem_.resize(size);
    unsigned int out_len = size;
    int rc = 0;
    if (compression == "bz2") {
      rc = BZ2_bzBuffToBuffDecompress(mem_.data(), &out_len, packed.data(), chunk.data_len, 0, 0);
      if (rc != BZ_OK) f.fail(pos_, fmt::format("bz2 chunk does not decompress (error {})", rc));
    } else {
      rc = roslz4_buffToBuffDecompress(packed.data(), chunk.data_len, mem_.data(), &out_len);
      if (rc != ROSLZ4_OK) f.fail(pos_, fmt::format("lz4 chunk does not decompress (error {})", rc));
    }
    if (out_len != size) f.fail(pos_, fmt::format("chunk decompresses to {} bytes, header says {}", out_len, size));
    in_memory_ = true;
    size_ = size;
  }

  uint64_t size() const { return size_; }
  void read(uint64_t off, uint64_t n, void* dst, const char* what) const {
    if (off > size_ || n > size_ - off)
      f_.fail(pos_,
              fmt::format("{} at chunk offset {} ({} bytes) runs past the chunk ({} bytes)", what, off, n, size_));
    if (n == 0) return;  // an empty header's vector has no buffer: memcpy from/to null is undefined even for 0 bytes
    if (in_memory_)
      std::memcpy(dst, mem_.data() + off, n);
    else
      f_.read(base_ + off, n, dst, what);
  }

  // Follows rosbag's readMessageDataHeaderFromBuffer from `off`: definition/connection records
  // are stepped over by their header alone, then a whole MSG_DATA record must fit.
  void check_message(uint64_t off, const std::set<uint32_t>& connections) const {
    const uint64_t start = off;
    for (int hop = 0; hop < 64; ++hop) {
      uint32_t header_len = 0;
      read(off, 4, &header_len, "message record");
      if (header_len > size_ - off - 4) bad(start, fmt::format("header length {} runs past the chunk", header_len));
      std::vector<uint8_t> header(header_len);
      read(off + 4, header_len, header.data(), "message header");
      Record r;
      r.pos = pos_;
      if (!parse_fields(header.data(), header_len, &r.fields)) bad(start, "malformed message header");
      uint32_t data_len = 0;
      read(off + 4 + header_len, 4, &data_len, "message data length");
      const uint8_t op = field<uint8_t>(f_, r, "op", "message record");
      const uint64_t bytes = 8 + uint64_t{header_len};
      if (op == kOpMsgDef || op == kOpConnection) {
        off += bytes;
        continue;
      }
      if (op != kOpMsgData) bad(start, fmt::format("index points at op {:#04x}, not a message", op));
      if (data_len > size_ - off - bytes)
        bad(start, fmt::format("message data ({} bytes) runs past the chunk", data_len));
      const uint32_t conn = field<uint32_t>(f_, r, "conn", "message record");
      if (!connections.count(conn)) bad(start, fmt::format("message of unknown connection {}", conn));
      return;
    }
    bad(start, "no message record after 64 definition records");
  }

 private:
  [[noreturn]] void bad(uint64_t off, const std::string& what) const {
    f_.fail(pos_, fmt::format("message at chunk offset {}: {}", off, what));
  }

  const BagFile& f_;
  uint64_t pos_ = 0;
  uint64_t base_ = 0;
  uint64_t size_ = 0;
  bool in_memory_ = false;
  std::vector<char> mem_;
};

}  // namespace

BagStructure check_bag_structure(const std::string& path) {
  BagFile f(path);
  BagStructure out;

  char line[32] = {};
  const uint64_t head = std::min<uint64_t>(f.size(), sizeof(line) - 1);
  f.read(0, head, line, "version line");
  const char* nl = static_cast<const char*>(std::memchr(line, '\n', head));
  const std::string version(line, nl ? static_cast<std::size_t>(nl - line) : head);
  if (version != "#ROSBAG V2.0") {
    if (version.rfind("#ROSBAG V", 0) == 0)
      f.fail(0, fmt::format("unsupported bag format '{}' (only 2.0 is read)", version));
    f.fail(0, "not a ROS bag (no '#ROSBAG V2.0' line)");
  }
  uint64_t pos = version.size() + 1;

  const Record fh = read_record(f, pos, "file header");
  expect_op(f, fh, kOpFileHeader, "file header");
  const auto index_pos = field<uint64_t>(f, fh, "index_pos", "file header");
  out.connections = field<uint32_t>(f, fh, "conn_count", "file header");
  out.chunks = field<uint32_t>(f, fh, "chunk_count", "file header");
  const auto enc = fh.fields.find("encryptor");
  if (enc != fh.fields.end() && !enc->second.empty() && enc->second != "rosbag/NoEncryptor")
    f.fail(fh.pos, fmt::format("encrypted bag ({}) not supported", enc->second));
  if (index_pos == 0) f.fail(fh.pos, "the bag has no index (recording not closed; `rosbag reindex` repairs it)");
  if (index_pos >= f.size())
    f.fail(fh.pos, fmt::format("index at byte {} is past the end of the file ({} bytes)", index_pos, f.size()));

  std::set<uint32_t> connections;
  pos = index_pos;
  for (uint32_t i = 0; i < out.connections; ++i) {
    const Record c = read_record(f, pos, "connection record");
    expect_op(f, c, kOpConnection, "connection record");
    connections.insert(field<uint32_t>(f, c, "conn", "connection record"));
    if (c.fields.count("topic") == 0) f.fail(c.pos, "connection record without topic");
    // The data part is the connection header itself (type, md5sum, message_definition).
    std::vector<uint8_t> header(c.data_len);
    f.read(c.data_pos, c.data_len, header.data(), "connection header");
    Fields conn_fields;
    if (!parse_fields(header.data(), header.size(), &conn_fields)) f.fail(c.data_pos, "malformed connection header");
    pos = c.data_pos + c.data_len;
  }

  struct ChunkRef {
    uint64_t pos;
    std::size_t index_records;
  };
  std::vector<ChunkRef> chunks;
  for (uint32_t i = 0; i < out.chunks; ++i) {
    const Record ci = read_record(f, pos, "chunk info record");
    expect_op(f, ci, kOpChunkInfo, "chunk info record");
    if (field<uint32_t>(f, ci, "ver", "chunk info record") != 1) f.fail(ci.pos, "chunk info version is not 1");
    const auto chunk_pos = field<uint64_t>(f, ci, "chunk_pos", "chunk info record");
    field<uint64_t>(f, ci, "start_time", "chunk info record");
    field<uint64_t>(f, ci, "end_time", "chunk info record");
    const uint64_t count = field<uint32_t>(f, ci, "count", "chunk info record");
    // rosbag reads `count` (connection, message count) pairs right after the data length.
    f.check_range(ci.data_pos, 8 * count, "chunk info entries");
    std::vector<uint32_t> pairs(2 * count);
    f.read(ci.data_pos, 8 * count, pairs.data(), "chunk info entries");
    std::set<uint32_t> ids;
    for (uint64_t k = 0; k < count; ++k) ids.insert(pairs[2 * k]);
    chunks.push_back({chunk_pos, ids.size()});
    pos = ci.data_pos + 8 * count;
  }

  for (const ChunkRef& ref : chunks) {
    const Record chunk = read_record(f, ref.pos, "chunk record");
    expect_op(f, chunk, kOpChunk, "chunk record");
    const ChunkData data(f, chunk);
    uint64_t ipos = chunk.data_pos + chunk.data_len;
    for (std::size_t k = 0; k < ref.index_records; ++k) {
      const Record ix = read_record(f, ipos, "index record");
      expect_op(f, ix, kOpIndexData, "index record");
      if (field<uint32_t>(f, ix, "ver", "index record") != 1) f.fail(ix.pos, "index record version is not 1");
      const uint32_t conn = field<uint32_t>(f, ix, "conn", "index record");
      if (!connections.count(conn)) f.fail(ix.pos, fmt::format("index of unknown connection {}", conn));
      const uint64_t count = field<uint32_t>(f, ix, "count", "index record");
      // rosbag reads `count` (sec, nsec, offset) triples right after the data length.
      f.check_range(ix.data_pos, 12 * count, "index entries");
      std::vector<uint32_t> entries(3 * count);
      f.read(ix.data_pos, 12 * count, entries.data(), "index entries");
      for (uint64_t e = 0; e < count; ++e) data.check_message(entries[3 * e + 2], connections);
      out.index_entries += count;
      ipos = ix.data_pos + 12 * count;
    }
  }
  return out;
}

}  // namespace dynavins::io::detail
