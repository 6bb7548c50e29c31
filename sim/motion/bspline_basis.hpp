#pragma once
// Uniform cubic B-spline basis in matrix form, and its cumulative version for Lie groups.
// Source: Qin, "General matrix representations for B-splines" (2000); cumulative form as used by
// Lovegrove et al., "Spline Fusion" (BMVC 2013), eq. (4), and Sommer et al., "Efficient Derivative
// Computation for Cumulative B-Splines on Lie Groups" (CVPR 2020), eqs. (3)-(6).
//
// On a segment with normalised time u in [0, 1] and control points c0..c3:
//   value      = sum_j b_j(u) c_j,        b = M^T [1 u u^2 u^3]^T
//   cumulative = c0 + sum_{j=1..3} λ_j(u) (c_j - c_{j-1}),  λ_j = sum_{k>=j} b_k
// Derivatives w.r.t. time divide by dt, dt^2, dt^3.

#include <array>

namespace dynavins::sim::bspline {

/// Basis weights b0..b3 of a uniform cubic B-spline and their first three u-derivatives.
struct CubicBasis {
  std::array<double, 4> b{}, db{}, ddb{}, dddb{};
};

/// Evaluates the basis at u in [0, 1]. b = {(1-u)^3, 3u^3-6u^2+4, -3u^3+3u^2+3u+1, u^3} / 6.
inline CubicBasis cubic_basis(double u) {
  CubicBasis r;
  const double u2 = u * u, u3 = u2 * u, w = 1.0 - u;
  r.b = {w * w * w / 6.0, (3.0 * u3 - 6.0 * u2 + 4.0) / 6.0, (-3.0 * u3 + 3.0 * u2 + 3.0 * u + 1.0) / 6.0,
         u3 / 6.0};
  r.db = {-0.5 * w * w, 1.5 * u2 - 2.0 * u, -1.5 * u2 + u + 0.5, 0.5 * u2};
  r.ddb = {w, 3.0 * u - 2.0, 1.0 - 3.0 * u, u};
  r.dddb = {-1.0, 3.0, -3.0, 1.0};
  return r;
}

/// Cumulative weights λ1..λ3 (λ0 == 1) and their first two u-derivatives.
struct CumulativeBasis {
  std::array<double, 3> l{}, dl{}, ddl{};
};

/// λ1 = (5 + 3u - 3u^2 + u^3)/6, λ2 = (1 + 3u + 3u^2 - 2u^3)/6, λ3 = u^3/6.
inline CumulativeBasis cumulative_basis(double u) {
  const CubicBasis c = cubic_basis(u);
  CumulativeBasis r;
  for (int j = 2; j >= 0; --j) {
    const int k = j + 1;
    r.l[j] = c.b[k] + (j < 2 ? r.l[j + 1] : 0.0);
    r.dl[j] = c.db[k] + (j < 2 ? r.dl[j + 1] : 0.0);
    r.ddl[j] = c.ddb[k] + (j < 2 ? r.ddl[j + 1] : 0.0);
  }
  return r;
}

}  // namespace dynavins::sim::bspline
