#pragma once
// Renders a World through a distorted pinhole camera: gray image, metric depth (z along the optical
// axis) and per-pixel object labels. Each quad is rasterised only over the 16x16-pixel cells its
// projection can cover, with an exact ray-plane intersection per pixel from the RayTable; a z-buffer
// resolves occlusion, then each visible pixel is shaded once with footprint-filtered texture sampling.
// Object silhouettes are anti-aliased with 4 sub-samples; depth and labels stay those of the pixel centre.

#include <memory>
#include <utility>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>

#include "sim/render/camera_rays.hpp"
#include "sim/render/world.hpp"

namespace dynavins::sim {

/// Lighting, sky and quality settings.
struct RenderOptions {
  double near_m = 0.05;  ///< nearest visible depth
  /// Unit vector toward the sun (world frame).
  Eigen::Vector3d sun_direction = Eigen::Vector3d(0.35, -0.45, 0.82).normalized();
  double ambient = 0.5;   ///< shading = ambient + diffuse * max(0, n . sun)
  double diffuse = 0.55;
  double exposure = 1.15;  ///< gray = 255 * exposure * albedo * shading
  double sky_horizon = 212.0;  ///< sky gray at the horizon
  double sky_zenith = 172.0;   ///< sky gray straight up
  int max_anisotropy = 8;      ///< texture probes along a stretched footprint
  bool antialias_edges = true; ///< super-sample pixels where the visible quad changes
};

/// One rendered view. depth is +inf and label 0 where nothing is hit (sky).
struct RenderedView {
  cv::Mat gray;    ///< CV_8UC1
  cv::Mat depth;   ///< CV_32FC1, z along the optical axis [m]
  cv::Mat labels;  ///< CV_8UC1, 0 static world / sky, k = moving object k
};

class Renderer {
 public:
  /// Precomputes the ray table for the camera.
  explicit Renderer(const CameraIntrinsics& camera = CameraIntrinsics{}, const RenderOptions& options = {});

  /// Renders the world at time t seen from T_world_cam (camera frame: x right, y down, z forward).
  /// Thread-safe: concurrent calls on one Renderer are fine.
  RenderedView render(const World& world, double t, const Eigen::Isometry3d& T_world_cam) const;

  /// Left and right views (right camera at T_world_left * T_left_right, same intrinsics), rendered on
  /// two threads.
  std::pair<RenderedView, RenderedView> render_stereo(const World& world, double t,
                                                      const Eigen::Isometry3d& T_world_left,
                                                      const Eigen::Isometry3d& T_left_right) const;

  const RayTable& rays() const { return *rays_; }
  const CameraIntrinsics& camera() const { return rays_->camera(); }
  const RenderOptions& options() const { return options_; }

 private:
  std::shared_ptr<const RayTable> rays_;
  RenderOptions options_;
};

}  // namespace dynavins::sim
