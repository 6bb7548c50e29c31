#include "stages/estimator/initialization/gyro_bias_estimator.hpp"

#include <cmath>
#include <stdexcept>

#include "stages/common/so3.hpp"

namespace dynavins::estimator {
namespace {
/// Interval k's rotation mismatch Log(γ^-1 R_rel) and its Jacobian J^γ_bg (§V-B-1).
void interval_mismatch(const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b, const imu::ImuPreintegration& p,
                       Eigen::Vector3d& r, Eigen::Matrix3d& J) {
  const Eigen::Matrix3d R_rel = R_a.transpose() * R_b;  // q_bk^-1 ⊗ q_bk+1
  J = p.jacobian().block<3, 3>(imu::ImuPreintegration::kR, imu::ImuPreintegration::kBg);
  // γ Exp(J δbg) = R_rel  =>  J δbg = Log(γ^-1 R_rel).
  r = so3::log(p.delta_q().toRotationMatrix().transpose() * R_rel);
}
}  // namespace

Eigen::Vector3d estimate_gyro_bias(const std::vector<Eigen::Matrix3d>& R_wb,
                                 const std::vector<const imu::ImuPreintegration*>& preints) {
  if (R_wb.size() != preints.size() + 1)
    throw std::invalid_argument("estimate_gyro_bias: need one rotation more than preintegrations");
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < preints.size(); ++k) {
    if (preints[k] == nullptr) throw std::invalid_argument("estimate_gyro_bias: null preintegration");
    Eigen::Vector3d r;
    Eigen::Matrix3d J;
    interval_mismatch(R_wb[k], R_wb[k + 1], *preints[k], r, J);
    A += J.transpose() * J;
    b += J.transpose() * r;
  }
  if (preints.empty()) return Eigen::Vector3d::Zero();
  return A.ldlt().solve(b);
}

double gyro_bias_fit_rms_rad(const std::vector<Eigen::Matrix3d>& R_wb,
                             const std::vector<const imu::ImuPreintegration*>& preints, const Eigen::Vector3d& dbg) {
  if (R_wb.size() != preints.size() + 1)
    throw std::invalid_argument("gyro_bias_fit_rms_rad: need one rotation more than preintegrations");
  if (preints.empty()) return 0.0;
  double sum = 0.0;
  for (size_t k = 0; k < preints.size(); ++k) {
    if (preints[k] == nullptr) throw std::invalid_argument("gyro_bias_fit_rms_rad: null preintegration");
    Eigen::Vector3d r;
    Eigen::Matrix3d J;
    interval_mismatch(R_wb[k], R_wb[k + 1], *preints[k], r, J);
    sum += (r - J * dbg).squaredNorm();
  }
  return std::sqrt(sum / static_cast<double>(preints.size()));
}

}  // namespace dynavins::estimator
