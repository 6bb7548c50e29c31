#include "stages/tracker/patch_template.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/LU>

namespace dynavins::tracker {

namespace {

constexpr int kR = PatchTemplate::kRadius;
constexpr int kN = PatchTemplate::kPixels;
using PatchVector = Eigen::Matrix<float, kN, 1>;

/// Bilinear sample of an 8-bit image; the caller keeps (x, y) inside [0, cols-1) x [0, rows-1).
inline float sample(const cv::Mat& img, float x, float y) {
  const int c = static_cast<int>(x), r = static_cast<int>(y);
  const float a = x - static_cast<float>(c), b = y - static_cast<float>(r);
  const uint8_t* p0 = img.ptr<uint8_t>(r) + c;
  const uint8_t* p1 = p0 + img.step[0];
  return (1 - b) * ((1 - a) * p0[0] + a * p0[1]) + b * ((1 - a) * p1[0] + a * p1[1]);
}

/// Whether every pixel of the patch warped by (A, t), grown by `margin` patch pixels, samples inside.
bool inside(const cv::Mat& img, const Eigen::Matrix2f& A, const Eigen::Vector2f& t, int margin) {
  const float e = static_cast<float>(kR + margin);
  for (float su : {-e, e})
    for (float sv : {-e, e}) {
      const Eigen::Vector2f p = A * Eigen::Vector2f(su, sv) + t;
      if (!(p.x() >= 0.f && p.y() >= 0.f && p.x() < img.cols - 1.f && p.y() < img.rows - 1.f)) return false;
    }
  return true;
}

/// Zero mean, unit norm; returns the norm it divided by, or 0 when the patch is flat.
float normalise(PatchVector* v) {
  v->array() -= v->mean();
  const float n = v->norm();
  if (!(n > 1e-3f * std::sqrt(static_cast<float>(kN)))) return 0.f;  // under ~0.001 gray level rms
  *v /= n;
  return n;
}

}  // namespace

float image_noise_sigma(const cv::Mat& gray) {
  if (gray.type() != CV_8UC1 || gray.rows < 3 || gray.cols < 3) return 0.f;
  // sum |I * M| over the interior, M = [1 -2 1; -2 4 -2; 1 -2 1]; every fourth row is plenty.
  double sum = 0;
  long n = 0;
  for (int r = 1; r + 1 < gray.rows; r += 4) {
    const uint8_t *a = gray.ptr<uint8_t>(r - 1), *b = gray.ptr<uint8_t>(r), *c = gray.ptr<uint8_t>(r + 1);
    // An integer sum per row (exact, and it vectorises): |I * M| <= 16 * 255, so int holds 500k columns.
    int row = 0;
    for (int x = 1; x + 1 < gray.cols; ++x) {
      const int v = (a[x - 1] + a[x + 1] + c[x - 1] + c[x + 1]) - 2 * (a[x] + c[x] + b[x - 1] + b[x + 1]) + 4 * b[x];
      row += std::abs(v);
    }
    sum += row;
    n += gray.cols - 2;
  }
  return static_cast<float>(std::sqrt(M_PI / 2.0) * sum / (6.0 * static_cast<double>(n)));
}

float AffineWarp::scale() const { return std::sqrt(std::abs(A.determinant())); }

std::shared_ptr<const PatchTemplate> capture_patch(const cv::Mat& gray, const Eigen::Vector2f& px) {
  if (gray.type() != CV_8UC1 || !inside(gray, Eigen::Matrix2f::Identity(), px, 1)) return nullptr;
  // The patch with a one-pixel rim for the central-difference gradients.
  constexpr int kS = PatchTemplate::kSide + 2;
  Eigen::Matrix<float, kS, kS, Eigen::RowMajor> big;
  for (int v = 0; v < kS; ++v)
    for (int u = 0; u < kS; ++u) big(v, u) = sample(gray, px.x() + static_cast<float>(u - kR - 1), px.y() + static_cast<float>(v - kR - 1));
  PatchVector value;
  for (int v = 0; v < PatchTemplate::kSide; ++v)
    for (int u = 0; u < PatchTemplate::kSide; ++u) value(v * PatchTemplate::kSide + u) = big(v + 1, u + 1);
  const float norm = normalise(&value);
  if (norm == 0.f) return nullptr;

  auto t = std::make_shared<PatchTemplate>();
  for (int v = -kR; v <= kR; ++v)
    for (int u = -kR; u <= kR; ++u) {
      const int k = (v + kR) * PatchTemplate::kSide + (u + kR);
      const float gx = 0.5f * (big(v + kR + 1, u + kR + 2) - big(v + kR + 1, u + kR)) / norm;
      const float gy = 0.5f * (big(v + kR + 2, u + kR + 1) - big(v + kR, u + kR + 1)) / norm;
      const float fu = static_cast<float>(u), fv = static_cast<float>(v);
      // d T(W(x; p)) / dp at p = 0 for W(x; p) = (I + D) x + t, p = (t_x, t_y, D00, D01, D10, D11).
      t->steepest_descent.col(k) << gx, gy, gx * fu, gx * fv, gy * fu, gy * fv;
    }
  // Project out the appearance directions the normalisation removes (offset and gain), so the
  // Jacobian matches the normalised residual.
  for (int i = 0; i < 6; ++i) {
    auto row = t->steepest_descent.row(i);
    row.array() -= row.mean();
    row -= row.dot(value.transpose()) * value.transpose();
  }
  const Eigen::Matrix<float, 6, 6> H = t->steepest_descent * t->steepest_descent.transpose();
  Eigen::FullPivLU<Eigen::Matrix<float, 6, 6>> lu(H);
  if (!lu.isInvertible()) return nullptr;
  t->hessian_inverse = lu.inverse();
  Eigen::Map<PatchVector>(t->value.data()) = value;
  t->contrast = norm;
  return t;
}

RefineOutcome refine_patch(const PatchTemplate& tmpl, const cv::Mat& gray, AffineWarp* warp, float noise_sigma,
                          int max_iterations, float epsilon) {
  const Eigen::Map<const PatchVector> T(tmpl.value.data());
  PatchVector I;
  RefineOutcome out;
  for (int it = 0; it < max_iterations; ++it) {
    out.iterations = it + 1;
    if (!inside(gray, warp->A, warp->t, 0)) {
      out.result = RefineResult::OutOfImage;
      return out;
    }
    // Warp the current image onto the template grid, row by row.
    for (int v = -kR; v <= kR; ++v) {
      Eigen::Vector2f p = warp->A * Eigen::Vector2f(static_cast<float>(-kR), static_cast<float>(v)) + warp->t;
      const Eigen::Vector2f step = warp->A.col(0);
      float* out = I.data() + (v + kR) * PatchTemplate::kSide;
      for (int u = 0; u < PatchTemplate::kSide; ++u, p += step) out[u] = sample(gray, p.x(), p.y());
    }
    if (normalise(&I) == 0.f) return out;
    out.ncc = I.dot(T);
    // Inverse compositional step: dp minimises |T(W(x; dp)) - I(W(x; p))|^2; then W <- W o W(dp)^-1.
    const Eigen::Matrix<float, 6, 1> dp = tmpl.hessian_inverse * (tmpl.steepest_descent * (I - T));
    // The update cannot settle below the estimate's own noise (Gauss-Newton covariance: the image
    // noise, in template units, times the translation block of H^-1): a clean patch has to settle to
    // `epsilon`, a weak texture under sensor noise stops earlier instead of counting as divergence.
    const float sigma = noise_sigma / tmpl.contrast;
    const float settle =
        std::max(epsilon, sigma * std::sqrt(tmpl.hessian_inverse(0, 0) + tmpl.hessian_inverse(1, 1)));
    Eigen::Matrix2f B;
    B << 1.f + dp(2), dp(3), dp(4), 1.f + dp(5);
    const float det = B.determinant();
    if (!std::isfinite(det) || std::abs(det) < 1e-3f) return out;
    const Eigen::Matrix2f A = warp->A * B.inverse();
    const Eigen::Vector2f move = A * dp.head<2>();
    warp->A = A;
    warp->t -= move;
    const float s = warp->scale();
    if (!(s > 0.25f && s < 4.f)) return out;
    if (move.norm() < settle) {
      out.result = RefineResult::Converged;
      return out;
    }
  }
  return out;
}

}  // namespace dynavins::tracker
