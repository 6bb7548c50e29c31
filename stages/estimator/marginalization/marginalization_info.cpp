#include "stages/estimator/marginalization/marginalization_info.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Eigenvalues>

#include "stages/estimator/parameter_layout.hpp"

namespace dynavins::estimator {

namespace {

using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// Applies a robust loss to a residual and its Jacobians the way Ceres' internal Corrector does
/// (ceres/internal/corrector.cc; Triggs et al. 2000, §4.3): with s = |r|^2 and rho = (ρ, ρ', ρ''),
///   ρ'' <= 0 (Huber, Cauchy, ...):  r <- sqrt(ρ') r,            J <- sqrt(ρ') J
///   ρ'' >  0:  α = 1 - sqrt(1 + 2 s ρ''/ρ'),  r <- sqrt(ρ')/(1-α) r,  J <- sqrt(ρ') (I - α r r^T/s) J
/// so that (J^T J, J^T r) is the Hessian/gradient the solver itself forms for that residual.
void applyLoss(const ceres::LossFunction& loss, Eigen::VectorXd& r, std::vector<Eigen::MatrixXd>& jacobians) {
  const double sq_norm = r.squaredNorm();
  double rho[3];
  loss.Evaluate(sq_norm, rho);
  if (!(rho[1] > 0.0)) {
    // ρ' = 0 (e.g. Tukey beyond its scale): the residual carries no information here.
    r.setZero();
    for (auto& j : jacobians) j.setZero();
    return;
  }
  const double sqrt_rho1 = std::sqrt(rho[1]);
  double residual_scaling = sqrt_rho1;
  double alpha_sq_norm = 0.0;
  if (sq_norm > 0.0 && rho[2] > 0.0) {
    const double alpha = 1.0 - std::sqrt(1.0 + 2.0 * sq_norm * rho[2] / rho[1]);
    residual_scaling = sqrt_rho1 / (1.0 - alpha);
    alpha_sq_norm = alpha / sq_norm;
  }
  // Jacobians first: the correction uses the unscaled residual.
  for (auto& j : jacobians) {
    const Eigen::RowVectorXd rt_j = r.transpose() * j;
    j = sqrt_rho1 * (j - alpha_sq_norm * r * rt_j);
  }
  r *= residual_scaling;
}

}  // namespace

MarginalizationInfo::MarginalizationInfo(double eigenvalue_threshold)
    : eigenvalue_threshold_(eigenvalue_threshold) {}

int MarginalizationInfo::tangentSize(int ambient_size) {
  return ambient_size == kPoseSize ? kPoseTangentSize : ambient_size;
}

void MarginalizationInfo::add(ResidualBlockInfo residual) {
  if (linearized_) throw std::logic_error("MarginalizationInfo::add after linearize()");
  if (!residual.cost) throw std::invalid_argument("MarginalizationInfo::add: null cost function");
  const std::vector<int32_t>& sizes = residual.cost->parameter_block_sizes();
  if (sizes.size() != residual.blocks.size()) {
    throw std::invalid_argument("MarginalizationInfo::add: " + std::to_string(residual.blocks.size()) +
                                " blocks for a cost with " + std::to_string(sizes.size()));
  }
  for (size_t i = 0; i < sizes.size(); ++i) {
    double* block = residual.blocks[i];
    if (block == nullptr) throw std::invalid_argument("MarginalizationInfo::add: null parameter block");
    const auto [it, inserted] = block_size_.emplace(block, sizes[i]);
    if (inserted) {
      blocks_.push_back(block);
    } else if (it->second != sizes[i]) {
      throw std::invalid_argument("MarginalizationInfo::add: block seen with sizes " +
                                  std::to_string(it->second) + " and " + std::to_string(sizes[i]));
    }
  }
  for (int d : residual.drop) {
    if (d < 0 || d >= static_cast<int>(residual.blocks.size())) {
      throw std::invalid_argument("MarginalizationInfo::add: drop index " + std::to_string(d) + " out of range");
    }
    dropped_.insert(residual.blocks[d]);
  }
  residuals_.push_back(std::move(residual));
}

void MarginalizationInfo::linearize() {
  linearizations_.clear();
  linearizations_.reserve(residuals_.size());
  for (const ResidualBlockInfo& res : residuals_) {
    const ceres::CostFunction& cost = *res.cost;
    const std::vector<int32_t>& sizes = cost.parameter_block_sizes();
    const int rows = cost.num_residuals();
    std::vector<RowMajorMatrix> ambient(sizes.size());
    std::vector<double*> jacobian_ptrs(sizes.size());
    for (size_t i = 0; i < sizes.size(); ++i) {
      ambient[i].setZero(rows, sizes[i]);
      jacobian_ptrs[i] = ambient[i].data();
    }
    Linearization lin;
    lin.residual.resize(rows);
    if (!cost.Evaluate(res.blocks.data(), lin.residual.data(), jacobian_ptrs.data())) {
      throw std::runtime_error("MarginalizationInfo::linearize: a residual block failed to evaluate");
    }
    // Tangent Jacobian = ambient Jacobian * PlusJacobian; PoseManifold's is [I6; 0], so a pose block's
    // tangent Jacobian is its first 6 columns (parameter_layout.hpp).
    lin.jacobians.reserve(sizes.size());
    for (size_t i = 0; i < sizes.size(); ++i) lin.jacobians.emplace_back(ambient[i].leftCols(tangentSize(sizes[i])));
    if (res.loss) applyLoss(*res.loss, lin.residual, lin.jacobians);
    linearizations_.push_back(std::move(lin));
  }
  x0_.clear();
  for (double* block : blocks_) {
    x0_.emplace(block, Eigen::Map<const Eigen::VectorXd>(block, block_size_.at(block)));
  }
  linearized_ = true;
}

void MarginalizationInfo::marginalize() {
  if (!linearized_) throw std::logic_error("MarginalizationInfo::marginalize before linearize()");

  // Column layout: dropped blocks first (in order of appearance), then the kept ones.
  std::unordered_map<const double*, int> offset;
  int dropped_size = 0;
  for (double* block : blocks_) {
    if (!dropped_.count(block)) continue;
    offset[block] = dropped_size;
    dropped_size += tangentSize(block_size_.at(block));
  }
  kept_blocks_.clear();
  kept_sizes_.clear();
  kept_tangent_offsets_.clear();
  kept_x0_.clear();
  int total = dropped_size;
  for (double* block : blocks_) {
    if (dropped_.count(block)) continue;
    const int size = block_size_.at(block);
    offset[block] = total;
    kept_blocks_.push_back(block);
    kept_sizes_.push_back(size);
    kept_tangent_offsets_.push_back(total - dropped_size);
    kept_x0_.push_back(x0_.at(block));
    total += tangentSize(size);
  }
  kept_tangent_size_ = total - dropped_size;
  if (kept_blocks_.empty()) throw std::runtime_error("MarginalizationInfo::marginalize: no block is kept");

  // Gauss-Newton system H = Σ J^T J, b = Σ J^T r over all residual blocks.
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(total, total);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(total);
  for (size_t k = 0; k < residuals_.size(); ++k) {
    const Linearization& lin = linearizations_[k];
    const std::vector<double*>& blocks = residuals_[k].blocks;
    for (size_t i = 0; i < blocks.size(); ++i) {
      const Eigen::MatrixXd& ji = lin.jacobians[i];
      const int oi = offset.at(blocks[i]);
      b.segment(oi, ji.cols()) += ji.transpose() * lin.residual;
      for (size_t j = 0; j < blocks.size(); ++j) {
        const Eigen::MatrixXd& jj = lin.jacobians[j];
        H.block(oi, offset.at(blocks[j]), ji.cols(), jj.cols()) += ji.transpose() * jj;
      }
    }
  }

  // Schur complement onto the kept blocks; H_mm is inverted through its eigen-decomposition so a
  // rank-deficient dropped block (e.g. an unobservable direction) is pseudo-inverted, not blown up.
  const int m = dropped_size;
  const int n = kept_tangent_size_;
  Eigen::MatrixXd schur = H.bottomRightCorner(n, n);
  Eigen::VectorXd schur_b = b.tail(n);
  if (m > 0) {
    const Eigen::MatrixXd hmm = 0.5 * (H.topLeftCorner(m, m) + H.topLeftCorner(m, m).transpose());
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(hmm);
    const Eigen::VectorXd inv = (eig.eigenvalues().array() > eigenvalue_threshold_)
                                    .select(eig.eigenvalues().array().inverse(), 0.0);
    const Eigen::MatrixXd hmm_inv = eig.eigenvectors() * inv.asDiagonal() * eig.eigenvectors().transpose();
    const Eigen::MatrixXd hkm_hmm_inv = H.bottomLeftCorner(n, m) * hmm_inv;
    schur -= hkm_hmm_inv * H.topRightCorner(m, n);
    schur_b -= hkm_hmm_inv * b.head(m);
  }
  schur = 0.5 * (schur + schur.transpose()).eval();

  // H* = V S V^T  ->  J = S^1/2 V^T, r0 = S^-1/2 V^T b* over the eigenvalues above the threshold.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(schur);
  std::vector<int> kept_directions;
  for (int i = 0; i < n; ++i) {
    if (eig.eigenvalues()(i) > eigenvalue_threshold_) kept_directions.push_back(i);
  }
  if (kept_directions.empty()) {
    throw std::runtime_error("MarginalizationInfo::marginalize: the prior carries no information");
  }
  const int rank = static_cast<int>(kept_directions.size());
  linearized_jacobian_.resize(rank, n);
  linearized_residual_.resize(rank);
  for (int row = 0; row < rank; ++row) {
    const int i = kept_directions[row];
    const double sqrt_s = std::sqrt(eig.eigenvalues()(i));
    const auto v = eig.eigenvectors().col(i);
    linearized_jacobian_.row(row) = sqrt_s * v.transpose();
    linearized_residual_(row) = v.dot(schur_b) / sqrt_s;
  }
  // The residual blocks (and whatever their costs hold, e.g. preintegrations) are no longer needed.
  linearizations_.clear();
  residuals_.clear();
}

std::vector<double*> MarginalizationInfo::keptBlocks(
    const std::unordered_map<const double*, double*>& shift) const {
  std::vector<double*> out;
  out.reserve(kept_blocks_.size());
  for (double* block : kept_blocks_) {
    const auto it = shift.find(block);
    out.push_back(it == shift.end() ? block : it->second);
  }
  return out;
}

}  // namespace dynavins::estimator
