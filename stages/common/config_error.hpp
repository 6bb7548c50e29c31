#pragma once
// The one error type of configuration loading: what() reads "<file>: <key>: <problem>" so a user
// sees at once which file and which key to fix.

#include <stdexcept>
#include <string>

namespace dynavins {

class ConfigError : public std::runtime_error {
 public:
  ConfigError(const std::string& file, const std::string& key, const std::string& problem)
      : std::runtime_error(file + ": " + (key.empty() ? std::string() : "key '" + key + "': ") + problem),
        file_(file),
        key_(key) {}
  const std::string& file() const { return file_; }
  const std::string& key() const { return key_; }  ///< empty when the whole file is at fault

 private:
  std::string file_;
  std::string key_;
};

}  // namespace dynavins
