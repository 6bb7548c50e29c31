#include "sim/render/camera_rays.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/LU>
#include <spdlog/spdlog.h>

namespace dynavins::sim {

Eigen::Vector2d distort_normalized(const CameraIntrinsics& c, const Eigen::Vector2d& xn,
                                   Eigen::Matrix2d* jacobian) {
  const double x = xn.x();
  const double y = xn.y();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + c.k1 * r2 + c.k2 * r2 * r2;
  const Eigen::Vector2d out(x * radial + 2.0 * c.p1 * x * y + c.p2 * (r2 + 2.0 * x * x),
                            y * radial + c.p1 * (r2 + 2.0 * y * y) + 2.0 * c.p2 * x * y);
  if (jacobian) {
    const double dr = 2.0 * (c.k1 + 2.0 * c.k2 * r2);  // d(radial)/d(x) = dr * x
    (*jacobian)(0, 0) = radial + dr * x * x + 2.0 * c.p1 * y + 6.0 * c.p2 * x;
    (*jacobian)(0, 1) = dr * x * y + 2.0 * c.p1 * x + 2.0 * c.p2 * y;
    (*jacobian)(1, 0) = dr * x * y + 2.0 * c.p1 * x + 2.0 * c.p2 * y;
    (*jacobian)(1, 1) = radial + dr * y * y + 6.0 * c.p1 * y + 2.0 * c.p2 * x;
  }
  return out;
}

Eigen::Vector2d project_point(const CameraIntrinsics& c, const Eigen::Vector3d& p) {
  const Eigen::Vector2d d = distort_normalized(c, Eigen::Vector2d(p.x() / p.z(), p.y() / p.z()));
  return {c.fx * d.x() + c.cx, c.fy * d.y() + c.cy};
}

bool undistort_pixel(const CameraIntrinsics& c, const Eigen::Vector2d& px, Eigen::Vector2d* xn,
                     double* residual_px) {
  const Eigen::Vector2d target((px.x() - c.cx) / c.fx, (px.y() - c.cy) / c.fy);
  Eigen::Vector2d x = target;  // the distortion is mild: start from the distorted point
  double err = std::numeric_limits<double>::infinity();
  for (int it = 0; it < 50; ++it) {
    Eigen::Matrix2d J;
    const Eigen::Vector2d f = distort_normalized(c, x, &J) - target;
    err = f.norm();
    if (err < 1e-15) break;
    const double det = J.determinant();
    if (!(std::abs(det) > 1e-12)) break;  // fold of the distortion: no reliable inverse here
    Eigen::Vector2d step = J.inverse() * f;
    // Newton can overshoot far from the centre; halve the step until the error shrinks.
    for (int k = 0; k < 30; ++k) {
      if ((distort_normalized(c, x - step) - target).norm() < err) break;
      step *= 0.5;
    }
    x -= step;
  }
  const Eigen::Vector2d f = distort_normalized(c, x) - target;
  const double res = std::hypot(f.x() * c.fx, f.y() * c.fy);
  if (residual_px) *residual_px = res;
  *xn = x;
  return std::isfinite(res) && res < 1e-6;
}

RayTable::RayTable(const CameraIntrinsics& cam) : cam_(cam) {
  const int w = cam.width;
  const int h = cam.height;
  const size_t n = static_cast<size_t>(w) * h;
  x_.resize(n);
  y_.resize(n);
  dxdu_.resize(n);
  dxdv_.resize(n);
  dydu_.resize(n);
  dydv_.resize(n);
  int failures = 0;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const size_t i = static_cast<size_t>(v) * w + u;
      Eigen::Vector2d xn;
      double res = 0.0;
      if (!undistort_pixel(cam, Eigen::Vector2d(u, v), &xn, &res)) {
        all_converged_ = false;
        ++failures;
      }
      max_residual_px_ = std::max(max_residual_px_, res);
      Eigen::Matrix2d J;
      distort_normalized(cam, xn, &J);
      // d(xn)/d(pixel) = J^-1 * diag(1/fx, 1/fy): the inverse function's derivative.
      const Eigen::Matrix2d Ji = J.inverse();
      x_[i] = static_cast<float>(xn.x());
      y_[i] = static_cast<float>(xn.y());
      dxdu_[i] = static_cast<float>(Ji(0, 0) / cam.fx);
      dxdv_[i] = static_cast<float>(Ji(0, 1) / cam.fy);
      dydu_[i] = static_cast<float>(Ji(1, 0) / cam.fx);
      dydv_[i] = static_cast<float>(Ji(1, 1) / cam.fy);
    }
  }
  if (failures > 0) {
    spdlog::warn("RayTable: distortion inversion failed at {} pixels (max residual {:.3g} px)", failures,
                 max_residual_px_);
  }

  cells_u_ = (w + kCell - 1) / kCell;
  cells_v_ = (h + kCell - 1) / kCell;
  cell_bounds_.resize(static_cast<size_t>(cells_u_) * cells_v_);
  const float inf = std::numeric_limits<float>::infinity();
  image_bounds_ = Eigen::Vector4f(inf, -inf, inf, -inf);
  for (int cv = 0; cv < cells_v_; ++cv) {
    for (int cu = 0; cu < cells_u_; ++cu) {
      Eigen::Vector4f b(inf, -inf, inf, -inf);
      for (int v = cv * kCell; v < std::min(h, (cv + 1) * kCell); ++v) {
        for (int u = cu * kCell; u < std::min(w, (cu + 1) * kCell); ++u) {
          const size_t i = static_cast<size_t>(v) * w + u;
          b[0] = std::min(b[0], x_[i]);
          b[1] = std::max(b[1], x_[i]);
          b[2] = std::min(b[2], y_[i]);
          b[3] = std::max(b[3], y_[i]);
        }
      }
      cell_bounds_[static_cast<size_t>(cv) * cells_u_ + cu] = b;
      image_bounds_[0] = std::min(image_bounds_[0], b[0]);
      image_bounds_[1] = std::max(image_bounds_[1], b[1]);
      image_bounds_[2] = std::min(image_bounds_[2], b[2]);
      image_bounds_[3] = std::max(image_bounds_[3], b[3]);
    }
  }
}

}  // namespace dynavins::sim
