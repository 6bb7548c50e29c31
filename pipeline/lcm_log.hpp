#pragma once
// LCM event logs (the `lcm-logger` format) as the project's recorded-sensor-log format.
// Writing goes through LCM's own LogFile, so every log is what lcm-logplayer and lcm-spy read.
// Reading is our own small parser of that format (sync word, event number, timestamp, channel,
// payload; big-endian), because LCM's reader cannot tell a truncated log from its end: here a
// truncated or corrupt log is an error naming the file, the event index and the byte offset.

#include <cstdint>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "pipeline/wire_decode.hpp"

namespace lcm {
class LogFile;
}

namespace dynavins::pipeline {

/// One event of a log.
struct LogRecord {
  int64_t eventnum = 0;
  int64_t utime = 0;  ///< the event's log timestamp [us]
  std::string channel;
  std::vector<uint8_t> data;
  int64_t offset = 0;  ///< byte offset of the event in the file
};

class LcmLogWriter {
 public:
  /// Creates (truncates) `path`. Throws if it cannot be opened.
  explicit LcmLogWriter(const std::string& path);
  ~LcmLogWriter();

  /// Appends one encoded message. Throws on a write error.
  template <typename Msg>
  void write(const std::string& channel, int64_t utime, const Msg& msg) {
    std::vector<uint8_t> buf(static_cast<std::size_t>(msg.getEncodedSize()));
    if (msg.encode(buf.data(), 0, static_cast<int>(buf.size())) != static_cast<int>(buf.size()))
      throw std::runtime_error(path_ + ": cannot encode a message for channel " + channel);
    write_raw(channel, utime, buf);
  }
  /// Appends one already-encoded payload.
  void write_raw(const std::string& channel, int64_t utime, const std::vector<uint8_t>& payload);
  /// Flushes and closes; throws if the data could not be written. Called by the destructor too.
  void close();
  int64_t events_written() const { return events_; }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::unique_ptr<lcm::LogFile> log_;
  int64_t events_ = 0;
};

class LcmLogReader {
 public:
  /// Opens `path` for reading. Throws if it cannot be opened.
  explicit LcmLogReader(const std::string& path);
  ~LcmLogReader();
  LcmLogReader(const LcmLogReader&) = delete;
  LcmLogReader& operator=(const LcmLogReader&) = delete;

  /// Reads the next event. Returns false at a clean end of file; throws on a truncated or
  /// corrupt event (message names the file, event index and byte offset).
  bool next(LogRecord& out);

  /// Decodes a record as `Msg`; throws naming the file, event and channel if it is not one.
  /// Length fields are checked before anything is allocated (pipeline/wire_decode.hpp).
  template <typename Msg>
  Msg decode(const LogRecord& r) const {
    return decode_payload<Msg>(r.data, where(r));
  }

  /// "event #N (byte B, channel C)" for error messages.
  static std::string event_name(const LogRecord& r);
  /// "file: event #N (byte B, channel C)".
  std::string where(const LogRecord& r) const { return path_ + ": " + event_name(r); }
  const std::string& path() const { return path_; }
  int64_t file_size() const { return size_; }
  int64_t position() const { return pos_; }

 private:
  std::string path_;
  std::FILE* fp_ = nullptr;
  int64_t size_ = 0;
  int64_t pos_ = 0;
  int64_t index_ = 0;
};

/// The LCM type fingerprint at the start of an encoded payload (0 if too short).
int64_t payload_fingerprint(const std::vector<uint8_t>& data);

}  // namespace dynavins::pipeline
