#include "pipeline/lcm_log.hpp"

#include <cerrno>
#include <cstring>

#include <lcm/lcm-cpp.hpp>

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

void LcmLogWriter::write_raw(const std::string& channel, int64_t utime, const std::vector<uint8_t>& payload) {
  if (!log_) throw std::runtime_error(path_ + ": write after close");
  lcm::LogEvent ev;
  ev.eventnum = events_;
  ev.timestamp = utime;
  ev.channel = channel;
  ev.datalen = static_cast<int32_t>(payload.size());
  ev.data = const_cast<uint8_t*>(payload.data());
  if (log_->writeEvent(&ev) != 0) throw std::runtime_error(path_ + ": write failed: " + std::strerror(errno));
  ++events_;
}

void LcmLogWriter::close() {
  if (!log_) return;
  std::FILE* fp = log_->getFilePtr();
  const bool flushed = fp && std::fflush(fp) == 0 && !std::ferror(fp);
  log_.reset();
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
