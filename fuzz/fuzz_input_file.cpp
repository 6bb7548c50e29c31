#include "fuzz/fuzz_input_file.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>

#include <spdlog/spdlog.h>
#include <unistd.h>

namespace dynavins::fuzz {

const std::string& fuzz_scratch_dir() {
  static const std::string kDir = [] {
    // The readers warn about what they skip; at thousands of inputs a second that is only noise.
    spdlog::set_level(spdlog::level::off);
    const char* tmp = std::getenv("TMPDIR");
    const std::filesystem::path d =
        std::filesystem::path(tmp && *tmp ? tmp : "/tmp") / ("dynavins-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d.string();
  }();
  return kDir;
}

std::string write_fuzz_file(const std::string& name, const uint8_t* data, std::size_t size) {
  const std::string path = fuzz_scratch_dir() + "/" + name;
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  std::FILE* f = std::fopen(path.c_str(), "wb");
  // The harness's own failure, not the reader's: abort so it cannot pass for a clean run.
  if (!f) std::abort();
  if (size > 0 && std::fwrite(data, 1, size, f) != size) std::abort();
  if (std::fclose(f) != 0) std::abort();
  return path;
}

}  // namespace dynavins::fuzz
