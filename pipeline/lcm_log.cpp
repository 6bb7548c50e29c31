#include "pipeline/lcm_log.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>

#include <lcm/lcm-cpp.hpp>
#include <zlib.h>

namespace dynavins::pipeline {
namespace {

constexpr uint32_t kSyncWord = 0xEDA1DA01u;
constexpr int64_t kHeaderBytes = 4 + 8 + 8 + 4 + 4;
constexpr int32_t kMaxChannelLength = 256;  // LCM's own channel name limit (LCM_MAX_CHANNEL_NAME_LENGTH)

uint64_t read_be(const uint8_t* p, int bytes) {
  uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v = (v << 8) | p[i];
  return v;
}

void put_be(std::vector<uint8_t>& out, uint64_t v, int bytes) {
  for (int i = bytes - 1; i >= 0; --i) out.push_back(static_cast<uint8_t>(v >> (8 * i)));
}

/// CRC-32 (zlib) of a block continued over one event: its channel name, then its payload.
uint32_t crc_of_event(uint32_t crc, const std::string& channel, const uint8_t* data, std::size_t size) {
  crc = static_cast<uint32_t>(crc32(crc, reinterpret_cast<const Bytef*>(channel.data()), static_cast<uInt>(channel.size())));
  // zlib takes uInt lengths: a payload is below 2 GB (the reader's int32 length), so one call does.
  return static_cast<uint32_t>(crc32(crc, data, static_cast<uInt>(size)));
}

// A checksum event's payload: the block's first byte offset (int64), its event count (int64), its CRC-32.
constexpr std::size_t kChecksumPayloadBytes = 8 + 8 + 4;

std::string hex32(uint32_t v) {
  char b[11];
  std::snprintf(b, sizeof b, "0x%08x", v);
  return b;
}

}  // namespace

LcmLogWriter::LcmLogWriter(const std::string& path) : path_(path) {
  log_ = std::make_unique<lcm::LogFile>(path, "w");
  if (!log_->good()) throw std::runtime_error(path + ": cannot open for writing: " + std::strerror(errno));
}

LcmLogWriter::~LcmLogWriter() {
  try {
    close();
  } catch (...) {
    // A destructor must not throw; callers who care call close() themselves.
  }
}

void LcmLogWriter::write_event(const std::string& channel, int64_t utime, const uint8_t* data, std::size_t size) {
  lcm::LogEvent ev;
  ev.eventnum = events_;
  ev.timestamp = utime;
  ev.channel = channel;
  ev.datalen = static_cast<int32_t>(size);
  ev.data = const_cast<uint8_t*>(data);
  if (log_->writeEvent(&ev) != 0) throw std::runtime_error(path_ + ": write failed: " + std::strerror(errno));
  offset_ += kHeaderBytes + static_cast<int64_t>(channel.size() + size);
  last_utime_ = utime;
}

void LcmLogWriter::write_raw(const std::string& channel, int64_t utime, const std::vector<uint8_t>& payload) {
  if (!log_) throw std::runtime_error(path_ + ": write after close");
  if (channel == kChecksumChannel) throw std::invalid_argument(path_ + ": channel " + channel + " is reserved for checksums");
  if (block_events_ == 0) block_offset_ = offset_, block_crc_ = static_cast<uint32_t>(crc32(0, nullptr, 0));
  write_event(channel, utime, payload.data(), payload.size());
  block_crc_ = crc_of_event(block_crc_, channel, payload.data(), payload.size());
  ++block_events_;
  block_bytes_ += static_cast<int64_t>(payload.size());
  ++events_;
  if (block_events_ >= kChecksumBlockEvents || block_bytes_ >= kChecksumBlockBytes) close_block();
}

void LcmLogWriter::close_block() {
  if (block_events_ == 0) return;
  std::vector<uint8_t> payload;
  put_be(payload, static_cast<uint64_t>(block_offset_), 8);
  put_be(payload, static_cast<uint64_t>(block_events_), 8);
  put_be(payload, block_crc_, 4);
  // The block's last time, so lcm-logplayer's pacing does not jump.
  write_event(kChecksumChannel, last_utime_, payload.data(), payload.size());
  block_events_ = 0;
  block_bytes_ = 0;
}

void LcmLogWriter::close() {
  if (!log_) return;
  std::exception_ptr error;
  try {
    close_block();
  } catch (...) {
    error = std::current_exception();
  }
  std::FILE* fp = log_->getFilePtr();
  const bool flushed = fp && std::fflush(fp) == 0 && !std::ferror(fp);
  log_.reset();
  if (error) std::rethrow_exception(error);
  if (!flushed) throw std::runtime_error(path_ + ": could not write the log to disk");
}

LcmLogReader::LcmLogReader(const std::string& path) : path_(path) {
  fp_ = std::fopen(path.c_str(), "rb");
  if (!fp_) throw std::runtime_error(path + ": cannot open: " + std::strerror(errno));
  std::fseek(fp_, 0, SEEK_END);
  size_ = std::ftell(fp_);
  std::fseek(fp_, 0, SEEK_SET);
}

LcmLogReader::~LcmLogReader() {
  if (fp_) std::fclose(fp_);
}

std::string LcmLogReader::event_name(const LogRecord& r) {
  return "event #" + std::to_string(r.eventnum) + " (byte " + std::to_string(r.offset) + ", channel " + r.channel +
         ")";
}

bool LcmLogReader::next(LogRecord& out) {
  while (next_event(out)) {
    if (out.channel == kChecksumChannel) {
      check_block(out);
      continue;
    }
    if (block_events_ == 0) {
      block_offset_ = out.offset;
      block_first_index_ = index_ - 1;
      block_crc_ = static_cast<uint32_t>(crc32(0, nullptr, 0));
    }
    block_crc_ = crc_of_event(block_crc_, out.channel, out.data.data(), out.data.size());
    ++block_events_;
    ++checksums_.events_unverified;
    return true;
  }
  return false;
}

void LcmLogReader::check_block(const LogRecord& r) {
  const bool sized = r.data.size() == kChecksumPayloadBytes;
  const auto offset = sized ? static_cast<int64_t>(read_be(r.data.data(), 8)) : -1;
  const auto events = sized ? static_cast<int64_t>(read_be(r.data.data() + 8, 8)) : -1;
  const auto crc = sized ? static_cast<uint32_t>(read_be(r.data.data() + 16, 4)) : 0u;
  const bool lines_up = sized && block_events_ > 0 && offset == block_offset_ && events == block_events_;
  if (lines_up && crc != block_crc_)
    throw std::runtime_error(path_ + ": events #" + std::to_string(block_first_index_) + " to #" +
                             std::to_string(index_ - 2) + " (bytes " + std::to_string(block_offset_) + " to " +
                             std::to_string(r.offset) + "): checksum mismatch (CRC-32 " + hex32(block_crc_) +
                             " read, " + hex32(crc) + " written at byte " + std::to_string(r.offset) +
                             "): the log was changed after it was written");
  if (lines_up) {
    ++checksums_.blocks_verified;
    checksums_.events_verified += block_events_;
    checksums_.events_unverified -= block_events_;
  } else {
    ++checksums_.foreign_checksums;
  }
  block_events_ = 0;
}

bool LcmLogReader::next_event(LogRecord& out) {
  if (pos_ == size_) return false;
  const std::string at = path_ + ": event " + std::to_string(index_) + " at byte " + std::to_string(pos_);
  if (size_ - pos_ < kHeaderBytes) throw std::runtime_error(at + ": truncated event header");
  uint8_t h[kHeaderBytes];
  if (std::fread(h, 1, kHeaderBytes, fp_) != static_cast<std::size_t>(kHeaderBytes))
    throw std::runtime_error(at + ": read error");
  if (read_be(h, 4) != kSyncWord) throw std::runtime_error(at + ": not an LCM log event (bad sync word)");
  const auto channel_len = static_cast<int32_t>(read_be(h + 20, 4));
  const auto data_len = static_cast<int32_t>(read_be(h + 24, 4));
  if (channel_len <= 0 || channel_len > kMaxChannelLength || data_len < 0)
    throw std::runtime_error(at + ": corrupt event header (channel length " + std::to_string(channel_len) +
                             ", data length " + std::to_string(data_len) + ")");
  if (size_ - pos_ - kHeaderBytes < static_cast<int64_t>(channel_len) + data_len)
    throw std::runtime_error(at + ": truncated (event needs " + std::to_string(static_cast<int64_t>(channel_len) + data_len) +
                             " bytes, file has " + std::to_string(size_ - pos_ - kHeaderBytes) + ")");
  out.offset = pos_;
  out.eventnum = static_cast<int64_t>(read_be(h + 4, 8));
  out.utime = static_cast<int64_t>(read_be(h + 12, 8));
  out.channel.resize(static_cast<std::size_t>(channel_len));
  out.data.resize(static_cast<std::size_t>(data_len));
  if (std::fread(out.channel.data(), 1, out.channel.size(), fp_) != out.channel.size() ||
      std::fread(out.data.data(), 1, out.data.size(), fp_) != out.data.size())
    throw std::runtime_error(at + ": read error");
  pos_ += kHeaderBytes + channel_len + data_len;
  ++index_;
  return true;
}

int64_t payload_fingerprint(const std::vector<uint8_t>& data) {
  return data.size() < 8 ? 0 : static_cast<int64_t>(read_be(data.data(), 8));
}

}  // namespace dynavins::pipeline
