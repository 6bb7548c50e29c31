#pragma once
// The one error type of the sensor-data readers: what() reads "<file>:<line>: <problem>", or
// "<file>: <problem>" when no line applies, so every bad input names where it is.

#include <cstddef>
#include <stdexcept>
#include <string>

namespace dynavins::io {

class InputError : public std::runtime_error {
 public:
  InputError(const std::string& file, std::size_t line, const std::string& problem)
      : std::runtime_error(file + (line ? ":" + std::to_string(line) : std::string()) + ": " + problem),
        file_(file),
        line_(line) {}
  const std::string& file() const { return file_; }
  std::size_t line() const { return line_; }  ///< 1-based; 0 when no line applies

 private:
  std::string file_;
  std::size_t line_;
};

}  // namespace dynavins::io
