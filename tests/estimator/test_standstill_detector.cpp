// check_standstill: a camera that only rotates is at rest, one that moves a few centimetres is not, a
// moving object filling most of the view hides the standstill until the robust BA rejects its features,
// and the speed and feature-count guards hold. Geometry is exact (projections of known points).
#include <catch2/catch.hpp>

#include <random>

#include "stages/common/so3.hpp"
#include "stages/estimator/standstill_detector.hpp"

using namespace dynavins;
using namespace dynavins::estimator;

namespace {

struct Camera {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  ///< R_wc
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
};

TrackedFeature observe(int64_t id, const Camera& c, const Eigen::Vector3d& p_w) {
  const Eigen::Vector3d p_c = c.R.transpose() * (p_w - c.p);
  TrackedFeature t;
  t.id = id;
  t.xy = p_c.head<2>() / p_c.z();
  t.px = kNominalFocalPx * t.xy + Eigen::Vector2d(376, 240);
  return t;
}

/// Two frames of `n_static` static points 3-10 m ahead, plus `n_moving` points of an object 3 m ahead that
/// moves `object_step` between the frames; the camera goes from `a` to `b`.
WindowFeatures two_frames(const Camera& a, const Camera& b, int n_static, int n_moving,
                         const Eigen::Vector3d& object_step) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> xy(-2, 2), z(3, 10);
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i < n_static + n_moving; ++i) pts.emplace_back(xy(rng), xy(rng), i < n_static ? z(rng) : 3.0);
  WindowFeatures wf;
  for (int slot = 0; slot < 2; ++slot) {
    TrackedFrame f;
    f.t_ns = slot * 50'000'000LL;
    for (int i = 0; i < n_static + n_moving; ++i) {
      const Eigen::Vector3d p = pts[i] + (i >= n_static && slot == 1 ? object_step : Eigen::Vector3d::Zero());
      f.features.push_back(observe(i, slot == 0 ? a : b, p));
    }
    wf.add_frame(slot, f, 10.0 / kNominalFocalPx, false);
  }
  return wf;
}

Eigen::Matrix3d prev_from_new(const Camera& a, const Camera& b) { return a.R.transpose() * b.R; }

}  // namespace

TEST_CASE("check_standstill: a rotating camera stands still, a translating one does not", "[standstill]") {
  const StandstillOptions o;
  Camera a, b;
  b.R = so3::exp(Eigen::Vector3d(0.01, 0.03, -0.02));  // ~2 degrees in 50 ms, no translation
  const StandstillCheck rot = check_standstill(two_frames(a, b, 60, 0, Eigen::Vector3d::Zero()), 1, prev_from_new(a, b), 0.0, o);
  CHECK(rot.still);
  CHECK(rot.features == 60);
  CHECK(rot.median_disparity_px < 1e-9);

  b.p = Eigen::Vector3d(0.03, 0, 0);  // 3 cm sideways (0.6 m/s at 20 Hz): several pixels at 3-10 m
  const StandstillCheck moved = check_standstill(two_frames(a, b, 60, 0, Eigen::Vector3d::Zero()), 1, prev_from_new(a, b), 0.0, o);
  CHECK_FALSE(moved.still);
  CHECK(moved.median_disparity_px > 1.0);
}

TEST_CASE("check_standstill: a moving object hides the standstill until its features are rejected", "[standstill]") {
  const StandstillOptions o;
  const Camera a, b;
  // 80 of 110 features on an object moving 10 cm between the frames (2 m/s) 3 m ahead.
  WindowFeatures wf = two_frames(a, b, 30, 80, Eigen::Vector3d(0.1, 0, 0));
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  CHECK_FALSE(check_standstill(wf, 1, I, 0.0, o).still);
  for (auto& [id, f] : wf.all())
    if (id >= 30) f.weight = 0.05;  // what the robust BA does to them
  const StandstillCheck c = check_standstill(wf, 1, I, 0.0, o);
  CHECK(c.still);
  CHECK(c.features == 30);
}

TEST_CASE("check_standstill: speed, feature count and the switch guard the decision", "[standstill]") {
  StandstillOptions o;
  const Camera a, b;
  const WindowFeatures wf = two_frames(a, b, 60, 0, Eigen::Vector3d::Zero());
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  CHECK(check_standstill(wf, 1, I, 0.05, o).still);
  CHECK_FALSE(check_standstill(wf, 1, I, 0.5, o).still);  // the last solve says it moves
  const WindowFeatures few = two_frames(a, b, o.min_features - 1, 0, Eigen::Vector3d::Zero());
  CHECK_FALSE(check_standstill(few, 1, I, 0.0, o).still);
  CHECK_FALSE(check_standstill(wf, 0, I, 0.0, o).still);  // no previous frame
  o.enabled = false;
  const StandstillCheck off = check_standstill(wf, 1, I, 0.0, o);
  CHECK_FALSE(off.still);
  CHECK(off.features == 60);  // still measured, for the log
}
