#pragma once
// Radial-tangential (Brown-Conrady, k1 k2 p1 p2) distortion on the normalized plane, shared by the
// pinhole and MEI models exactly as camodocs and OpenCV (k3 = 0) apply it.

#include <Eigen/Core>
#include <Eigen/LU>

namespace dynavins {

struct RadtanDistortion {
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0;

  /// Undistorted -> distorted normalized point; fills d(out)/d(m) when `J` is not null.
  Eigen::Vector2d distort(const Eigen::Vector2d& m, Eigen::Matrix2d* J = nullptr) const {
    const double x = m.x(), y = m.y();
    const double xx = x * x, yy = y * y, xy = x * y, r2 = xx + yy;
    const double rad = 1.0 + k1 * r2 + k2 * r2 * r2;
    const Eigen::Vector2d out(x * rad + 2 * p1 * xy + p2 * (r2 + 2 * xx),
                              y * rad + p1 * (r2 + 2 * yy) + 2 * p2 * xy);
    if (J) {
      const double drad = k1 + 2 * k2 * r2;  // d(rad)/d(r2)
      (*J)(0, 0) = rad + 2 * xx * drad + 2 * p1 * y + 6 * p2 * x;
      (*J)(0, 1) = 2 * xy * drad + 2 * p1 * x + 2 * p2 * y;
      (*J)(1, 0) = 2 * xy * drad + 2 * p1 * x + 2 * p2 * y;
      (*J)(1, 1) = rad + 2 * yy * drad + 6 * p1 * y + 2 * p2 * x;
    }
    return out;
  }

  /// Distorted -> undistorted by Gauss-Newton (camodocs' fixed-point recursion drifts at the borders).
  Eigen::Vector2d undistort(const Eigen::Vector2d& d) const {
    Eigen::Vector2d m = d;
    for (int i = 0; i < 30; ++i) {
      Eigen::Matrix2d J;
      const Eigen::Vector2d r = distort(m, &J) - d;
      if (r.squaredNorm() < 1e-26) break;
      m -= J.lu().solve(r);
    }
    return m;
  }
};

}  // namespace dynavins
