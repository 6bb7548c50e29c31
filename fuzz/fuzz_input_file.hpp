#pragma once
// The readers under fuzz take a path, so a harness writes its input to a file first: one file per
// process and name, under $TMPDIR (/tmp), rewritten for each input.

#include <cstddef>
#include <cstdint>
#include <string>

namespace dynavins::fuzz {

/// A folder of this process for fuzz inputs (created on first use, when logging is also switched off).
const std::string& fuzz_scratch_dir();

/// Writes `size` bytes at `data` to fuzz_scratch_dir()/`name` and returns that path.
std::string write_fuzz_file(const std::string& name, const uint8_t* data, std::size_t size);

}  // namespace dynavins::fuzz
