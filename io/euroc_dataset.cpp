#include "io/euroc_dataset.hpp"

#include <filesystem>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <spdlog/spdlog.h>

#include "io/csv_table.hpp"
#include "io/input_error.hpp"

namespace dynavins::io {
namespace fs = std::filesystem;
namespace {

struct ImageEntry {
  int64_t t_ns;
  std::string path;
};

/// Throws unless `t` comes strictly after the previous timestamp of the same file.
void check_increasing(int64_t t, int64_t& last, const std::string& file, std::size_t line) {
  if (t <= last)
    throw InputError(file, line, t == last ? "duplicate timestamp " + std::to_string(t)
                                           : "timestamp " + std::to_string(t) + " goes back in time");
  last = t;
}

/// Reads a camera's data.csv. Rows whose image file is absent are skipped and added to `missing`
/// (real EuRoC extracts list images that were not shipped), with a warning naming this camera's first
/// and a count of this camera's own.
std::vector<ImageEntry> read_camera(const fs::path& cam_dir, std::size_t& missing_total) {
  const std::string csv = (cam_dir / "data.csv").string();
  std::vector<ImageEntry> out;
  std::size_t missing = 0;
  int64_t last = INT64_MIN;
  for (const auto& row : read_csv(csv, 2)) {
    const int64_t t = parse_int64(row.fields[0], csv, row.line, "timestamp");
    check_increasing(t, last, csv, row.line);
    const fs::path image = cam_dir / "data" / row.fields[1];
    if (!fs::is_regular_file(image)) {
      if (missing++ == 0) spdlog::warn("{}:{}: image {} does not exist; skipped", csv, row.line, image.string());
      continue;
    }
    out.push_back({t, image.string()});
  }
  if (missing > 1) spdlog::warn("{}: {} listed images do not exist; skipped", csv, missing);
  missing_total += missing;
  if (out.empty()) throw InputError(csv, 0, "lists no image that exists");
  return out;
}

std::vector<ImuSample> read_imu(const fs::path& imu_dir) {
  const std::string csv = (imu_dir / "data.csv").string();
  std::vector<ImuSample> out;
  int64_t last = INT64_MIN;
  for (const auto& row : read_csv(csv, 7)) {
    ImuSample s;
    s.t_ns = parse_int64(row.fields[0], csv, row.line, "timestamp");
    check_increasing(s.t_ns, last, csv, row.line);
    // EuRoC column order: angular rate first, then linear acceleration.
    for (int i = 0; i < 3; ++i) {
      s.gyr[i] = parse_double(row.fields[1 + i], csv, row.line, "w_RS_S");
      s.acc[i] = parse_double(row.fields[4 + i], csv, row.line, "a_RS_S");
    }
    out.push_back(s);
  }
  if (out.empty()) throw InputError(csv, 0, "holds no IMU samples");
  return out;
}

/// Ground truth: EuRoC's state_groundtruth_estimate0 (timestamp, p_RS_R xyz, q_RS wxyz, v_RS_R xyz, b_w xyz,
/// b_a xyz) or, `pose_only`, TUM-VI's mocap0 in EuRoC's layout (timestamp, p_RS_R xyz, q_RS wxyz; the IMU's pose).
std::vector<GroundTruthState> read_ground_truth(const fs::path& dir, bool pose_only) {
  const std::string csv = (dir / "data.csv").string();
  const int values = pose_only ? 7 : 16;
  std::vector<GroundTruthState> out;
  int64_t last = INT64_MIN;
  for (const auto& row : read_csv(csv, values + 1)) {
    double v[16];
    for (int i = 0; i < values; ++i) v[i] = parse_double(row.fields[1 + i], csv, row.line, "state value");
    GroundTruthState gt;
    gt.t_ns = parse_int64(row.fields[0], csv, row.line, "timestamp");
    check_increasing(gt.t_ns, last, csv, row.line);
    gt.p_wb = {v[0], v[1], v[2]};
    gt.q_wb = Eigen::Quaterniond(v[3], v[4], v[5], v[6]);
    if (std::abs(gt.q_wb.norm() - 1.0) > 1e-3) throw InputError(csv, row.line, "q_RS is not a unit quaternion");
    gt.q_wb.normalize();
    if (!pose_only) {
      gt.v_wb = {v[7], v[8], v[9]};
      gt.bias_gyr = {v[10], v[11], v[12]};
      gt.bias_acc = {v[13], v[14], v[15]};
      gt.has_velocity = gt.has_biases = true;
    }
    out.push_back(gt);
  }
  return out;
}

cv::Mat read_gray(const std::string& path) {
  cv::Mat img = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (img.empty()) throw InputError(path, 0, "cannot read the image (missing, unreadable or not an image)");
  if (img.depth() != CV_8U) throw InputError(path, 0, "is not an 8-bit image");
  if (img.channels() == 3) cv::cvtColor(img, img, cv::COLOR_BGR2GRAY);
  else if (img.channels() == 4) cv::cvtColor(img, img, cv::COLOR_BGRA2GRAY);
  return img;
}

}  // namespace

EurocDataset::EurocDataset(const std::string& dir, int64_t stereo_tolerance_ns) {
  fs::path root(dir);
  if (fs::is_directory(root / "mav0")) root /= "mav0";
  if (!fs::is_directory(root / "cam0"))
    throw InputError(dir, 0, "is not an EuRoC ASL folder (no mav0/cam0 inside)");
  if (!fs::is_directory(root / "imu0")) throw InputError(dir, 0, "has no mav0/imu0 folder (IMU data)");
  mav0_ = root.string();

  const auto left = read_camera(root / "cam0", missing_images_);
  imu_ = read_imu(root / "imu0");
  // EuRoC ships the folder with only sensor.yaml for some clips: ground truth only if data.csv exists.
  if (fs::is_regular_file(root / "state_groundtruth_estimate0" / "data.csv"))
    ground_truth_ = read_ground_truth(root / "state_groundtruth_estimate0", false);
  else if (fs::is_regular_file(root / "mocap0" / "data.csv"))
    ground_truth_ = read_ground_truth(root / "mocap0", true);
  const fs::path labels_dir = root / "cam0" / "labels";
  const bool has_labels = fs::is_directory(labels_dir);
  auto labels_of = [&](const std::string& image) {
    return has_labels ? (labels_dir / fs::path(image).filename()).string() : std::string();
  };

  stereo_ = fs::is_directory(root / "cam1");
  if (!stereo_) {
    for (const auto& l : left) frames_.push_back({l.t_ns, l.path, {}, labels_of(l.path)});
    return;
  }
  // Both lists are sorted: walk them together, pairing stamps within the tolerance.
  const auto right = read_camera(root / "cam1", missing_images_);
  std::size_t j = 0;
  for (const auto& l : left) {
    while (j < right.size() && right[j].t_ns < l.t_ns - stereo_tolerance_ns) ++j, ++unmatched_right_;
    if (j < right.size() && std::abs(right[j].t_ns - l.t_ns) <= stereo_tolerance_ns) {
      frames_.push_back({l.t_ns, l.path, right[j].path, labels_of(l.path)});
      ++j;
    } else {
      ++unmatched_left_;
    }
  }
  unmatched_right_ += right.size() - j;
  if (unmatched_left_ || unmatched_right_)
    spdlog::warn("{}: {} left and {} right images have no stereo partner within {:.1f} ms; they are not used",
                 mav0_, unmatched_left_, unmatched_right_, stereo_tolerance_ns / 1e6);
  if (frames_.empty()) throw InputError(mav0_, 0, "no cam0/cam1 image pair matches in time");
}

StereoFrame EurocDataset::load(std::size_t i) const {
  const EurocFrame& e = frames_.at(i);
  StereoFrame f;
  f.t_ns = e.t_ns;
  f.seq = static_cast<int64_t>(i);
  f.left = read_gray(e.left);
  if (!e.right.empty()) {
    f.right = read_gray(e.right);
    if (f.right.size() != f.left.size()) throw InputError(e.right, 0, "size differs from the left image " + e.left);
  }
  if (!e.labels.empty() && fs::exists(e.labels)) f.labels = cv::imread(e.labels, cv::IMREAD_UNCHANGED);
  return f;
}

}  // namespace dynavins::io
