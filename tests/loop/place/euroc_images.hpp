#pragma once
// Fixture: cam0/cam1 images of the real EuRoC clip in ../shared (V1_01_easy, first 4.7 s, 95 frames, the drone
// standing still), loaded gray by index.
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

namespace dynavins::loop::test {

inline std::string euroc_cam_dir(int cam) {
  return std::string(DYNAVINS_SHARED_DIR) + "/data/euroc_v1_01_micro/mav0/cam" + std::to_string(cam);
}

/// File names of camera `cam`'s frames in time order (data.csv).
inline std::vector<std::string> euroc_cam_files(int cam) {
  std::ifstream csv(euroc_cam_dir(cam) + "/data.csv");
  if (!csv) throw std::runtime_error("cannot open " + euroc_cam_dir(cam) + "/data.csv");
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

/// Frame `index` of camera `cam` (0 or 1), 8-bit gray.
inline cv::Mat euroc_image(int cam, int index) {
  const std::vector<std::string> files = euroc_cam_files(cam);
  const std::string path = euroc_cam_dir(cam) + "/data/" + files.at(index);
  cv::Mat img = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (img.empty()) throw std::runtime_error("cannot read " + path);
  return img;
}

inline cv::Mat euroc_cam0_image(int index) { return euroc_image(0, index); }

}  // namespace dynavins::loop::test
