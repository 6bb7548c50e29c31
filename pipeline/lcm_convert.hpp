#pragma once
// Conversions between the in-process messages (messages/) and the LCM wire types (lcm_types/).
// Time: nanoseconds inside, microseconds (utime) on the wire. Bad wire data throws
// std::runtime_error naming the field.

#include <cstdint>
#include <stdexcept>
#include <string>

#include <dynavins_lcm/ground_truth_t.hpp>
#include <dynavins_lcm/image_t.hpp>
#include <dynavins_lcm/imu_t.hpp>
#include <dynavins_lcm/loop_hypotheses_t.hpp>
#include <dynavins_lcm/path_t.hpp>
#include <dynavins_lcm/pipeline_stats_t.hpp>
#include <dynavins_lcm/pose_t.hpp>
#include <dynavins_lcm/stereo_image_t.hpp>
#include <dynavins_lcm/weighted_feature_set_t.hpp>

#include "messages/estimate_messages.hpp"
#include "messages/sensor_messages.hpp"
#include "pipeline/publish_item.hpp"

namespace dynavins::pipeline {

struct RunReport;

inline int64_t ns_to_utime(int64_t ns) { return ns >= 0 ? (ns + 500) / 1000 : -((-ns + 500) / 1000); }
/// Throws std::runtime_error for a utime beyond +-292 years, whose nanoseconds overflow int64 (corrupt
/// wire data; found by fuzz_lcm_decode and fuzz_lcm_log).
inline int64_t utime_to_ns(int64_t utime) {
  if (utime > INT64_MAX / 1000 || utime < INT64_MIN / 1000)
    throw std::runtime_error("utime " + std::to_string(utime) + " us is out of range");
  return utime * 1000;
}

enum class ImageEncoding : int8_t { Gray8 = 0, Png = 1 };

/// An 8-bit single-channel image (or an empty one) to the wire, raw or PNG-compressed.
dynavins_lcm::image_t image_to_lcm(const cv::Mat& gray, int64_t t_ns, ImageEncoding encoding);
/// Back to a CV_8UC1 image; an empty image for size 0. Throws on inconsistent size or bad PNG.
cv::Mat image_from_lcm(const dynavins_lcm::image_t& msg);

dynavins_lcm::stereo_image_t to_lcm(const StereoFrame& frame, ImageEncoding encoding);
StereoFrame from_lcm(const dynavins_lcm::stereo_image_t& msg);

dynavins_lcm::imu_t to_lcm(const ImuSample& sample);
ImuSample from_lcm(const dynavins_lcm::imu_t& msg);

dynavins_lcm::ground_truth_t to_lcm(const GroundTruthState& gt);
GroundTruthState from_lcm(const dynavins_lcm::ground_truth_t& msg);

dynavins_lcm::pose_t to_lcm(const PoseEstimate& pose);
PoseEstimate from_lcm(const dynavins_lcm::pose_t& msg);

dynavins_lcm::weighted_feature_set_t to_lcm(const WeightedFeatureSet& set);
WeightedFeatureSet from_lcm(const dynavins_lcm::weighted_feature_set_t& msg);

dynavins_lcm::path_t to_lcm(const PathUpdate& path);
dynavins_lcm::loop_hypotheses_t to_lcm(const HypothesesUpdate& update);

/// The pipeline's counters as a stats message; `sensor_s` is how much sensor time was processed.
dynavins_lcm::pipeline_stats_t to_lcm(const RunReport& report, int64_t wall_utime, double sensor_s);

}  // namespace dynavins::pipeline
