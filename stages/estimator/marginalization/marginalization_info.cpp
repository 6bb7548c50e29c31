#include "stages/estimator/marginalization/marginalization_info.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Eigenvalues>

#include "stages/estimator/parameter_layout.hpp"

namespace dynavins::estimator {

namespace {

using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using ConstMap = Eigen::Map<const Eigen::MatrixXd>;
using MutMap = Eigen::Map<Eigen::MatrixXd>;

/// Applies a robust loss to a residual and its Jacobians the way Ceres' internal Corrector does
/// (ceres/internal/corrector.cc; Triggs et al. 2000, §4.3): with s = |r|^2 and rho = (ρ, ρ', ρ''),
///   ρ'' <= 0 (Huber, Cauchy, ...):  r <- sqrt(ρ') r,            J <- sqrt(ρ') J
///   ρ'' >  0:  α = 1 - sqrt(1 + 2 s ρ''/ρ'),  r <- sqrt(ρ')/(1-α) r,  J <- sqrt(ρ') (I - α r r^T/s) J
/// so that (J^T J, J^T r) is the Hessian/gradient the solver itself forms for that residual.
/// `jacobian` holds every block's tangent Jacobian side by side (rows x total tangent columns).
void apply_loss(const ceres::LossFunction& loss, Eigen::Map<Eigen::VectorXd> r, MutMap jacobian) {
  const double sq_norm = r.squaredNorm();
  double rho[3];
  loss.Evaluate(sq_norm, rho);
  if (!(rho[1] > 0.0)) {
    // ρ' = 0 (e.g. Tukey beyond its scale): the residual carries no information here.
    r.setZero();
    jacobian.setZero();
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
  if (alpha_sq_norm != 0.0) {
    const Eigen::RowVectorXd rt_j = r.transpose() * jacobian;
    jacobian = sqrt_rho1 * (jacobian - alpha_sq_norm * r * rt_j);
  } else {
    jacobian *= sqrt_rho1;
  }
  r *= residual_scaling;
}

}  // namespace

MarginalizationInfo::MarginalizationInfo(double eigenvalue_threshold)
    : eigenvalue_threshold_(eigenvalue_threshold) {}

int MarginalizationInfo::tangent_size(int ambient_size) {
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
  std::vector<int> indices(sizes.size());
  for (size_t i = 0; i < sizes.size(); ++i) {
    double* block = residual.blocks[i];
    if (block == nullptr) throw std::invalid_argument("MarginalizationInfo::add: null parameter block");
    const auto [it, inserted] = block_index_.emplace(block, static_cast<int>(blocks_.size()));
    if (inserted) {
      blocks_.push_back(block);
      sizes_.push_back(sizes[i]);
      is_dropped_.push_back(0);
    } else if (sizes_[it->second] != sizes[i]) {
      throw std::invalid_argument("MarginalizationInfo::add: block seen with sizes " +
                                  std::to_string(sizes_[it->second]) + " and " + std::to_string(sizes[i]));
    }
    indices[i] = it->second;
  }
  for (int d : residual.drop) {
    if (d < 0 || d >= static_cast<int>(residual.blocks.size())) {
      throw std::invalid_argument("MarginalizationInfo::add: drop index " + std::to_string(d) + " out of range");
    }
    is_dropped_[indices[d]] = 1;
  }
  residual_blocks_.push_back(std::move(indices));
  residuals_.push_back(std::move(residual));
}

void MarginalizationInfo::linearize() {
  // Buffer layout per residual: residual (rows), then the tangent Jacobians side by side (column-major
  // rows x Σ tangent sizes, i.e. block after block).
  size_t total = 0;
  lin_offset_.resize(residuals_.size());
  for (size_t k = 0; k < residuals_.size(); ++k) {
    lin_offset_[k] = total;
    int cols = 0;
    for (int b : residual_blocks_[k]) cols += tangent_size(sizes_[b]);
    total += static_cast<size_t>(residuals_[k].cost->num_residuals()) * (1 + cols);
  }
  lin_data_.assign(total, 0.0);
  std::vector<double> ambient;  // row-major ambient Jacobians of one residual, reused
  std::vector<double*> jacobian_ptrs;
  for (size_t k = 0; k < residuals_.size(); ++k) {
    const ResidualBlockInfo& res = residuals_[k];
    const ceres::CostFunction& cost = *res.cost;
    const std::vector<int>& blocks = residual_blocks_[k];
    const int rows = cost.num_residuals();
    int ambient_cols = 0, tangent_cols = 0;
    for (int b : blocks) {
      ambient_cols += sizes_[b];
      tangent_cols += tangent_size(sizes_[b]);
    }
    ambient.assign(static_cast<size_t>(rows) * ambient_cols, 0.0);
    jacobian_ptrs.resize(blocks.size());
    for (size_t i = 0, o = 0; i < blocks.size(); ++i) {
      jacobian_ptrs[i] = ambient.data() + o;
      o += static_cast<size_t>(rows) * sizes_[blocks[i]];
    }
    double* residual = lin_data_.data() + lin_offset_[k];
    if (!cost.Evaluate(res.blocks.data(), residual, jacobian_ptrs.data())) {
      throw std::runtime_error("MarginalizationInfo::linearize: a residual block failed to evaluate");
    }
    // Tangent Jacobian = ambient Jacobian * PlusJacobian; PoseManifold's is [I6; 0], so a pose block's
    // tangent Jacobian is its first 6 columns (parameter_layout.hpp).
    double* tangent = residual + rows;
    for (size_t i = 0; i < blocks.size(); ++i) {
      const int size = sizes_[blocks[i]];
      const int t = tangent_size(size);
      MutMap(tangent, rows, t) = Eigen::Map<const RowMajorMatrix>(jacobian_ptrs[i], rows, size).leftCols(t);
      tangent += static_cast<size_t>(rows) * t;
    }
    if (res.loss) {
      apply_loss(*res.loss, Eigen::Map<Eigen::VectorXd>(residual, rows), MutMap(residual + rows, rows, tangent_cols));
    }
  }
  x0_.clear();
  x0_.reserve(blocks_.size());
  for (size_t i = 0; i < blocks_.size(); ++i) x0_.emplace_back(Eigen::Map<const Eigen::VectorXd>(blocks_[i], sizes_[i]));
  linearized_ = true;
}

/// A scalar dropped block d couples (through its residuals) with a few dense blocks only, and with no
/// other scalar block, so its row of H is h_dd, the coupling c_d = H_{dense,d} over those blocks, b_d.
struct MarginalizationInfo::ScalarBlock {
  double h = 0.0, b = 0.0;
  std::vector<int> neighbours;  ///< dense block indices
  std::vector<int> local;       ///< offset of each neighbour in c
  Eigen::VectorXd c;
};

namespace {
/// Copies the upper triangle of a square matrix into its lower one.
void mirror_upper_triangle(Eigen::MatrixXd& H) {
  const int total = static_cast<int>(H.rows());
  for (int j = 0; j < total; ++j) {
    for (int i = j + 1; i < total; ++i) H(i, j) = H(j, i);
  }
}
}  // namespace

int MarginalizationInfo::dense_column_offsets(const std::vector<char>& scalar, std::vector<int>& offset,
                                            int& dropped_dense_size) const {
  const int num_blocks = static_cast<int>(blocks_.size());
  // Non-scalar dropped blocks first (in order of appearance), then the kept ones; scalar ones get -1.
  offset.assign(num_blocks, -1);
  int total = 0;
  for (int i = 0; i < num_blocks; ++i) {
    if (is_dropped_[i] && !scalar[i]) {
      offset[i] = total;
      total += tangent_size(sizes_[i]);
    }
  }
  dropped_dense_size = total;
  for (int i = 0; i < num_blocks; ++i) {
    if (!is_dropped_[i]) {
      offset[i] = total;
      total += tangent_size(sizes_[i]);
    }
  }
  return total;
}

std::vector<MarginalizationInfo::ScalarBlock> MarginalizationInfo::scalar_blocks(
    const std::vector<char>& scalar, std::vector<int>& scalar_id, std::vector<int>& residual_scalar) const {
  const int num_blocks = static_cast<int>(blocks_.size());
  scalar_id.assign(num_blocks, -1);
  std::vector<ScalarBlock> scalars;
  for (int i = 0; i < num_blocks; ++i) {
    if (scalar[i]) {
      scalar_id[i] = static_cast<int>(scalars.size());
      scalars.emplace_back();
    }
  }
  residual_scalar.assign(residuals_.size(), -1);
  for (size_t k = 0; k < residuals_.size(); ++k) {
    const std::vector<int>& blocks = residual_blocks_[k];
    for (size_t i = 0; i < blocks.size(); ++i) {
      if (scalar_id[blocks[i]] >= 0) residual_scalar[k] = static_cast<int>(i);
    }
    if (residual_scalar[k] < 0) continue;
    ScalarBlock& s = scalars[scalar_id[blocks[residual_scalar[k]]]];
    for (int blk : blocks) {
      if (scalar_id[blk] >= 0) continue;
      if (std::find(s.neighbours.begin(), s.neighbours.end(), blk) == s.neighbours.end()) s.neighbours.push_back(blk);
    }
  }
  for (ScalarBlock& s : scalars) {
    int n = 0;
    s.local.resize(s.neighbours.size());
    for (size_t j = 0; j < s.neighbours.size(); ++j) {
      s.local[j] = n;
      n += tangent_size(sizes_[s.neighbours[j]]);
    }
    s.c = Eigen::VectorXd::Zero(n);
  }
  return scalars;
}

void MarginalizationInfo::accumulate_normal_equations(const std::vector<int>& offset, const std::vector<int>& scalar_id,
                                                    const std::vector<int>& residual_scalar,
                                                    std::vector<ScalarBlock>& scalars, Eigen::MatrixXd& H,
                                                    Eigen::VectorXd& b) const {
  std::vector<int> col;  // per block of the residual: column in its Jacobian buffer
  for (size_t k = 0; k < residuals_.size(); ++k) {
    const std::vector<int>& blocks = residual_blocks_[k];
    const int rows = residuals_[k].cost->num_residuals();
    const double* data = lin_data_.data() + lin_offset_[k];
    const Eigen::Map<const Eigen::VectorXd> r(data, rows);
    const double* jac = data + rows;
    col.resize(blocks.size());
    for (size_t i = 0, c = 0; i < blocks.size(); ++i) {
      col[i] = static_cast<int>(c);
      c += tangent_size(sizes_[blocks[i]]);
    }
    auto J = [&](size_t i) {
      return ConstMap(jac + static_cast<size_t>(rows) * col[i], rows, tangent_size(sizes_[blocks[i]]));
    };
    const int si = residual_scalar[k];
    for (size_t i = 0; i < blocks.size(); ++i) {
      if (static_cast<int>(i) == si) continue;
      const auto ji = J(i);
      const int oi = offset[blocks[i]];
      b.segment(oi, ji.cols()).noalias() += ji.transpose() * r;
      for (size_t j = 0; j < blocks.size(); ++j) {
        if (static_cast<int>(j) == si) continue;
        const int oj = offset[blocks[j]];
        if (oj < oi) continue;
        const auto jj = J(j);
        H.block(oi, oj, ji.cols(), jj.cols()).noalias() += ji.transpose() * jj;
      }
    }
    if (si >= 0) {
      ScalarBlock& s = scalars[scalar_id[blocks[si]]];
      const auto jd = J(si);  // rows x 1
      s.h += jd.squaredNorm();
      s.b += jd.col(0).dot(r);
      for (size_t j = 0; j < blocks.size(); ++j) {
        if (static_cast<int>(j) == si) continue;
        const auto jj = J(j);
        const size_t n = std::find(s.neighbours.begin(), s.neighbours.end(), blocks[j]) - s.neighbours.begin();
        s.c.segment(s.local[n], jj.cols()).noalias() += jj.transpose() * jd.col(0);
      }
    }
  }
}

bool MarginalizationInfo::eliminate_scalar_blocks(const std::vector<ScalarBlock>& scalars, const std::vector<int>& offset,
                                                Eigen::MatrixXd& H, Eigen::VectorXd& b) const {
  // H -= c c^T / h_dd, b -= c b_d / h_dd (H_dd is diagonal over the scalar blocks).
  for (const ScalarBlock& s : scalars) {
    if (!(s.h > eigenvalue_threshold_)) return false;
    const double inv_h = 1.0 / s.h;
    const Eigen::VectorXd c_scaled = s.c * inv_h;
    for (size_t i = 0; i < s.neighbours.size(); ++i) {
      const int oi = offset[s.neighbours[i]];
      const int ti = tangent_size(sizes_[s.neighbours[i]]);
      const auto ci = s.c.segment(s.local[i], ti);
      b.segment(oi, ti) -= ci * (s.b * inv_h);
      for (size_t j = 0; j < s.neighbours.size(); ++j) {
        const int oj = offset[s.neighbours[j]];
        if (oj < oi) continue;
        const int tj = tangent_size(sizes_[s.neighbours[j]]);
        H.block(oi, oj, ti, tj).noalias() -= ci * c_scaled.segment(s.local[j], tj).transpose();
      }
    }
  }
  return true;
}

bool MarginalizationInfo::assemble(const std::vector<char>& scalar, Eigen::MatrixXd& H, Eigen::VectorXd& b,
                                   int& dropped_dense_size) const {
  std::vector<int> offset;
  const int total = dense_column_offsets(scalar, offset, dropped_dense_size);
  std::vector<int> scalar_id, residual_scalar;
  std::vector<ScalarBlock> scalars = scalar_blocks(scalar, scalar_id, residual_scalar);
  // Gauss-Newton system H = Σ J^T J, b = Σ J^T r over all residual blocks; the dense part in its upper
  // triangle (blocks above the diagonal, diagonal blocks whole), mirrored below once the scalar blocks
  // are eliminated.
  H.setZero(total, total);
  b.setZero(total);
  accumulate_normal_equations(offset, scalar_id, residual_scalar, scalars, H, b);
  if (!eliminate_scalar_blocks(scalars, offset, H, b)) return false;
  mirror_upper_triangle(H);
  return true;
}

void MarginalizationInfo::marginalize() {
  if (!linearized_) throw std::logic_error("MarginalizationInfo::marginalize before linearize()");

  kept_blocks_.clear();
  kept_sizes_.clear();
  kept_tangent_offsets_.clear();
  kept_x0_.clear();
  kept_tangent_size_ = 0;
  for (size_t i = 0; i < blocks_.size(); ++i) {
    if (is_dropped_[i]) continue;
    kept_blocks_.push_back(blocks_[i]);
    kept_sizes_.push_back(sizes_[i]);
    kept_tangent_offsets_.push_back(kept_tangent_size_);
    kept_x0_.push_back(x0_[i]);
    kept_tangent_size_ += tangent_size(sizes_[i]);
  }
  if (kept_blocks_.empty()) throw std::runtime_error("MarginalizationInfo::marginalize: no block is kept");

  // Dropped blocks of tangent size 1 that share no residual with another such block (the inverse depths
  // of the features anchored in the dropped frame) have a diagonal H_dd: they are eliminated one by one
  // while H is formed, which is the same Schur complement (H_dd is positive definite; H is positive
  // semi-definite, so the rest of H_mm's pseudo-inverse is unaffected) without the dense m x m work.
  std::vector<char> scalar(blocks_.size(), 0);
  for (size_t i = 0; i < blocks_.size(); ++i) scalar[i] = is_dropped_[i] && tangent_size(sizes_[i]) == 1;
  for (const std::vector<int>& blocks : residual_blocks_) {
    int count = 0;
    for (int blk : blocks) count += scalar[blk] ? 1 : 0;
    if (count > 1) {
      for (int blk : blocks) scalar[blk] = 0;
    }
  }
  Eigen::MatrixXd H;
  Eigen::VectorXd b;
  int m = 0;
  if (!assemble(scalar, H, b, m)) {
    std::fill(scalar.begin(), scalar.end(), 0);
    assemble(scalar, H, b, m);  // a scalar block without information: pseudo-invert it with the rest
  }

  // Schur complement onto the kept blocks; H_mm is inverted through its eigen-decomposition so a
  // rank-deficient dropped block (e.g. an unobservable direction) is pseudo-inverted, not blown up.
  const int n = kept_tangent_size_;
  Eigen::MatrixXd schur = H.bottomRightCorner(n, n);
  Eigen::VectorXd schur_b = b.tail(n);
  if (m > 0) {
    const Eigen::MatrixXd hmm = 0.5 * (H.topLeftCorner(m, m) + H.topLeftCorner(m, m).transpose());
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(hmm);
    const Eigen::VectorXd inv = (eig.eigenvalues().array() > eigenvalue_threshold_)
                                    .select(eig.eigenvalues().array().inverse(), 0.0);
    const Eigen::MatrixXd hmm_inv = eig.eigenvectors() * inv.asDiagonal() * eig.eigenvectors().transpose();
    Eigen::MatrixXd hkm_hmm_inv(n, m);
    hkm_hmm_inv.noalias() = H.bottomLeftCorner(n, m) * hmm_inv;
    schur.noalias() -= hkm_hmm_inv * H.topRightCorner(m, n);
    schur_b.noalias() -= hkm_hmm_inv * b.head(m);
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
  lin_data_.clear();
  lin_data_.shrink_to_fit();
  lin_offset_.clear();
  residual_blocks_.clear();
  residuals_.clear();
}

std::vector<double*> MarginalizationInfo::kept_blocks(
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
