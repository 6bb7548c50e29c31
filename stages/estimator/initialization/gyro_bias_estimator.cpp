#include "stages/estimator/initialization/gyro_bias_estimator.hpp"

#include <stdexcept>

#include "stages/common/so3.hpp"

namespace dynavins::estimator {

Eigen::Vector3d estimate_gyro_bias(const std::vector<Eigen::Matrix3d>& R_wb,
                                 const std::vector<const imu::ImuPreintegration*>& preints) {
  if (R_wb.size() != preints.size() + 1)
    throw std::invalid_argument("estimate_gyro_bias: need one rotation more than preintegrations");
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < preints.size(); ++k) {
    if (preints[k] == nullptr) throw std::invalid_argument("estimate_gyro_bias: null preintegration");
    const Eigen::Matrix3d R_rel = R_wb[k].transpose() * R_wb[k + 1];  // q_bk^-1 ⊗ q_bk+1
    const Eigen::Matrix3d J = preints[k]->jacobian().block<3, 3>(imu::ImuPreintegration::kR, imu::ImuPreintegration::kBg);
    // §V-B-1: γ Exp(J δbg) = R_rel  =>  J δbg = Log(γ^-1 R_rel).
    const Eigen::Vector3d r = so3::log(preints[k]->delta_q().toRotationMatrix().transpose() * R_rel);
    A += J.transpose() * J;
    b += J.transpose() * r;
  }
  if (preints.empty()) return Eigen::Vector3d::Zero();
  return A.ldlt().solve(b);
}

}  // namespace dynavins::estimator
