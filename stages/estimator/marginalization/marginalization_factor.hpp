#pragma once
// The prior a marginalisation leaves behind (VINS-Mono §VI-E): the linear residual
//   r(x) = r0 + J (x ⊖ x0)
// over the kept blocks, with J, r0 and x0 from MarginalizationInfo. x ⊖ x0 per block: Euclidean x - x0;
// pose [p - p0, Log(q0^-1 q)] (PoseManifold::Minus). The Jacobian of a pose block is written in its 6
// tangent columns (column 7 zero, parameter_layout.hpp) and is exact: d Log(q0^-1 q Exp(δθ)) / dδθ =
// Jr^-1(Log(q0^-1 q)) (VINS-Fusion approximates it by the identity).

#include <memory>

#include <ceres/cost_function.h>

#include "stages/estimator/marginalization/marginalization_info.hpp"

namespace dynavins::estimator {

class MarginalizationFactor final : public ceres::CostFunction {
 public:
  /// `info` must have been marginalize()d. Parameter blocks: info->kept_blocks(shift) (ambient sizes
  /// info->kept_sizes()); residuals: info->linearized_jacobian().rows().
  explicit MarginalizationFactor(std::shared_ptr<const MarginalizationInfo> info);

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

  const MarginalizationInfo& info() const { return *info_; }

 private:
  std::shared_ptr<const MarginalizationInfo> info_;
};

}  // namespace dynavins::estimator
