// ORB on the keyframe's points (see keyframe_descriptors.hpp).
#include "stages/loop/place/keyframe_descriptors.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "stages/loop/place/hamming.hpp"

namespace dynavins::loop {

std::size_t KeyframeDescriptors::memory_bytes() const {
  return sizeof(*this) + points.capacity() * sizeof(KeyframePoint) + descriptors.total() * descriptors.elemSize();
}

KeyframeDescriptors compute_keyframe_descriptors(const Keyframe& kf, const DescriptorOptions& opts,
                                                 const Undistort& undistort) {
  if (kf.image.empty() || kf.image.type() != CV_8UC1)
    throw std::invalid_argument("compute_keyframe_descriptors: keyframe image must be non-empty 8-bit gray");
  const cv::Mat& img = kf.image;
  const int border = opts.border_px;
  auto inside = [&](const Eigen::Vector2d& px) {
    return px.x() >= border && px.y() >= border && px.x() < img.cols - border && px.y() < img.rows - border;
  };

  // Candidate points: the tracked ones inside the border first, then extra corners away from them.
  std::vector<KeyframePoint> candidates;
  candidates.reserve(opts.max_points);
  for (const KeyframePoint& p : kf.points) {
    if (static_cast<int>(candidates.size()) >= opts.max_points) break;
    if (inside(p.px)) candidates.push_back(p);
  }
  const int extra = opts.max_points - static_cast<int>(candidates.size());
  if (extra > 0 && img.cols > 2 * border && img.rows > 2 * border) {
    cv::Mat mask(img.size(), CV_8UC1, cv::Scalar(0));
    mask(cv::Rect(border, border, img.cols - 2 * border, img.rows - 2 * border)).setTo(255);
    const int r = static_cast<int>(std::lround(opts.corner_min_distance_px));
    for (const KeyframePoint& p : candidates)
      cv::circle(mask, cv::Point(static_cast<int>(std::lround(p.px.x())), static_cast<int>(std::lround(p.px.y()))), r,
                 cv::Scalar(0), cv::FILLED);
    std::vector<cv::Point2f> corners;
    cv::goodFeaturesToTrack(img, corners, extra, opts.corner_quality, opts.corner_min_distance_px, mask);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (const cv::Point2f& c : corners) {
      KeyframePoint p;
      p.px = Eigen::Vector2d(c.x, c.y);
      p.xy = undistort ? undistort(p.px) : Eigen::Vector2d(nan, nan);
      candidates.push_back(p);
    }
  }

  // Upright ORB (angle 0) at full resolution; class_id carries the candidate index through ORB's filtering.
  std::vector<cv::KeyPoint> keypoints;
  keypoints.reserve(candidates.size());
  for (std::size_t i = 0; i < candidates.size(); ++i)
    keypoints.emplace_back(
        cv::Point2f(static_cast<float>(candidates[i].px.x()), static_cast<float>(candidates[i].px.y())), 31.f, 0.f, 0.f,
        0, static_cast<int>(i));
  cv::Mat desc;
  if (!keypoints.empty()) {
    cv::Ptr<cv::ORB> orb = cv::ORB::create(opts.max_points, 1.2f, 1, 31, 0, 2, cv::ORB::HARRIS_SCORE, 31);
    orb->compute(img, keypoints, desc);
  }

  KeyframeDescriptors out;
  out.t_ns = kf.t_ns;
  out.seq = kf.seq;
  out.p_wb = kf.p_wb;
  out.q_wb = kf.q_wb;
  out.p_bc = kf.p_bc;
  out.q_bc = kf.q_bc;
  out.points.reserve(keypoints.size());
  for (const cv::KeyPoint& k : keypoints) out.points.push_back(candidates[k.class_id]);
  out.descriptors = desc.empty() ? cv::Mat(0, kDescriptorBytes, CV_8UC1) : desc;
  return out;
}

}  // namespace dynavins::loop
