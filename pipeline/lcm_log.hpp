#pragma once
// LCM event logs (the `lcm-logger` format) as the project's recorded-sensor-log format.
// Writing goes through LCM's own LogFile, so every log is what lcm-logplayer and lcm-spy read.
// Reading is our own small parser of that format (sync word, event number, timestamp, channel,
// payload; big-endian), because LCM's reader cannot tell a truncated log from its end: here a
// truncated or corrupt log is an error naming the file, the event index and the byte offset.
//
// Checksums: the format has none, so a log whose payload bytes were overwritten (raw gray8 pixels
// keep every length intact) read as valid. LcmLogWriter therefore closes each block of events (at most
// kChecksumBlockEvents events or kChecksumBlockBytes payload bytes, and at close) with one event on
// kChecksumChannel: the block's first byte offset, its event count and the CRC-32 of its channels and
// payloads. LcmLogReader checks each block and throws naming the block's events and bytes on a
// mismatch; checksum events are consumed there, never returned. A log without them (lcm-logger
// recordings) reads as before, unverified (checksum_stats() says so). A checksum event whose block
// does not line up with what the reader saw (a log re-recorded by lcm-logger from lcm-logplayer,
// other channels interleaved) cannot be checked and is counted as foreign, not as an error.

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

/// The channel of the checksum events (lcm-logplayer publishes it like any channel; nothing subscribes).
inline constexpr const char* kChecksumChannel = "DYNAVINS_LOG_CHECKSUM";
inline constexpr int64_t kChecksumBlockEvents = 256;
inline constexpr int64_t kChecksumBlockBytes = 4 << 20;

/// What LcmLogReader's checksum check saw so far.
struct LogChecksumStats {
  int64_t blocks_verified = 0;     ///< blocks whose CRC matched
  int64_t events_verified = 0;     ///< data events inside those blocks
  int64_t foreign_checksums = 0;   ///< checksum events that did not line up with the events read (not checked)
  int64_t events_unverified = 0;   ///< data events read after the last verified block (all of them in a log without checksums)
};

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
  /// Writes the checksum event of the open block, if it has any events.
  void close_block();
  void write_event(const std::string& channel, int64_t utime, const uint8_t* data, std::size_t size);

  std::string path_;
  std::unique_ptr<lcm::LogFile> log_;
  int64_t events_ = 0;
  int64_t offset_ = 0;  ///< bytes written so far
  int64_t last_utime_ = 0;
  // The open checksum block.
  int64_t block_offset_ = 0;
  int64_t block_events_ = 0;
  int64_t block_bytes_ = 0;
  uint32_t block_crc_ = 0;
};

class LcmLogReader {
 public:
  /// Opens `path` for reading. Throws if it cannot be opened.
  explicit LcmLogReader(const std::string& path);
  ~LcmLogReader();
  LcmLogReader(const LcmLogReader&) = delete;
  LcmLogReader& operator=(const LcmLogReader&) = delete;

  /// Reads the next data event. Returns false at a clean end of file; throws on a truncated or
  /// corrupt event (message names the file, event index and byte offset), or on a checksum block
  /// that does not match its events (naming the block's first and last event and their bytes).
  bool next(LogRecord& out);
  const LogChecksumStats& checksum_stats() const { return checksums_; }

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
  /// Reads one event of any channel.
  bool next_event(LogRecord& out);
  /// Checks the block a checksum event `r` closes.
  void check_block(const LogRecord& r);
  LogChecksumStats checksums_;
  // The block being read: since the previous checksum event.
  int64_t block_offset_ = 0;
  int64_t block_first_index_ = 0;
  int64_t block_events_ = 0;
  uint32_t block_crc_ = 0;
};

/// The LCM type fingerprint at the start of an encoded payload (0 if too short).
int64_t payload_fingerprint(const std::vector<uint8_t>& data);

}  // namespace dynavins::pipeline
