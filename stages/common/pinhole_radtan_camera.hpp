#pragma once
// camodocs PINHOLE: perspective projection, radial-tangential distortion, fx fy cx cy.

#include "stages/common/camera_model.hpp"
#include "stages/common/radtan_distortion.hpp"

namespace dynavins {

class PinholeRadtanCamera : public CameraModel {
 public:
  struct Params {
    int width = 0, height = 0;
    double fx = 0, fy = 0, cx = 0, cy = 0;
    RadtanDistortion distortion;
  };
  /// Throws std::invalid_argument on non-positive focal lengths or image size.
  explicit PinholeRadtanCamera(const Params& params);

  std::string name() const override { return "PINHOLE"; }
  int width() const override { return p_.width; }
  int height() const override { return p_.height; }
  Eigen::Vector3d lift(const Eigen::Vector2d& pixel) const override;
  /// Only meaningful for points in front of the camera (z > 0); the caller checks.
  Eigen::Vector2d project(const Eigen::Vector3d& point, Jacobian* jacobian = nullptr) const override;
  std::string describe() const override;
  const Params& params() const { return p_; }

 private:
  Params p_;
};

}  // namespace dynavins
