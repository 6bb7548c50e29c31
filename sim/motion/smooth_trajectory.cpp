#include "sim/motion/smooth_trajectory.hpp"

#include <stdexcept>

namespace dynavins::sim {

SmoothTrajectory::SmoothTrajectory(BSplineR3 position, BSplineSO3 orientation)
    : pos_(std::move(position)), rot_(std::move(orientation)) {
  const UniformKnots& a = pos_.knots();
  const UniformKnots& b = rot_.knots();
  if (a.num_control() != b.num_control() || a.t0() != b.t0() || a.dt() != b.dt())
    throw std::invalid_argument("SmoothTrajectory: position and orientation splines must share one knot grid");
}

KinematicState SmoothTrajectory::evaluate(double t) const {
  const SplineR3Value p = pos_.evaluate(t);
  const SplineSO3Value r = rot_.evaluate(t);
  KinematicState s;
  s.t = t;
  s.p_w = p.p;
  s.v_w = p.v;
  s.a_w = p.a;
  s.j_w = p.j;
  s.R_wb = r.R;
  s.omega_b = r.omega;
  s.alpha_b = r.alpha;
  return s;
}

Eigen::Isometry3d SmoothTrajectory::pose(double t) const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = rotation(t);
  T.translation() = position(t);
  return T;
}

SmoothTrajectory SmoothTrajectory::shifted_in_time(double offset) const {
  const UniformKnots& k = pos_.knots();
  return SmoothTrajectory(BSplineR3(k.t0() + offset, k.dt(), pos_.control()),
                          BSplineSO3(k.t0() + offset, k.dt(), rot_.control()));
}

}  // namespace dynavins::sim
