#include "stages/common/config_reader.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

#include <opencv2/core.hpp>

namespace dynavins {
namespace {

std::string type_name(const cv::FileNode& n) {
  if (n.isInt()) return "an integer";
  if (n.isReal()) return "a real number";
  if (n.isString()) return "the string \"" + n.string() + "\"";
  if (n.isMap()) return "a map";
  if (n.isSeq()) return "a sequence";
  return "an empty value";
}

// OpenCV keeps "true # comment" as the whole scalar; keep the first word only.
std::string first_word(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return {};
  const auto e = s.find_first_of(" \t#", b);
  return s.substr(b, e == std::string::npos ? std::string::npos : e - b);
}

// OpenCV 4.6's yaml parser never returns from some files with junk after a "---" document marker (found
// by fuzz_camera: "%YAML:1.0\n---k%YAML:1.0\n--d-\n" and "%YAML:1.0\n---*m%Y]AML:1.0\n--\n-mo\n" loop
// forever inside FileStorage::open). A VINS-Fusion / OpenCV config has its %YAML directive at the start of
// the first line and "---" alone on its line, so anything else there is refused before the parser sees
// it. Returns what is wrong, with its 1-based line, or an empty string.
std::string parser_trap(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    const auto at = line.find("%YAML");
    if (at != std::string::npos && (n > 1 || at > 0))
      return "line " + std::to_string(n) + ": a %YAML directive belongs at the start of the first line only";
    // An empty key ("   : camera"): OpenCV read out of bounds on it (found by fuzz_camera: std::length_error
    // in a Release build, SEGV inside OpenCV under ThreadSanitizer).
    const auto first = line.find_first_not_of(" \t");
    if (first != std::string::npos && line[first] == ':')
      return "line " + std::to_string(n) + ": a key is missing before ':'";
    if (line.rfind("---", 0) == 0) {
      const auto rest = line.find_first_not_of(" \t\r", 3);
      if (rest != std::string::npos && line[rest] != '#')
        return "line " + std::to_string(n) + ": the document marker --- must stand alone on its line";
    }
  }
  return {};
}

}  // namespace

ConfigReader::ConfigReader(const std::string& path) : path_(path) {
  if (!std::filesystem::is_regular_file(path)) throw ConfigError(path, "", "file not found");
  if (const std::string trap = parser_trap(path); !trap.empty()) throw ConfigError(path, "", trap);
  try {
    fs_.open(path, cv::FileStorage::READ);
  } catch (const cv::Exception& e) {
    // e.err is OpenCV's own short description (e.msg adds its source file and function).
    throw ConfigError(path, "", "not a valid OpenCV yaml file (" + e.err + "); a VINS-Fusion config starts with %YAML:1.0");
  } catch (const std::exception& e) {
    // OpenCV's parser also lets standard exceptions out on some malformed files (found by fuzz_camera:
    // std::length_error from basic_string); they are the same bad file.
    throw ConfigError(path, "", std::string("not a valid OpenCV yaml file (its parser failed: ") + e.what() +
                                    "); a VINS-Fusion config starts with %YAML:1.0");
  }
  if (!fs_.isOpened()) throw ConfigError(path, "", "cannot open as an OpenCV yaml file");
  // OpenCV's map keeps every entry while fs_[key] finds the first, so a repeat is seen here.
  const cv::FileNode root = fs_.root();
  // A sequence or a scalar at the top (found by fuzz_camera): OpenCV asserts on any key lookup in it.
  if (root.isSeq() || root.isString() || root.isInt() || root.isReal())
    throw ConfigError(path, "", "the top level is " + type_name(root) + ", not a map of keys");
  if (!root.isMap()) return;  // empty: every key is missing
  std::set<std::string> seen;
  for (auto it = root.begin(); it != root.end(); ++it) {
    const std::string key = (*it).name();
    if (!seen.insert(key).second) fail(key, "appears more than once in the file (remove one of them)");
    keys_.push_back(key);
  }
}

void ConfigReader::fail(const std::string& key, const std::string& problem) const {
  throw ConfigError(path_, key, problem);
}

cv::FileNode ConfigReader::node(const std::string& key) const {
  return fs_.root().isMap() ? fs_[key] : cv::FileNode();  // OpenCV asserts on a lookup in a non-map
}

bool ConfigReader::has(const std::string& key) const {
  const cv::FileNode n = node(key);
  return !n.empty() && !n.isNone();
}

std::optional<int> ConfigReader::find_int(const std::string& key) const {
  if (!has(key)) return std::nullopt;
  const cv::FileNode n = node(key);
  if (n.isInt()) return static_cast<int>(n);
  if (n.isReal()) {
    const double v = static_cast<double>(n);
    if (v == std::round(v) && std::abs(v) < 2e9) return static_cast<int>(v);
  }
  fail(key, "expected an integer, found " + type_name(n));
}

std::optional<double> ConfigReader::find_double(const std::string& key) const {
  if (!has(key)) return std::nullopt;
  const cv::FileNode n = node(key);
  if (n.isInt()) return static_cast<double>(n);
  if (n.isReal()) {
    const double v = static_cast<double>(n);
    if (!std::isfinite(v)) fail(key, "expected a finite number, found " + std::to_string(v));
    return v;
  }
  fail(key, "expected a number, found " + type_name(n));
}

std::optional<bool> ConfigReader::find_bool(const std::string& key) const {
  if (!has(key)) return std::nullopt;
  const cv::FileNode n = node(key);
  if (n.isInt()) {
    const int v = static_cast<int>(n);
    if (v == 0 || v == 1) return v == 1;
  } else if (n.isString()) {
    const std::string w = first_word(n.string());
    if (w == "true" || w == "True" || w == "TRUE") return true;
    if (w == "false" || w == "False" || w == "FALSE") return false;
  }
  fail(key, "expected 0/1 or true/false, found " + type_name(n));
}

int ConfigReader::get_int(const std::string& key) const {
  if (auto v = find_int(key)) return *v;
  fail(key, "required key is missing");
}

double ConfigReader::get_double(const std::string& key) const {
  if (auto v = find_double(key)) return *v;
  fail(key, "required key is missing");
}

bool ConfigReader::get_bool(const std::string& key) const {
  if (auto v = find_bool(key)) return *v;
  fail(key, "required key is missing");
}

std::string ConfigReader::get_string(const std::string& key) const {
  if (!has(key)) fail(key, "required key is missing");
  const cv::FileNode n = node(key);
  if (!n.isString()) fail(key, "expected a string, found " + type_name(n));
  return n.string();
}

double ConfigReader::get_nested_double(const std::string& map, const std::string& key) const {
  const std::string full = map + "." + key;
  const cv::FileNode m = node(map);
  if (m.empty() || m.isNone()) fail(full, "required key is missing (no '" + map + "' section)");
  if (!m.isMap()) fail(map, "expected a map, found " + type_name(m));
  const cv::FileNode n = m[key];
  if (n.empty() || n.isNone()) fail(full, "required key is missing");
  if (!n.isInt() && !n.isReal()) fail(full, "expected a number, found " + type_name(n));
  if (!std::isfinite(static_cast<double>(n))) fail(full, "expected a finite number");
  return static_cast<double>(n);
}

Eigen::Isometry3d ConfigReader::get_transform(const std::string& key) const {
  if (!has(key)) fail(key, "required key is missing");
  const cv::FileNode n = node(key);
  if (!n.isMap()) fail(key, "expected a 4x4 !!opencv-matrix, found " + type_name(n));
  // rows, cols and the data's length checked before OpenCV reads the matrix: it allocates rows x cols
  // as written (a garbled `rows` made it ask for 64 GB, found by fuzz_config).
  for (const char* dim : {"rows", "cols"})
    if (!n[dim].isInt() || static_cast<int>(n[dim]) != 4)
      fail(key, std::string("expected a 4x4 !!opencv-matrix, found ") + dim + ": " +
                    (n[dim].isInt() ? std::to_string(static_cast<int>(n[dim])) : type_name(n[dim])));
  if (!n["data"].isSeq() || n["data"].size() != 16)
    fail(key, "expected a 4x4 !!opencv-matrix: data must be a sequence of 16 numbers");
  cv::Mat m;
  try {
    n >> m;
  } catch (const cv::Exception& e) {
    fail(key, "not a valid !!opencv-matrix: " + e.msg);
  }
  if (m.rows != 4 || m.cols != 4 || m.channels() != 1)
    fail(key, "expected a 4x4 matrix, found " + std::to_string(m.rows) + "x" + std::to_string(m.cols));
  m.convertTo(m, CV_64F);
  Eigen::Matrix4d T;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) T(r, c) = m.at<double>(r, c);
  if (!T.allFinite()) fail(key, "matrix has non-finite entries");
  if ((T.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() > 1e-9) fail(key, "last row must be [0, 0, 0, 1]");
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > 1e-3 || R.determinant() < 0)
    fail(key, "top-left 3x3 block is not a rotation");
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = Eigen::Quaterniond(R).normalized().toRotationMatrix();
  out.translation() = T.topRightCorner<3, 1>();
  return out;
}

}  // namespace dynavins
