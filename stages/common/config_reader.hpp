#pragma once
// Typed access to one OpenCV FileStorage yaml (the format VINS-Fusion and camodocs use), with the
// quirks of real files tolerated: reals written for ints when integral, 0/1 or true/false flags,
// OpenCV keeping a trailing "# comment" inside unquoted strings. Every failure is a ConfigError.
// A top-level key written twice is an error (OpenCV would keep the first value silently), and so is a
// non-finite number (.nan, .inf).

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core/persistence.hpp>

#include "stages/common/config_error.hpp"

namespace dynavins {

class ConfigReader {
 public:
  /// Opens `path`; throws ConfigError naming the file if it is missing, not valid yaml, or repeats a
  /// top-level key (naming the key).
  explicit ConfigReader(const std::string& path);

  const std::string& path() const { return path_; }
  /// The file's top-level keys in file order.
  const std::vector<std::string>& keys() const { return keys_; }
  bool has(const std::string& key) const;

  /// Required values: throw ConfigError naming key and file when absent or of the wrong type.
  int get_int(const std::string& key) const;
  double get_double(const std::string& key) const;
  bool get_bool(const std::string& key) const;
  std::string get_string(const std::string& key) const;
  /// A 4x4 !!opencv-matrix rigid transform; the rotation is re-orthonormalized (files carry ~1e-6 errors).
  Eigen::Isometry3d get_transform(const std::string& key) const;

  /// Optional values: nullopt when absent, ConfigError when present but wrongly typed.
  std::optional<int> find_int(const std::string& key) const;
  std::optional<double> find_double(const std::string& key) const;
  std::optional<bool> find_bool(const std::string& key) const;

  /// Value of a sub-map entry such as distortion_parameters.k1 (camodocs files nest their numbers).
  double get_nested_double(const std::string& map, const std::string& key) const;

  /// Throws ConfigError for `key` with `problem`.
  [[noreturn]] void fail(const std::string& key, const std::string& problem) const;

 private:
  cv::FileNode node(const std::string& key) const;
  std::string path_;
  cv::FileStorage fs_;
  std::vector<std::string> keys_;
};

}  // namespace dynavins
