#pragma once
// camodocs KANNALA_BRANDT (equidistant fisheye): r(theta) = theta + k2 t^3 + k3 t^5 + k4 t^7 + k5 t^9,
// scaled by mu mv and shifted by u0 v0. camodocs' k2..k5 are cv::fisheye's k1..k4.

#include "stages/common/camera_model.hpp"

namespace dynavins {

class KannalaBrandtCamera : public CameraModel {
 public:
  struct Params {
    int width = 0, height = 0;
    double k2 = 0, k3 = 0, k4 = 0, k5 = 0;
    double mu = 0, mv = 0, u0 = 0, v0 = 0;
  };
  /// Throws std::invalid_argument on non-positive mu mv or image size.
  explicit KannalaBrandtCamera(const Params& params);

  std::string name() const override { return "KANNALA_BRANDT"; }
  int width() const override { return p_.width; }
  int height() const override { return p_.height; }
  Eigen::Vector3d lift(const Eigen::Vector2d& pixel) const override;
  Eigen::Vector2d project(const Eigen::Vector3d& point, Jacobian* jacobian = nullptr) const override;
  std::string describe() const override;
  const Params& params() const { return p_; }

 private:
  double poly(double theta, double* dpoly) const;
  Params p_;
};

}  // namespace dynavins
