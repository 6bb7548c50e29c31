#include "stages/tracker/kalibr_camera.hpp"

#include <vector>

#include <opencv2/core.hpp>

#include "stages/common/config_error.hpp"

namespace dynavins::tracker {

namespace {

std::vector<double> read_numbers(const cv::FileNode& node, const std::string& path, const std::string& key,
                                 std::size_t count) {
  std::vector<double> v;
  if (node.isSeq())
    for (const auto& e : node) v.push_back(static_cast<double>(e));
  if (v.size() != count) throw ConfigError(path, key, "expected " + std::to_string(count) + " numbers");
  return v;
}

}  // namespace

KalibrCamera load_kalibr_camera(const std::string& path) {
  cv::FileStorage fs;
  try {
    fs.open(path, cv::FileStorage::READ);
  } catch (const cv::Exception& e) {
    throw ConfigError(path, "", std::string("cannot parse: ") + e.what());
  }
  if (!fs.isOpened()) throw ConfigError(path, "", "cannot open");
  const std::string model = fs["camera_model"].isString() ? fs["camera_model"].string() : "";
  if (model != "pinhole") throw ConfigError(path, "camera_model", "only 'pinhole' is supported, got '" + model + "'");
  const std::string dist = fs["distortion_model"].isString() ? fs["distortion_model"].string() : "";
  if (dist != "radial-tangential")
    throw ConfigError(path, "distortion_model", "only 'radial-tangential' is supported, got '" + dist + "'");
  const auto res = read_numbers(fs["resolution"], path, "resolution", 2);
  const auto k = read_numbers(fs["intrinsics"], path, "intrinsics", 4);
  const auto d = read_numbers(fs["distortion_coefficients"], path, "distortion_coefficients", 4);
  const auto T = read_numbers(fs["T_BS"]["data"], path, "T_BS", 16);

  PinholeRadtanCamera::Params p;
  p.width = static_cast<int>(res[0]);
  p.height = static_cast<int>(res[1]);
  p.fx = k[0];
  p.fy = k[1];
  p.cx = k[2];
  p.cy = k[3];
  p.distortion = RadtanDistortion{d[0], d[1], d[2], d[3]};
  KalibrCamera out;
  try {
    out.camera = std::make_shared<const PinholeRadtanCamera>(p);
  } catch (const std::invalid_argument& e) {
    throw ConfigError(path, "intrinsics", e.what());
  }
  Eigen::Matrix4d M;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) M(r, c) = T[4 * r + c];
  out.T_body_cam.matrix() = M;
  return out;
}

}  // namespace dynavins::tracker
