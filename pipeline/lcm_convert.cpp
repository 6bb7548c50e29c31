#include "pipeline/lcm_convert.hpp"

#include <stdexcept>
#include <string>

#include <opencv2/imgcodecs.hpp>

#include "pipeline/pipeline.hpp"

namespace dynavins::pipeline {
namespace {

void put3(double* dst, const Eigen::Vector3d& v) {
  for (int i = 0; i < 3; ++i) dst[i] = v[i];
}
Eigen::Vector3d get3(const double* src) { return {src[0], src[1], src[2]}; }
void put_quat(double* dst, const Eigen::Quaterniond& q) {
  dst[0] = q.w(), dst[1] = q.x(), dst[2] = q.y(), dst[3] = q.z();
}
Eigen::Quaterniond get_quat(const double* src, const char* type) {
  Eigen::Quaterniond q(src[0], src[1], src[2], src[3]);
  const double n = q.norm();
  if (!(n > 0.5 && n < 1.5)) throw std::runtime_error(std::string(type) + ".orientation is not a unit quaternion");
  return q.normalized();
}

}  // namespace

dynavins_lcm::image_t image_to_lcm(const cv::Mat& gray, int64_t t_ns, ImageEncoding encoding) {
  dynavins_lcm::image_t msg;
  msg.utime = ns_to_utime(t_ns);
  msg.width = gray.cols;
  msg.height = gray.rows;
  msg.encoding = static_cast<int8_t>(encoding);
  if (gray.empty()) {
    msg.size = 0;
    return msg;
  }
  if (gray.type() != CV_8UC1) throw std::invalid_argument("image_to_lcm: only 8-bit single-channel images");
  if (encoding == ImageEncoding::Png) {
    if (!cv::imencode(".png", gray, msg.data, {cv::IMWRITE_PNG_COMPRESSION, 1}))
      throw std::runtime_error("image_to_lcm: PNG encoding failed");
  } else {
    const cv::Mat c = gray.isContinuous() ? gray : gray.clone();
    msg.data.assign(c.data, c.data + c.total());
  }
  msg.size = static_cast<int32_t>(msg.data.size());
  return msg;
}

cv::Mat image_from_lcm(const dynavins_lcm::image_t& msg) {
  if (msg.size == 0) return {};
  if (msg.size != static_cast<int32_t>(msg.data.size()))
    throw std::runtime_error("image_t.size does not match its data");
  if (msg.encoding == dynavins_lcm::image_t::ENCODING_GRAY8) {
    // Both positive: -2 x -3 also makes 6 bytes (found by fuzz_lcm_decode: OpenCV asserted in Mat::create).
    if (msg.width <= 0 || msg.height <= 0 || static_cast<int64_t>(msg.width) * msg.height != msg.size)
      throw std::runtime_error("image_t: gray8 data of " + std::to_string(msg.size) + " bytes for " +
                               std::to_string(msg.width) + "x" + std::to_string(msg.height));
    return cv::Mat(msg.height, msg.width, CV_8UC1, const_cast<uint8_t*>(msg.data.data())).clone();
  }
  if (msg.encoding == dynavins_lcm::image_t::ENCODING_PNG) {
    cv::Mat img = cv::imdecode(msg.data, cv::IMREAD_UNCHANGED);
    if (img.empty()) throw std::runtime_error("image_t: PNG data does not decode");
    if (img.type() != CV_8UC1 || img.cols != msg.width || img.rows != msg.height)
      throw std::runtime_error("image_t: PNG is not a " + std::to_string(msg.width) + "x" +
                               std::to_string(msg.height) + " 8-bit gray image");
    return img;
  }
  throw std::runtime_error("image_t.encoding " + std::to_string(msg.encoding) + " is unknown");
}

dynavins_lcm::stereo_image_t to_lcm(const StereoFrame& frame, ImageEncoding encoding) {
  dynavins_lcm::stereo_image_t msg;
  msg.utime = ns_to_utime(frame.t_ns);
  msg.seq = frame.seq;
  msg.left = image_to_lcm(frame.left, frame.t_ns, encoding);
  msg.right = image_to_lcm(frame.right, frame.t_ns, encoding);
  return msg;
}

StereoFrame from_lcm(const dynavins_lcm::stereo_image_t& msg) {
  StereoFrame f;
  f.t_ns = utime_to_ns(msg.utime);
  f.seq = msg.seq;
  f.left = image_from_lcm(msg.left);
  f.right = image_from_lcm(msg.right);
  if (f.left.empty()) throw std::runtime_error("stereo_image_t.left is empty");
  if (!f.right.empty() && f.right.size() != f.left.size())
    throw std::runtime_error("stereo_image_t: left and right sizes differ");
  return f;
}

dynavins_lcm::imu_t to_lcm(const ImuSample& s) {
  dynavins_lcm::imu_t msg;
  msg.utime = ns_to_utime(s.t_ns);
  put3(msg.linear_acceleration, s.acc);
  put3(msg.angular_velocity, s.gyr);
  return msg;
}

ImuSample from_lcm(const dynavins_lcm::imu_t& msg) {
  ImuSample s;
  s.t_ns = utime_to_ns(msg.utime);
  s.acc = get3(msg.linear_acceleration);
  s.gyr = get3(msg.angular_velocity);
  if (!s.acc.allFinite() || !s.gyr.allFinite()) throw std::runtime_error("imu_t has a non-finite value");
  return s;
}

dynavins_lcm::ground_truth_t to_lcm(const GroundTruthState& gt) {
  dynavins_lcm::ground_truth_t msg;
  msg.utime = ns_to_utime(gt.t_ns);
  put3(msg.position, gt.p_wb);
  put_quat(msg.orientation, gt.q_wb);
  msg.has_velocity = gt.has_velocity;
  put3(msg.velocity, gt.v_wb);
  msg.has_biases = gt.has_biases;
  put3(msg.gyro_bias, gt.bias_gyr);
  put3(msg.accel_bias, gt.bias_acc);
  return msg;
}

GroundTruthState from_lcm(const dynavins_lcm::ground_truth_t& msg) {
  GroundTruthState gt;
  gt.t_ns = utime_to_ns(msg.utime);
  gt.p_wb = get3(msg.position);
  gt.q_wb = get_quat(msg.orientation, "ground_truth_t");
  gt.has_velocity = msg.has_velocity;
  gt.v_wb = get3(msg.velocity);
  gt.has_biases = msg.has_biases;
  gt.bias_gyr = get3(msg.gyro_bias);
  gt.bias_acc = get3(msg.accel_bias);
  return gt;
}

dynavins_lcm::pose_t to_lcm(const PoseEstimate& pose) {
  dynavins_lcm::pose_t msg;
  msg.utime = ns_to_utime(pose.state.t_ns);
  msg.source = static_cast<int8_t>(pose.source);
  put3(msg.position, pose.state.p_wb);
  put_quat(msg.orientation, pose.state.q_wb);
  put3(msg.velocity, pose.state.v_wb);
  return msg;
}

PoseEstimate from_lcm(const dynavins_lcm::pose_t& msg) {
  if (msg.source < 0 || msg.source > dynavins_lcm::pose_t::SOURCE_LOOP_CORRECTED)
    throw std::runtime_error("pose_t.source " + std::to_string(msg.source) + " is unknown");
  PoseEstimate p;
  p.source = static_cast<PoseSource>(msg.source);
  p.state.t_ns = utime_to_ns(msg.utime);
  p.state.p_wb = get3(msg.position);
  p.state.q_wb = get_quat(msg.orientation, "pose_t");
  p.state.v_wb = get3(msg.velocity);
  return p;
}

dynavins_lcm::weighted_feature_set_t to_lcm(const WeightedFeatureSet& set) {
  dynavins_lcm::weighted_feature_set_t msg;
  msg.utime = ns_to_utime(set.t_ns);
  msg.num_features = static_cast<int32_t>(set.features.size());
  msg.features.reserve(set.features.size());
  for (const auto& f : set.features) {
    dynavins_lcm::weighted_feature_t w;
    w.id = f.id;
    w.u = f.u;
    w.v = f.v;
    put3(w.point, f.p_w);
    w.weight = f.weight;
    w.times_solved = f.times_solved;
    w.sim_label = f.sim_label;
    msg.features.push_back(w);
  }
  return msg;
}

WeightedFeatureSet from_lcm(const dynavins_lcm::weighted_feature_set_t& msg) {
  WeightedFeatureSet set;
  set.t_ns = utime_to_ns(msg.utime);
  set.features.reserve(msg.features.size());
  for (const auto& w : msg.features) {
    WeightedFeature f;
    f.id = w.id;
    f.u = w.u;
    f.v = w.v;
    f.p_w = get3(w.point);
    f.weight = w.weight;
    f.times_solved = w.times_solved;
    f.sim_label = w.sim_label;
    set.features.push_back(f);
  }
  return set;
}

dynavins_lcm::path_t to_lcm(const PathUpdate& path) {
  dynavins_lcm::path_t msg;
  msg.utime = ns_to_utime(path.t_ns);
  for (const PoseEstimate& p : path.poses) msg.poses.push_back(to_lcm(p));
  msg.num_poses = static_cast<int32_t>(msg.poses.size());
  return msg;
}

dynavins_lcm::loop_hypotheses_t to_lcm(const HypothesesUpdate& u) {
  dynavins_lcm::loop_hypotheses_t msg;
  msg.utime = ns_to_utime(u.t_ns);
  msg.group_first_utime = ns_to_utime(u.group_first_t_ns);
  msg.group_size = u.group_size;
  for (const HypothesesUpdate::Hypothesis& h : u.hypotheses) {
    dynavins_lcm::loop_hypothesis_t m;
    m.weight = h.weight;
    put3(m.position, h.first_keyframe.p_wb);
    put_quat(m.orientation, h.first_keyframe.q_wb);
    for (const auto& [query, match] : h.loops) {
      m.query_utime.push_back(ns_to_utime(query));
      m.match_utime.push_back(ns_to_utime(match));
    }
    m.num_loops = static_cast<int32_t>(m.query_utime.size());
    msg.hypotheses.push_back(m);
  }
  msg.num_hypotheses = static_cast<int32_t>(msg.hypotheses.size());
  return msg;
}

dynavins_lcm::pipeline_stats_t to_lcm(const RunReport& report, int64_t wall_utime, double sensor_s) {
  dynavins_lcm::pipeline_stats_t msg;
  msg.utime = wall_utime;
  msg.wall_s = report.wall_s;
  msg.realtime_factor = report.wall_s > 0 ? sensor_s / report.wall_s : 0.0;
  for (const auto& s : report.stages) {
    dynavins_lcm::stage_stats_t m;
    m.name = s.name;
    m.processed = static_cast<int64_t>(s.processed);
    m.process_ms_mean = static_cast<float>(s.process.mean_ms);
    m.process_ms_p95 = static_cast<float>(s.process.p95_ms);
    m.process_ms_max = static_cast<float>(s.process.max_ms);
    m.wait_ms_mean = static_cast<float>(s.wait.mean_ms);
    m.wait_ms_p95 = static_cast<float>(s.wait.p95_ms);
    msg.stages.push_back(m);
  }
  for (const auto& q : report.queues) {
    dynavins_lcm::queue_stats_t m;
    m.name = q.name;
    m.capacity = static_cast<int32_t>(q.capacity);
    m.depth = static_cast<int32_t>(q.depth);
    m.max_depth = static_cast<int32_t>(q.max_depth);
    m.pushed = static_cast<int64_t>(q.pushed);
    m.delivered = static_cast<int64_t>(q.delivered);
    m.dropped = static_cast<int64_t>(q.dropped);
    msg.queues.push_back(m);
  }
  msg.num_stages = static_cast<int32_t>(msg.stages.size());
  msg.num_queues = static_cast<int32_t>(msg.queues.size());
  return msg;
}

}  // namespace dynavins::pipeline
