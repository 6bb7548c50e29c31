// Renders one stereo frame of the example street with a truck close ahead and writes
// /tmp/render_example_{left,right,depth,labels}.png, for looking at the renderer's output.
// Usage: sim_render_example [prefix] [t] [day|night] [timing repetitions]

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "sim/render/photometric.hpp"
#include "sim/render/renderer.hpp"
#include "sim/render/street_scene.hpp"

int main(int argc, char** argv) {
  using namespace dynavins::sim;
  const std::string prefix = argc > 1 ? argv[1] : "/tmp/render_example";
  const double t = argc > 2 ? std::stod(argv[2]) : 1.0;
  const bool night = argc > 3 && std::string(argv[3]) == "night";
  const int reps = argc > 4 ? std::stoi(argv[4]) : 1;  // renders of the left view to time
  auto t0 = std::chrono::steady_clock::now();
  StreetSceneOptions so;
  so.truck_start_x = 5.0;  // truck centre 8 m ahead of the camera at t = 1 s
  const World world = make_street_scene(so);
  auto t1 = std::chrono::steady_clock::now();
  std::printf("scene: %zu quads, %.1f MB textures, built in %.2f s\n", world.num_quads(),
              world.texture_bytes() / 1e6, std::chrono::duration<double>(t1 - t0).count());

  const Renderer renderer;
  Eigen::Isometry3d T_left_right = Eigen::Isometry3d::Identity();
  T_left_right.translation() = Eigen::Vector3d(0.11, 0.0, 0.0);
  const Eigen::Isometry3d T_wc = street_camera_pose(0.0, -StreetGeometry::kLaneOffset, 1.5, 0.03, -0.02);
  t0 = std::chrono::steady_clock::now();
  RenderedView left;
  for (int k = 0; k < reps; ++k) left = renderer.render(world, t, T_wc);
  t1 = std::chrono::steady_clock::now();
  const RenderedView right = renderer.render(world, t, T_wc * T_left_right);
  std::printf("render: %.1f ms per view\n", std::chrono::duration<double, std::milli>(t1 - t0).count() / reps);

  const PhotometricOptions po = night ? PhotometricOptions::night() : PhotometricOptions{};
  cv::imwrite(prefix + "_left.png", apply_photometric(left.gray, po, t, 0));
  cv::imwrite(prefix + "_right.png", apply_photometric(right.gray, po, t, 1));
  cv::Mat depth_vis;
  cv::Mat d = left.depth.clone();
  cv::patchNaNs(d, 0.0);
  cv::min(d, 60.0, d);
  d.convertTo(depth_vis, CV_8U, 255.0 / 60.0);
  cv::imwrite(prefix + "_depth.png", depth_vis);
  cv::Mat lab;
  left.labels.convertTo(lab, CV_8U, 80.0);
  cv::imwrite(prefix + "_labels.png", lab);
  std::printf("wrote %s_{left,right,depth,labels}.png\n", prefix.c_str());
  return 0;
}
