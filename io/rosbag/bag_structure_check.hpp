#pragma once
// Internal to dynavins_rosbag. rosbag_storage trusts the lengths and offsets in a bag: a corrupt
// index or chunk makes it read past its buffers (a crash, not an exception). So before it sees a
// file, this walks the same records it will read, bounds-checked, and rejects what would hurt it.

#include <cstdint>
#include <string>

namespace dynavins::io::detail {

/// What the walk found, for the log.
struct BagStructure {
  uint32_t connections = 0;
  uint32_t chunks = 0;
  uint64_t index_entries = 0;
};

/// Checks `path` as a ROS bag format 2.0 file: file header, connection and chunk-info records,
/// every chunk (decompressed if bz2/lz4) and every index entry's message record. Throws
/// io::InputError naming the file and the byte offset of the first bad record.
BagStructure check_bag_structure(const std::string& path);

}  // namespace dynavins::io::detail
