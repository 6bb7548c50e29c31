#pragma once
// Marginalisation of old states out of the sliding window (VINS-Mono §VI-E / VINS-Fusion's
// MarginalizationInfo; Sibley et al., "Sliding window filter with application to planetary landing",
// 2010, for the Schur complement). Every residual block touching a state to remove is evaluated at the
// current estimate x0, the Gauss-Newton system H δx = -b is formed over all blocks involved (tangent
// coordinates), the removed blocks are eliminated by the Schur complement
//   H* = H_kk - H_km H_mm^+ H_mk,   b* = b_k - H_km H_mm^+ b_m,
// and H*, b* are factored back into a linear residual r(x) = r0 + J (x ⊖ x0) with J^T J = H* and
// J^T r0 = b* (eigen-decomposition H* = V S V^T: J = S^1/2 V^T, r0 = S^-1/2 V^T b*, eigenvalues below a
// threshold dropped). MarginalizationFactor turns that residual into the prior of the next window.
//
// Blocks are raw double arrays (parameter_layout.hpp): ambient size 7 is a pose with a 6-dim tangent
// (right perturbation, PoseManifold), every other size is Euclidean. No threads.

#include <memory>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>
#include <ceres/cost_function.h>
#include <ceres/loss_function.h>

namespace dynavins::estimator {

/// One residual block of the window that touches a state to marginalise.
struct ResidualBlockInfo {
  std::shared_ptr<const ceres::CostFunction> cost;
  std::shared_ptr<const ceres::LossFunction> loss;  ///< may be null (plain least squares)
  std::vector<double*> blocks;                      ///< parameter blocks, in the cost's order
  std::vector<int> drop;                            ///< indices into `blocks` of the ones to marginalise
};

/// Collects residual blocks, linearises them and eliminates the dropped states (see file comment).
/// Use: add() every block touching a dropped state, linearize(), marginalize(); then build a
/// MarginalizationFactor on kept_blocks(shift).
class MarginalizationInfo {
 public:
  /// `eigenvalue_threshold`: eigenvalues of H_mm and H* at or below it are treated as zero (the prior
  /// carries no information along them).
  explicit MarginalizationInfo(double eigenvalue_threshold = 1e-8);

  /// Registers a residual block. A block listed in `drop` of any residual is marginalised. Throws
  /// std::invalid_argument on a size mismatch with the cost, a bad drop index, a null cost, or a block
  /// already seen with another size. Only before linearize().
  void add(ResidualBlockInfo residual);

  /// Evaluates every residual block at the current values of its blocks and snapshots those values
  /// (the linearisation point x0). Robust losses are applied exactly as Ceres' solver does (its
  /// internal Corrector, Triggs et al. "Bundle adjustment - a modern synthesis" §4.3): residual and
  /// Jacobian are scaled by sqrt(rho'), with the second-order correction when rho'' > 0; for Huber and
  /// Cauchy (rho'' <= 0) it is the plain sqrt(rho') weighting, so the prior holds the information the
  /// solver itself used. Throws std::runtime_error if a cost fails to evaluate.
  void linearize();

  /// Forms H and b, takes the Schur complement onto the kept blocks and factors it into
  /// linearized_jacobian() / linearized_residual(). Throws std::logic_error if linearize() was not called
  /// and std::runtime_error if no block is kept or the Schur complement has no eigenvalue above the
  /// threshold (nothing to keep). Releases the added residual blocks (their costs and losses).
  void marginalize();

  /// Kept blocks in column order of linearized_jacobian(), at their addresses after a window shift:
  /// `shift` maps an old address to its new one; blocks absent from the map keep their address.
  std::vector<double*> kept_blocks(const std::unordered_map<const double*, double*>& shift = {}) const;
  /// Ambient sizes of the kept blocks (7 = pose, else Euclidean), in column order.
  const std::vector<int>& kept_sizes() const { return kept_sizes_; }
  /// Column offset of each kept block in linearized_jacobian() (tangent coordinates).
  const std::vector<int>& kept_tangent_offsets() const { return kept_tangent_offsets_; }
  /// Sum of the kept blocks' tangent sizes: the columns of linearized_jacobian().
  int kept_tangent_size() const { return kept_tangent_size_; }
  /// Values of the kept blocks at linearisation (x0), in column order.
  const std::vector<Eigen::VectorXd>& kept_linearization_point() const { return kept_x0_; }

  /// J (m x kept_tangent_size()), m = rank of the Schur complement.
  const Eigen::MatrixXd& linearized_jacobian() const { return linearized_jacobian_; }
  /// r0 (m).
  const Eigen::VectorXd& linearized_residual() const { return linearized_residual_; }

  /// Tangent size of a block of ambient size `ambient_size` (7 -> 6, else unchanged).
  static int tangent_size(int ambient_size);

 private:
  /// Forms the Gauss-Newton system over the "dense" columns (non-scalar dropped blocks first, then the
  /// kept ones) with the scalar dropped blocks (see marginalize()) already eliminated. Returns false if
  /// a scalar block has no information (H_dd <= threshold): the caller then retries with none scalar.
  bool assemble(const std::vector<char>& scalar, Eigen::MatrixXd& H, Eigen::VectorXd& b,
                int& dropped_dense_size) const;
  /// A scalar dropped block's row of H (defined in the .cpp).
  struct ScalarBlock;
  /// assemble()'s phases. Column offset of every block in the dense system (-1 for the scalar ones);
  /// returns the system's size, `dropped_dense_size` the size of its dropped part.
  int dense_column_offsets(const std::vector<char>& scalar, std::vector<int>& offset, int& dropped_dense_size) const;
  /// One ScalarBlock (neighbours known, sums zero) per scalar block; `scalar_id` per block: its index there
  /// or -1; `residual_scalar` per residual: the position of its scalar block among its blocks, or -1.
  std::vector<ScalarBlock> scalar_blocks(const std::vector<char>& scalar, std::vector<int>& scalar_id,
                                        std::vector<int>& residual_scalar) const;
  /// Adds every residual's J^T J and J^T r: the dense blocks' into the upper triangle of H and into b,
  /// the scalar blocks' into their ScalarBlock.
  void accumulate_normal_equations(const std::vector<int>& offset, const std::vector<int>& scalar_id,
                                 const std::vector<int>& residual_scalar, std::vector<ScalarBlock>& scalars,
                                 Eigen::MatrixXd& H, Eigen::VectorXd& b) const;
  /// Schur complement of the scalar blocks into the upper triangle of H and into b; false if one of them
  /// has no information (h_dd at or below the threshold).
  bool eliminate_scalar_blocks(const std::vector<ScalarBlock>& scalars, const std::vector<int>& offset,
                             Eigen::MatrixXd& H, Eigen::VectorXd& b) const;

  double eigenvalue_threshold_;
  std::vector<ResidualBlockInfo> residuals_;
  std::vector<double*> blocks_;  ///< every block seen, in order of first appearance
  std::vector<int> sizes_;       ///< ambient size of blocks_[i]
  std::vector<char> is_dropped_;  ///< per blocks_[i]
  std::unordered_map<const double*, int> block_index_;  ///< address -> index into blocks_
  std::vector<std::vector<int>> residual_blocks_;       ///< per residual: indices into blocks_
  /// Linearisation of every residual, whitened and loss-corrected, in one buffer: per residual its
  /// residual vector then each block's tangent Jacobian (column-major, rows x tangent size).
  std::vector<double> lin_data_;
  std::vector<size_t> lin_offset_;  ///< per residual: start of its data in lin_data_
  std::vector<Eigen::VectorXd> x0_;  ///< per blocks_[i]
  bool linearized_ = false;

  std::vector<double*> kept_blocks_;
  std::vector<int> kept_sizes_;
  std::vector<int> kept_tangent_offsets_;
  int kept_tangent_size_ = 0;
  std::vector<Eigen::VectorXd> kept_x0_;
  Eigen::MatrixXd linearized_jacobian_;
  Eigen::VectorXd linearized_residual_;
};

}  // namespace dynavins::estimator
