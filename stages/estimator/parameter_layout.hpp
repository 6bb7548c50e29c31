#pragma once
// How the estimator stores its states as Ceres parameter blocks (VINS-Fusion's layout, so its factor
// algebra carries over):
//   pose        [7]: p_wb (x y z), q_wb (x y z w, Eigen's coeffs() order); tangent [6]: δp, δθ with the
//                    right perturbation q ⊗ Exp(δθ) (see PoseManifold).
//   speed-bias  [9]: v_wb (3), accelerometer bias (3), gyroscope bias (3).
//   extrinsic   [7]: body_T_cam as a pose block (p_bc, q_bc); held constant (fixed from config).
//   inverse depth [1]: of a feature in its anchor frame's cam0 (1 / z along the z = 1 bearing).
// Factors write the Jacobian of a pose block in its 6 tangent columns and leave column 7 zero; the
// manifold's PlusJacobian is [I6; 0], so Ceres' chain rule hands the solver exactly the tangent Jacobian.

namespace dynavins::estimator {

inline constexpr int kPoseSize = 7;
inline constexpr int kPoseTangentSize = 6;
inline constexpr int kSpeedBiasSize = 9;
inline constexpr int kInverseDepthSize = 1;

}  // namespace dynavins::estimator
