#pragma once
// Fixture: cam0 images of the real EuRoC clip in ../shared (V1_01_easy, first 4.7 s, 95 frames, the drone
// standing still), loaded gray by index.
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

namespace dynavins::loop::test {

inline std::string euroc_cam0_dir() { return std::string(DYNAVINS_SHARED_DIR) + "/data/euroc_v1_01_micro/mav0/cam0"; }

/// File names of cam0's frames in time order (data.csv).
inline std::vector<std::string> euroc_cam0_files() {
  std::ifstream csv(euroc_cam0_dir() + "/data.csv");
  if (!csv) throw std::runtime_error("cannot open " + euroc_cam0_dir() + "/data.csv");
  std::vector<std::string> files;
  std::string line;
  while (std::getline(csv, line)) {
    if (line.empty() || line[0] == '#') continue;
    const auto comma = line.find(',');
    std::string name = line.substr(comma + 1);
    while (!name.empty() && (name.back() == '\r' || name.back() == ' ')) name.pop_back();
    files.push_back(name);
  }
  return files;
}

inline cv::Mat euroc_cam0_image(int index) {
  static const std::vector<std::string> files = euroc_cam0_files();
  const std::string path = euroc_cam0_dir() + "/data/" + files.at(index);
  cv::Mat img = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (img.empty()) throw std::runtime_error("cannot read " + path);
  return img;
}

}  // namespace dynavins::loop::test
