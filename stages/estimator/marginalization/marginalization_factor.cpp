#include "stages/estimator/marginalization/marginalization_factor.hpp"

#include <stdexcept>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "stages/common/so3.hpp"
#include "stages/estimator/parameter_layout.hpp"

namespace dynavins::estimator {

MarginalizationFactor::MarginalizationFactor(std::shared_ptr<const MarginalizationInfo> info)
    : info_(std::move(info)) {
  if (!info_ || info_->kept_sizes().empty() || info_->linearized_jacobian().rows() == 0) {
    throw std::invalid_argument("MarginalizationFactor: the MarginalizationInfo was not marginalized");
  }
  for (int size : info_->kept_sizes()) mutable_parameter_block_sizes()->push_back(size);
  set_num_residuals(static_cast<int>(info_->linearized_jacobian().rows()));
}

bool MarginalizationFactor::Evaluate(double const* const* parameters, double* residuals,
                                     double** jacobians) const {
  const std::vector<int>& sizes = info_->kept_sizes();
  const std::vector<int>& offsets = info_->kept_tangent_offsets();
  const std::vector<Eigen::VectorXd>& x0 = info_->kept_linearization_point();
  const Eigen::MatrixXd& J = info_->linearized_jacobian();
  const int rows = static_cast<int>(J.rows());

  // dx = x ⊖ x0, plus d(dx)/d(tangent) for the pose rotations (Jr^-1; identity elsewhere).
  Eigen::VectorXd dx(info_->kept_tangent_size());
  std::vector<Eigen::Matrix3d> jr_inv(sizes.size(), Eigen::Matrix3d::Identity());
  for (size_t i = 0; i < sizes.size(); ++i) {
    const int o = offsets[i];
    if (sizes[i] == kPoseSize) {
      Eigen::Map<const Eigen::Vector3d> p(parameters[i]);
      Eigen::Map<const Eigen::Quaterniond> q(parameters[i] + 3);
      const Eigen::Quaterniond q0(x0[i](6), x0[i](3), x0[i](4), x0[i](5));
      dx.segment<3>(o) = p - x0[i].head<3>();
      const Eigen::Vector3d dtheta = so3::log((q0.conjugate() * q).normalized().toRotationMatrix());
      dx.segment<3>(o + 3) = dtheta;
      jr_inv[i] = so3::right_jacobian_inverse(dtheta);
    } else {
      dx.segment(o, sizes[i]) = Eigen::Map<const Eigen::VectorXd>(parameters[i], sizes[i]) - x0[i];
    }
  }

  Eigen::Map<Eigen::VectorXd>(residuals, rows) = info_->linearized_residual() + J * dx;

  if (jacobians == nullptr) return true;
  for (size_t i = 0; i < sizes.size(); ++i) {
    if (jacobians[i] == nullptr) continue;
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> ji(jacobians[i], rows, sizes[i]);
    const int o = offsets[i];
    if (sizes[i] == kPoseSize) {
      ji.setZero();
      ji.leftCols<3>() = J.middleCols<3>(o);
      ji.middleCols<3>(3) = J.middleCols<3>(o + 3) * jr_inv[i];
    } else {
      ji = J.middleCols(o, sizes[i]);
    }
  }
  return true;
}

}  // namespace dynavins::estimator
