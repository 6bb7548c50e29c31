#pragma once
// Small SO(3) toolbox shared by the simulator and the estimator: hat, Exp, Log, right/left Jacobians.
// Formulas: Barfoot, "State Estimation for Robotics" (2017), §7.1; Sola et al., "A micro Lie theory
// for state estimation in robotics" (arXiv:1812.01537), eqs. (143)-(146) (right Jacobian and inverse).
// Convention: Exp(φ) = I + sin|φ|/|φ| [φ]x + (1-cos|φ|)/|φ|^2 [φ]x^2; right Jacobian Jr satisfies
// Exp(φ + δ) ≈ Exp(φ) Exp(Jr(φ) δ) and Log(Exp(φ) Exp(δ)) ≈ φ + Jr(φ)^-1 δ.

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace dynavins::so3 {

/// Skew-symmetric matrix with hat(a) * b == a.cross(b).
inline Eigen::Matrix3d hat(const Eigen::Vector3d& a) {
  Eigen::Matrix3d m;
  m << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return m;
}

/// Rotation matrix of the rotation vector `phi` (Rodrigues).
inline Eigen::Matrix3d exp(const Eigen::Vector3d& phi) {
  const double th2 = phi.squaredNorm();
  const Eigen::Matrix3d k = hat(phi);
  double a, b;  // sin(th)/th and (1-cos th)/th^2
  if (th2 < 1e-10) {
    // Taylor terms up to th^2: the next ones are below double precision here.
    a = 1.0 - th2 / 6.0;
    b = 0.5 - th2 / 24.0;
  } else {
    const double th = std::sqrt(th2);
    a = std::sin(th) / th;
    b = (1.0 - std::cos(th)) / th2;
  }
  return Eigen::Matrix3d::Identity() + a * k + b * k * k;
}

/// Rotation vector of `R`, angle in [0, pi]. Goes through a quaternion, which stays accurate
/// near both 0 and pi (the trace formula does not).
inline Eigen::Vector3d log(const Eigen::Matrix3d& R) {
  Eigen::Quaterniond q(R);
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const Eigen::Vector3d v = q.vec();
  const double s = v.norm();
  if (s < 1e-12) return 2.0 * v / q.w();  // first order: angle = 2 asin(s) ~ 2 s
  const double angle = 2.0 * std::atan2(s, q.w());
  return (angle / s) * v;
}

/// Right Jacobian Jr(phi) of SO(3).
inline Eigen::Matrix3d right_jacobian(const Eigen::Vector3d& phi) {
  const double th2 = phi.squaredNorm();
  const Eigen::Matrix3d k = hat(phi);
  double a, b;  // (1-cos th)/th^2 and (th - sin th)/th^3
  if (th2 < 1e-10) {
    a = 0.5 - th2 / 24.0;
    b = 1.0 / 6.0 - th2 / 120.0;
  } else {
    const double th = std::sqrt(th2);
    a = (1.0 - std::cos(th)) / th2;
    b = (th - std::sin(th)) / (th2 * th);
  }
  return Eigen::Matrix3d::Identity() - a * k + b * k * k;
}

/// Inverse right Jacobian Jr(phi)^-1.
inline Eigen::Matrix3d right_jacobian_inverse(const Eigen::Vector3d& phi) {
  const double th2 = phi.squaredNorm();
  const Eigen::Matrix3d k = hat(phi);
  double c;  // 1/th^2 - (1+cos th)/(2 th sin th)
  if (th2 < 1e-10) {
    c = 1.0 / 12.0 + th2 / 720.0;
  } else {
    const double th = std::sqrt(th2);
    c = 1.0 / th2 - (1.0 + std::cos(th)) / (2.0 * th * std::sin(th));
  }
  return Eigen::Matrix3d::Identity() + 0.5 * k + c * k * k;
}

/// Inverse left Jacobian Jl(phi)^-1 = Jr(-phi)^-1: Log(Exp(δ) Exp(φ)) ≈ φ + Jl(φ)^-1 δ.
inline Eigen::Matrix3d left_jacobian_inverse(const Eigen::Vector3d& phi) {
  return right_jacobian_inverse(-phi);
}

/// Rotation matrix for intrinsic Z-Y-X angles: R = Rz(yaw) * Ry(pitch) * Rx(roll).
inline Eigen::Matrix3d from_yaw_pitch_roll(double yaw, double pitch, double roll) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

}  // namespace dynavins::so3
