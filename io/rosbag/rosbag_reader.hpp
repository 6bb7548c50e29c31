#pragma once
// Reads ROS 1 bags (as VIODE ships them) into the in-process sensor messages, through Debian's
// rosbag_storage and roscpp serialization: no ROS master, no catkin. ROS headers stay in the .cpp.
//
// Per topic:
// - images (sensor_msgs/Image): mono8 as is; bgr8, rgb8, bgra8, rgba8 converted to gray; any other
//   encoding is an error. Left and right are paired by header stamp (|dt| <= stereo_tolerance_ns,
//   keep it below half the frame period); a frame is complete when its second image arrives and
//   has t_ns = the left stamp. Images that find no partner are counted (stats) and logged.
// - IMU (sensor_msgs/Imu): linear_acceleration -> acc, angular_velocity -> gyr; orientation ignored.
// - ground truth (nav_msgs/Odometry): pose -> p_wb, q_wb; twist -> v_wb, see TwistFrame.
// Time: int64 nanoseconds from header.stamp. Header stamps must increase strictly per topic;
// see BadStampPolicy. Two orders: next_in_bag_order() / read_all() give events in bag (receive)
// time order; next() (the SensorSource) gives them in sensor time order, undoing disorder between
// topics up to reorder_window_ns. Every error is an io::InputError (a std::runtime_error) whose
// what() starts with the file and, for a message, names the topic and its 0-based index there.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "io/sensor_source.hpp"
#include "messages/sensor_event.hpp"

namespace dynavins::io {

/// What to do with a message whose header stamp is not after the previous one on its topic.
enum class BadStampPolicy {
  Throw,         ///< default: error naming the topic and message index
  SkipAndCount,  ///< drop the message, count it in RosbagReadStats and log a warning
};

/// Which frame the Odometry twist's linear part is expressed in.
enum class TwistFrame {
  /// nav_msgs' definition: in child_frame_id (the body) when that is set and differs from
  /// header.frame_id, then rotated into the world by the pose; otherwise already in the world.
  Auto,
  Body,    ///< always body frame: v_wb = q_wb * v
  World,   ///< always world frame: v_wb = v
  Ignore,  ///< do not use the twist: has_velocity = false
};

/// Topic names (VIODE's defaults) and matching rules. An empty topic name disables that stream
/// (no right topic: mono, StereoFrame::right stays empty); the left image topic is required.
struct RosbagReaderOptions {
  std::string left_topic = "/cam0/image_raw";
  std::string right_topic = "/cam1/image_raw";
  std::string imu_topic = "/imu0";
  std::string odometry_topic = "/odometry";
  int64_t stereo_tolerance_ns = 1'000'000;  ///< 0 demands identical left/right stamps
  /// Images held per side while waiting for their partner; the oldest beyond it count as unmatched.
  std::size_t max_pending_images = 64;
  BadStampPolicy bad_stamp = BadStampPolicy::Throw;
  TwistFrame twist_frame = TwistFrame::Auto;
  /// next() only: how far an event's stamp may lag newer events of other topics in the bag.
  int64_t reorder_window_ns = 200'000'000;
};

/// Counts of what was read so far.
struct RosbagReadStats {
  int64_t left_images = 0;   ///< accepted left images
  int64_t right_images = 0;  ///< accepted right images
  int64_t stereo_frames = 0;
  int64_t unmatched_left = 0;  ///< left images that found no right partner (0 in mono mode)
  int64_t unmatched_right = 0;
  int64_t imu_samples = 0;
  int64_t ground_truth_states = 0;
  int64_t skipped_bad_stamps = 0;  ///< only with BadStampPolicy::SkipAndCount

  /// One line for logs and the convert command.
  std::string summary() const;
};

/// One topic of the bag, for diagnostics.
struct RosbagTopicInfo {
  std::string topic;
  std::string datatype;
  int64_t messages = 0;
};

/// Callbacks for RosbagReader::read_all; an empty one drops that kind of message.
struct RosbagCallbacks {
  std::function<void(StereoFrame&&)> on_frame;
  std::function<void(ImuSample&&)> on_imu;
  std::function<void(GroundTruthState&&)> on_ground_truth;
};

/// A ROS 1 bag as a sensor source. Use either next() or next_in_bag_order()/read_all() on one
/// reader, not both. After any error, every further read throws that error again.
class RosbagReader final : public SensorSource {
 public:
  /// Opens `path` and checks that every configured topic exists with the expected type;
  /// throws InputError naming the file (and the topic and both types on a mismatch).
  explicit RosbagReader(const std::string& path, RosbagReaderOptions options = {});
  ~RosbagReader() override;
  RosbagReader(const RosbagReader&) = delete;
  RosbagReader& operator=(const RosbagReader&) = delete;

  /// Next event in sensor time order (ties keep bag order); false at the end.
  bool next(SensorEvent& out) override;
  /// Fraction of the selected topics' messages consumed.
  double progress() const override;
  /// The file and the topics read, for logs.
  std::string describe() const override;

  /// Next event in bag time order, or nullopt at the end (the stats are then final and logged).
  std::optional<SensorEvent> next_in_bag_order();
  /// Reads every remaining message in bag time order into the callbacks; returns the final stats.
  RosbagReadStats read_all(const RosbagCallbacks& callbacks);

  /// Counts so far (final once the end has been reached).
  const RosbagReadStats& stats() const;
  /// Every topic in the bag with its type and message count.
  const std::vector<RosbagTopicInfo>& topics() const;
  const std::string& path() const;
  const RosbagReaderOptions& options() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dynavins::io
