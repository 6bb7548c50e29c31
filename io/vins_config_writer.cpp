#include "io/vins_config_writer.hpp"

#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace dynavins::io {
namespace {

void write_camera(const std::string& path, const std::string& name, const PinholeRadtan& c) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) throw std::runtime_error(path + ": cannot write");
  std::fprintf(f,
               "%%YAML:1.0\n---\nmodel_type: PINHOLE\ncamera_name: %s\nimage_width: %d\nimage_height: %d\n"
               "distortion_parameters:\n   k1: %.10g\n   k2: %.10g\n   p1: %.10g\n   p2: %.10g\n"
               "projection_parameters:\n   fx: %.10g\n   fy: %.10g\n   cx: %.10g\n   cy: %.10g\n",
               name.c_str(), c.width, c.height, c.k1, c.k2, c.p1, c.p2, c.fx, c.fy, c.cx, c.cy);
  if (std::fclose(f) != 0) throw std::runtime_error(path + ": write failed");
}

void write_matrix(std::FILE* f, const char* name, const Eigen::Isometry3d& T) {
  const Eigen::Matrix4d M = T.matrix();
  std::fprintf(f, "%s: !!opencv-matrix\n   rows: 4\n   cols: 4\n   dt: d\n   data: [", name);
  for (int i = 0; i < 16; ++i) std::fprintf(f, "%s%.12g", i ? ", " : "", M(i / 4, i % 4));
  std::fprintf(f, "]\n\n");
}

}  // namespace

void write_vins_stereo_config(const std::string& dir, const VinsStereoConfig& c) {
  std::filesystem::create_directories(dir);
  write_camera(dir + "/cam0_pinhole.yaml", "cam0", c.cam0);
  write_camera(dir + "/cam1_pinhole.yaml", "cam1", c.cam1);
  const std::string path = dir + "/vins_config.yaml";
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) throw std::runtime_error(path + ": cannot write");
  std::fprintf(f,
               "%%YAML:1.0\n\n#common parameters (written by dynavins sim; VINS-Fusion's stereo-imu format)\n"
               "imu: 1\nnum_of_cam: 2\n\nimu_topic: \"/imu0\"\nimage0_topic: \"/cam0/image_raw\"\n"
               "image1_topic: \"/cam1/image_raw\"\noutput_path: \"~/output/\"\n\n"
               "cam0_calib: \"cam0_pinhole.yaml\"\ncam1_calib: \"cam1_pinhole.yaml\"\n"
               "image_width: %d\nimage_height: %d\n\nestimate_extrinsic: 0\n\n",
               c.cam0.width, c.cam0.height);
  write_matrix(f, "body_T_cam0", c.body_T_cam0);
  write_matrix(f, "body_T_cam1", c.body_T_cam1);
  std::fprintf(f,
               "multiple_thread: 1\n\n#feature traker paprameters\nmax_cnt: 150\nmin_dist: 30\nfreq: 10\n"
               "F_threshold: 1.0\nshow_track: 0\nflow_back: 1\n\n#optimization parameters\n"
               "max_solver_time: 0.04\nmax_num_iterations: 8\nkeyframe_parallax: 10.0\n\n#imu parameters\n"
               "acc_n: %.6g\ngyr_n: %.6g\nacc_w: %.6g\ngyr_w: %.6g\ng_norm: %.6g\n\n"
               "#unsynchronization parameters\nestimate_td: 0\ntd: 0.0\n\n#loop closure parameters\n"
               "load_previous_pose_graph: 0\npose_graph_save_path: \"~/output/pose_graph/\"\nsave_image: 0\n",
               c.acc_n, c.gyr_n, c.acc_w, c.gyr_w, c.g_norm);
  if (std::fclose(f) != 0) throw std::runtime_error(path + ": write failed");
}

}  // namespace dynavins::io
