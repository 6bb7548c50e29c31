#pragma once
// Pinhole camera with radial-tangential (k1, k2, p1, p2) distortion, OpenCV convention, and the
// per-pixel table of undistorted bearings the renderer casts rays through.
// Camera frame: x right, y down, z along the optical axis. Pixel centres sit at integer coordinates.

#include <vector>

#include <Eigen/Core>

namespace dynavins::sim {

/// Intrinsics; the defaults are EuRoC cam0 (752x480).
struct CameraIntrinsics {
  int width = 752;
  int height = 480;
  double fx = 458.654;
  double fy = 457.296;
  double cx = 367.215;
  double cy = 248.375;
  double k1 = -0.28340811;
  double k2 = 0.07395907;
  double p1 = 0.00019359;
  double p2 = 1.76187114e-05;
};

/// Applies the distortion to undistorted normalised coordinates; optionally returns d(out)/d(in).
Eigen::Vector2d distort_normalized(const CameraIntrinsics& cam, const Eigen::Vector2d& xn,
                                   Eigen::Matrix2d* jacobian = nullptr);

/// Projects a point in the camera frame (z > 0) to distorted pixel coordinates.
Eigen::Vector2d project_point(const CameraIntrinsics& cam, const Eigen::Vector3d& p_cam);

/// Inverts the distortion for a pixel by Newton's method. Returns false if it did not converge;
/// `residual_px` (optional) receives the reprojection error of the solution in pixels.
bool undistort_pixel(const CameraIntrinsics& cam, const Eigen::Vector2d& px, Eigen::Vector2d* xn,
                     double* residual_px = nullptr);

/// Undistorted bearing (x, y, 1) of every pixel centre and its derivatives w.r.t. the pixel, computed
/// once; also a coarse grid of cell bounds in normalised coordinates so the renderer visits only the
/// cells a quad can cover.
class RayTable {
 public:
  static constexpr int kCell = 16;  ///< side of a raster cell in pixels

  /// Builds the table; logs (does not throw) if any pixel failed to converge.
  explicit RayTable(const CameraIntrinsics& cam);

  const CameraIntrinsics& camera() const { return cam_; }
  int width() const { return cam_.width; }
  int height() const { return cam_.height; }

  /// Normalised x, y of pixel index i = v * width + u.
  float x(int i) const { return x_[i]; }
  float y(int i) const { return y_[i]; }
  /// Derivatives of the normalised coordinates w.r.t. the pixel coordinates.
  float dxdu(int i) const { return dxdu_[i]; }
  float dxdv(int i) const { return dxdv_[i]; }
  float dydu(int i) const { return dydu_[i]; }
  float dydv(int i) const { return dydv_[i]; }

  /// Raster cells: count along u / v and the normalised bounds of their pixel centres.
  int cells_u() const { return cells_u_; }
  int cells_v() const { return cells_v_; }
  /// Bounds of cell c = cv * cells_u + cu as {xmin, xmax, ymin, ymax}.
  const Eigen::Vector4f& cell_bounds(int c) const { return cell_bounds_[c]; }
  /// Normalised bounds of the whole image {xmin, xmax, ymin, ymax}.
  const Eigen::Vector4f& image_bounds() const { return image_bounds_; }

  /// Largest reprojection error of the inversion over all pixels [px]; all converged if true.
  double max_residual_px() const { return max_residual_px_; }
  bool all_converged() const { return all_converged_; }

 private:
  CameraIntrinsics cam_;
  std::vector<float> x_, y_, dxdu_, dxdv_, dydu_, dydv_;
  int cells_u_ = 0;
  int cells_v_ = 0;
  std::vector<Eigen::Vector4f> cell_bounds_;
  Eigen::Vector4f image_bounds_;
  double max_residual_px_ = 0.0;
  bool all_converged_ = true;
};

}  // namespace dynavins::sim
