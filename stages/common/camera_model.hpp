#pragma once
// The camera interface the front end and the estimator see: pixels <-> bearings, whatever the lens.

#include <memory>
#include <string>

#include <Eigen/Core>

namespace dynavins {

class CameraModel {
 public:
  using Jacobian = Eigen::Matrix<double, 2, 3>;

  virtual ~CameraModel() = default;

  /// The camodocs model_type this camera was built from ("PINHOLE", "MEI", "KANNALA_BRANDT").
  virtual std::string name() const = 0;
  /// Image size in pixels as given by the calibration file.
  virtual int width() const = 0;
  virtual int height() const = 0;

  /// Pixel -> unit bearing in the camera frame (z may be <= 0 for wide-angle models).
  virtual Eigen::Vector3d lift(const Eigen::Vector2d& pixel) const = 0;
  /// Camera-frame point -> pixel; fills d(pixel)/d(point) when `jacobian` is not null.
  virtual Eigen::Vector2d project(const Eigen::Vector3d& point, Jacobian* jacobian = nullptr) const = 0;

  /// Pixel -> point on the normalized plane z = 1 (what VINS-Fusion's feature tracker publishes).
  Eigen::Vector2d lift_normalized(const Eigen::Vector2d& pixel) const {
    const Eigen::Vector3d b = lift(pixel);
    return b.head<2>() / b.z();
  }
  /// One line with the model and its parameters, for the start-up print.
  virtual std::string describe() const = 0;
};

using CameraModelPtr = std::shared_ptr<const CameraModel>;

}  // namespace dynavins
