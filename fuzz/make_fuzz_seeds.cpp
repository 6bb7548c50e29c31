// Writes the fuzzers' seed corpora from real inputs: the first frames and IMU samples of the EuRoC
// clip in ../shared (images shrunk to 24x16 so a seed stays a few kB), the VINS-Fusion configs and
// camera files shipped there, and a small log and bag made from that clip. Nothing is committed:
// `make fuzz` runs this into the build tree.
//   make_fuzz_seeds <shared data dir> <out dir>   ->  <out>/{lcm_log,lcm_decode,euroc_csv,config,camera,rosbag}/

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>

#include <opencv2/imgproc.hpp>

#include <dynavins_lcm/loop_hypotheses_t.hpp>
#include <dynavins_lcm/path_t.hpp>
#include <dynavins_lcm/pipeline_stats_t.hpp>
#include <dynavins_lcm/status_t.hpp>

#include "io/euroc_dataset.hpp"
#include "pipeline/lcm_channels.hpp"
#include "pipeline/lcm_convert.hpp"
#include "pipeline/lcm_log.hpp"
#include "pipeline/sensor_log.hpp"

namespace fs = std::filesystem;
using namespace dynavins;

namespace {

constexpr std::size_t kFrames = 3;
const cv::Size kSeedImage(24, 16);

void write_bytes(const fs::path& path, const std::vector<uint8_t>& bytes) {
  std::ofstream f(path, std::ios::binary);
  f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (!f) throw std::runtime_error(path.string() + ": cannot write");
}
void write_text(const fs::path& path, const std::string& text) {
  write_bytes(path, std::vector<uint8_t>(text.begin(), text.end()));
}
std::string read_text(const fs::path& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

/// The clip's first frames (shrunk) with the IMU samples and a ground truth (IMU-time stamps) up to them.
struct Clip {
  std::vector<StereoFrame> frames;
  std::vector<ImuSample> imu;
  std::vector<GroundTruthState> truth;
};
Clip load_clip(const fs::path& euroc) {
  const io::EurocDataset d(euroc.string());
  Clip c;
  for (std::size_t i = 0; i < kFrames && i < d.frames().size(); ++i) {
    StereoFrame f = d.load(i);
    cv::resize(f.left, f.left, kSeedImage, 0, 0, cv::INTER_AREA);
    if (!f.right.empty()) cv::resize(f.right, f.right, kSeedImage, 0, 0, cv::INTER_AREA);
    c.frames.push_back(std::move(f));
  }
  for (const ImuSample& s : d.imu()) {
    if (s.t_ns > c.frames.back().t_ns) break;
    if (s.t_ns >= c.frames.front().t_ns - 20'000'000) c.imu.push_back(s);
  }
  for (std::size_t k = 0; k < c.imu.size(); k += 4) {
    GroundTruthState g;
    g.t_ns = c.imu[k].t_ns;
    g.p_wb = Eigen::Vector3d(0.01 * k, 0.0, 1.0);
    g.has_velocity = g.has_biases = true;
    c.truth.push_back(g);
  }
  return c;
}

void write_logs(const Clip& c, const fs::path& dir) {
  for (const auto encoding : {pipeline::ImageEncoding::Gray8, pipeline::ImageEncoding::Png}) {
    const bool png = encoding == pipeline::ImageEncoding::Png;
    pipeline::LcmLogWriter log((dir / (png ? "euroc_png.lcmlog" : "euroc_gray8.lcmlog")).string());
    std::size_t k = 0, g = 0;
    for (std::size_t i = 0; i < c.frames.size(); ++i) {
      for (; k < c.imu.size() && c.imu[k].t_ns <= c.frames[i].t_ns; ++k) {
        pipeline::write_sensor_event(log, c.imu[k], encoding);
        if (g < c.truth.size() && c.truth[g].t_ns == c.imu[k].t_ns) pipeline::write_sensor_event(log, c.truth[g++], encoding);
      }
      StereoFrame f = c.frames[i];
      if (png && i == 0) f.labels = cv::Mat(f.left.size(), CV_8UC1, cv::Scalar(0));  // a SIM_LABELS event
      pipeline::write_sensor_event(log, f, encoding);
    }
    // A channel the source skips and counts.
    log.write(pipeline::channels::kImu + std::string("_OTHER"), 1, pipeline::to_lcm(c.imu.front()));
    log.close();
  }
}

template <typename Msg>
void write_payload(const fs::path& dir, const std::string& name, uint8_t selector, const Msg& msg) {
  std::vector<uint8_t> bytes(1 + static_cast<std::size_t>(msg.getEncodedSize()));
  bytes[0] = selector;
  if (msg.encode(bytes.data(), 1, static_cast<int>(bytes.size()) - 1) != static_cast<int>(bytes.size()) - 1)
    throw std::runtime_error("cannot encode " + name);
  write_bytes(dir / name, bytes);
}

// Selectors as in fuzz_lcm_decode.cpp.
void write_payloads(const Clip& c, const fs::path& dir) {
  write_payload(dir, "stereo_gray8", 0, pipeline::to_lcm(c.frames[0], pipeline::ImageEncoding::Gray8));
  write_payload(dir, "stereo_png", 0, pipeline::to_lcm(c.frames[1], pipeline::ImageEncoding::Png));
  write_payload(dir, "imu", 1, pipeline::to_lcm(c.imu[0]));
  write_payload(dir, "ground_truth", 2, pipeline::to_lcm(c.truth[0]));
  write_payload(dir, "image_gray8", 3, pipeline::image_to_lcm(c.frames[2].left, c.frames[2].t_ns, pipeline::ImageEncoding::Gray8));
  PoseEstimate pose;
  pose.state.t_ns = c.frames[0].t_ns;
  write_payload(dir, "pose", 4, pipeline::to_lcm(pose));
  dynavins_lcm::weighted_feature_set_t features{};
  features.utime = 1;
  features.num_features = 2;
  features.features.resize(2);
  features.features[1].weight = 0.5f;
  write_payload(dir, "features", 5, features);
  dynavins_lcm::path_t path{};
  path.num_poses = 2;
  path.poses.resize(2);
  for (auto& p : path.poses) p.orientation[0] = 1.0;
  write_payload(dir, "path", 6, path);
  dynavins_lcm::loop_hypotheses_t hypotheses{};
  hypotheses.num_hypotheses = 1;
  hypotheses.hypotheses.resize(1);
  hypotheses.hypotheses[0].num_loops = 2;
  hypotheses.hypotheses[0].query_utime = {1, 2};
  hypotheses.hypotheses[0].match_utime = {3, 4};
  write_payload(dir, "hypotheses", 7, hypotheses);
  dynavins_lcm::status_t status{};
  status.reason = "reset: imu gap";
  write_payload(dir, "status", 8, status);
  dynavins_lcm::pipeline_stats_t stats{};
  stats.num_stages = 1;
  stats.stages.resize(1);
  stats.stages[0].name = "tracker";
  stats.num_queues = 1;
  stats.queues.resize(1);
  stats.queues[0].name = "frames";
  write_payload(dir, "stats", 9, stats);
}

void write_euroc_seeds(const Clip& c, const fs::path& euroc, const fs::path& dir) {
  std::ostringstream cam0, cam1, imu, truth;
  cam0 << "#timestamp [ns],filename\n";
  for (std::size_t i = 0; i < c.frames.size(); ++i) cam0 << c.frames[i].t_ns << "," << i << ".png\n";
  cam1 << "#timestamp [ns],filename\r\n";  // CRLF, as some extracts have
  for (std::size_t i = 0; i < c.frames.size(); ++i) cam1 << c.frames[i].t_ns << "," << i << ".png\r\n";
  // The clip's IMU rows as they are written there.
  std::istringstream rows(read_text(euroc / "mav0" / "imu0" / "data.csv"));
  std::string line;
  for (int n = 0; n < 24 && std::getline(rows, line); ++n) imu << line << "\n";
  truth << "#timestamp,p_x,p_y,p_z,q_w,q_x,q_y,q_z,v_x,v_y,v_z,bw_x,bw_y,bw_z,ba_x,ba_y,ba_z\n";
  for (const auto& g : c.truth)
    truth << g.t_ns << "," << g.p_wb.x() << "," << g.p_wb.y() << "," << g.p_wb.z() << ",1,0,0,0,0,0,0,0,0,0,0,0,0\n";
  const std::string sep = "\n===\n";
  write_text(dir / "stereo_with_truth", cam0.str() + sep + cam1.str() + sep + imu.str() + sep + truth.str());
  write_text(dir / "mono", cam0.str() + sep + sep + imu.str());
  write_text(dir / "stereo_bad_image", cam0.str() + "9" + std::to_string(c.frames.back().t_ns).substr(1) + ",bad.png\n" + sep +
                                           cam1.str() + sep + imu.str());
}

void copy_configs(const fs::path& shared, const fs::path& config_dir, const fs::path& camera_dir) {
  for (const char* folder : {"vins_fusion_euroc_config", "dynavins_viode_config"}) {
    for (const auto& e : fs::directory_iterator(shared / folder)) {
      if (e.path().extension() != ".yaml") continue;
      const std::string text = read_text(e.path());
      const std::string name = std::string(folder) + "_" + e.path().filename().string();
      if (text.find("model_type") != std::string::npos) {
        write_text(camera_dir / name, text);
        continue;
      }
      // The fuzzer's folder has one camera file: cam_pinhole.yaml.
      std::istringstream in(text);
      std::ostringstream out;
      std::string line;
      while (std::getline(in, line)) {
        if (line.rfind("cam0_calib:", 0) == 0) line = "cam0_calib: \"cam_pinhole.yaml\"";
        if (line.rfind("cam1_calib:", 0) == 0) line = "cam1_calib: \"cam_pinhole.yaml\"";
        out << line << "\n";
      }
      write_text(config_dir / name, out.str());
    }
  }
}

ros::Time ros_time(int64_t t_ns) {
  ros::Time t;
  t.fromNSec(static_cast<uint64_t>(t_ns));
  return t;
}
sensor_msgs::Image ros_image(const cv::Mat& gray, int64_t t_ns) {
  sensor_msgs::Image m;
  m.header.stamp = ros_time(t_ns);
  m.height = static_cast<uint32_t>(gray.rows);
  m.width = static_cast<uint32_t>(gray.cols);
  m.encoding = "mono8";
  m.step = m.width;
  m.data.assign(gray.data, gray.data + gray.total());
  return m;
}

void write_bags(const Clip& c, const fs::path& dir) {
  for (const auto compression : {rosbag::compression::Uncompressed, rosbag::compression::LZ4, rosbag::compression::BZ2}) {
    const char* name = compression == rosbag::compression::LZ4 ? "euroc_lz4.bag"
                       : compression == rosbag::compression::BZ2 ? "euroc_bz2.bag"
                                                                 : "euroc.bag";
    rosbag::Bag bag((dir / name).string(), rosbag::bagmode::Write);
    bag.setCompression(compression);
    bag.setChunkThreshold(1024);  // a few chunks
    for (const ImuSample& s : c.imu) {
      sensor_msgs::Imu m;
      m.header.stamp = ros_time(s.t_ns);
      m.angular_velocity.x = s.gyr.x(), m.angular_velocity.y = s.gyr.y(), m.angular_velocity.z = s.gyr.z();
      m.linear_acceleration.x = s.acc.x(), m.linear_acceleration.y = s.acc.y(), m.linear_acceleration.z = s.acc.z();
      bag.write("/imu0", m.header.stamp, m);
    }
    for (const StereoFrame& f : c.frames) {
      bag.write("/cam0/image_raw", ros_time(f.t_ns + 1000), ros_image(f.left, f.t_ns));
      bag.write("/cam1/image_raw", ros_time(f.t_ns + 2000), ros_image(f.right, f.t_ns));
    }
    for (const GroundTruthState& g : c.truth) {
      nav_msgs::Odometry o;
      o.header.stamp = ros_time(g.t_ns);
      o.header.frame_id = "world";
      o.pose.pose.position.x = g.p_wb.x(), o.pose.pose.position.z = g.p_wb.z();
      o.pose.pose.orientation.w = 1.0;
      bag.write("/odometry", ros_time(g.t_ns + 500), o);
    }
    bag.close();
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: make_fuzz_seeds <shared data dir> <out dir>\n");
    return 2;
  }
  try {
    const fs::path shared = argv[1], out = argv[2];
    for (const char* d : {"lcm_log", "lcm_decode", "euroc_csv", "config", "camera", "rosbag"}) fs::create_directories(out / d);
    const fs::path euroc = shared / "euroc_v1_01_micro";
    const Clip clip = load_clip(euroc);
    write_logs(clip, out / "lcm_log");
    write_payloads(clip, out / "lcm_decode");
    write_euroc_seeds(clip, euroc, out / "euroc_csv");
    copy_configs(shared, out / "config", out / "camera");
    write_bags(clip, out / "rosbag");
    std::printf("make_fuzz_seeds: seed corpora in %s\n", out.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_fuzz_seeds: %s\n", e.what());
    return 1;
  }
  return 0;
}
