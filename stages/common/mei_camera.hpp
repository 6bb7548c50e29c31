#pragma once
// camodocs MEI (unified omnidirectional, Mei & Rives 2007): the point goes to the unit sphere, is
// projected from a centre shifted by xi, then radtan-distorted and scaled by gamma1 gamma2 u0 v0.
// VINS-Fusion's default EuRoC configs use it; it matches cv::omnidir with zero skew.

#include "stages/common/camera_model.hpp"
#include "stages/common/radtan_distortion.hpp"

namespace dynavins {

class MeiCamera : public CameraModel {
 public:
  struct Params {
    int width = 0, height = 0;
    double xi = 0;
    RadtanDistortion distortion;
    double gamma1 = 0, gamma2 = 0, u0 = 0, v0 = 0;
  };
  /// Throws std::invalid_argument on non-positive gammas, negative xi or image size.
  explicit MeiCamera(const Params& params);

  std::string name() const override { return "MEI"; }
  int width() const override { return p_.width; }
  int height() const override { return p_.height; }
  /// Returns NaNs where the undistorted pixel lies outside the model's image (xi > 1 only).
  Eigen::Vector3d lift(const Eigen::Vector2d& pixel) const override;
  Eigen::Vector2d project(const Eigen::Vector3d& point, Jacobian* jacobian = nullptr) const override;
  std::string describe() const override;
  const Params& params() const { return p_; }

 private:
  Params p_;
};

}  // namespace dynavins
