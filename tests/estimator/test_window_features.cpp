// WindowFeatures: slot bookkeeping, keyframe decision, triangulation and re-anchoring against true geometry.
#include <catch2/catch.hpp>

#include <random>

#include "stages/common/so3.hpp"
#include "stages/estimator/window_features.hpp"

using namespace dynavins;
using namespace dynavins::estimator;

namespace {

/// A camera moving along x with a slight yaw, looking down +z, and fixed world points ahead.
struct Scene {
  std::vector<Eigen::Vector3d> points;
  CameraPose camera(int slot) const {
    CameraPose c;
    c.R = so3::exp(Eigen::Vector3d(0, 0.01 * slot, 0));
    c.p = Eigen::Vector3d(0.3 * slot, 0.02 * slot, 0);
    return c;
  }
  TrackedFrame frame(int slot, int first_id, int count, const Eigen::Isometry3d& T_c0c1) const {
    TrackedFrame f;
    f.t_ns = slot * 50'000'000LL;
    const CameraPose c = camera(slot);
    for (int i = first_id; i < first_id + count; ++i) {
      const Eigen::Vector3d p_c = c.R.transpose() * (points[i] - c.p);
      TrackedFeature t;
      t.id = i;
      t.xy = p_c.head<2>() / p_c.z();
      t.px = 460.0 * t.xy + Eigen::Vector2d(376, 240);
      const Eigen::Vector3d p_c1 = T_c0c1.inverse() * p_c;
      t.has_right = true;
      t.xy_right = p_c1.head<2>() / p_c1.z();
      t.sim_label = 0;
      f.features.push_back(t);
    }
    return f;
  }
};

Scene make_scene(int n) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> xy(-3, 3), z(4, 12);
  Scene s;
  for (int i = 0; i < n; ++i) s.points.emplace_back(xy(rng), xy(rng), z(rng));
  return s;
}

Eigen::Vector3d world_point(const WindowFeature& f, const CameraPose& anchor) {
  return anchor.R * (Eigen::Vector3d(f.obs[0].xy.x(), f.obs[0].xy.y(), 1.0) / f.inv_depth) + anchor.p;
}

}  // namespace

TEST_CASE("two-view triangulation recovers the true point", "[window_features]") {
  const Scene s = make_scene(20);
  for (const auto& p : s.points) {
    const CameraPose a = s.camera(0), b = s.camera(3);
    const Eigen::Vector3d pa = a.R.transpose() * (p - a.p), pb = b.R.transpose() * (p - b.p);
    const Eigen::Vector3d x = triangulate_two_view(a, b, pa.head<2>() / pa.z(), pb.head<2>() / pb.z());
    CHECK((x - p).norm() < 1e-9);
  }
}

TEST_CASE("stereo depths, slot shifts and re-anchoring keep every feature on its world point", "[window_features]") {
  const Scene s = make_scene(120);
  Eigen::Isometry3d T_c0c1 = Eigen::Isometry3d::Identity();
  T_c0c1.translation() = Eigen::Vector3d(0.11, 0, 0);
  WindowFeatures wf;
  // Slots 0..4: features 0..99 in all, 100..119 only from slot 2 on.
  std::vector<CameraPose> cams;
  for (int k = 0; k < 5; ++k) {
    cams.push_back(s.camera(k));
    TrackedFrame f = s.frame(k, 0, 100, T_c0c1);
    if (k >= 2) {
      const TrackedFrame extra = s.frame(k, 100, 20, T_c0c1);
      f.features.insert(f.features.end(), extra.features.begin(), extra.features.end());
    }
    wf.add_frame(k, f, 10.0 / kNominalFocalPx, true);
  }
  SlotCameraPose cam = [&](int k) { return cams[k]; };
  wf.triangulate(cam, T_c0c1, true);
  REQUIRE(wf.all().size() == 120);
  for (const auto& [id, f] : wf.all()) {
    REQUIRE(f.has_depth);
    CHECK((world_point(f, cams[f.start_slot]) - s.points[id]).norm() < 1e-6);
    CHECK(f.in_ba() == (f.obs.size() >= 4));
  }
  CHECK(wf.all().at(0).start_slot == 0);
  CHECK(wf.all().at(100).start_slot == 2);

  // Drop the second newest (slot 3): slot 4 becomes 3; features keep their points.
  wf.remove_slot(3, cam);
  cams.erase(cams.begin() + 3);
  for (const auto& [id, f] : wf.all()) {
    CHECK(f.end_slot() == 3);
    CHECK((world_point(f, cams[f.start_slot]) - s.points[id]).norm() < 1e-6);
  }
  // Drop the oldest: features anchored at 0 move their anchor to the old slot 1 (now 0).
  wf.remove_oldest(cam);
  cams.erase(cams.begin());
  for (const auto& [id, f] : wf.all()) {
    CHECK(f.start_slot == (id < 100 ? 0 : 1));
    CHECK((world_point(f, cams[f.start_slot]) - s.points[id]).norm() < 1e-6);
  }
}

TEST_CASE("the oldest slot's observations join the tracks' past with its pose, the latest max_past kept",
          "[window_features]") {
  const Scene s = make_scene(30);
  WindowFeatures wf;
  wf.set_max_past(3);
  // Slots 0..5; each removal drops the oldest, as the estimator's slide does.
  std::vector<CameraPose> cams;
  for (int k = 0; k < 6; ++k) {
    cams.push_back(s.camera(k));
    wf.add_frame(k, s.frame(k, 0, 30, Eigen::Isometry3d::Identity()), 10.0 / kNominalFocalPx, false);
  }
  wf.remove_oldest([&](int k) { return cams[k]; }, false);  // before the initialisation: nothing kept
  cams.erase(cams.begin());
  for (const auto& [id, f] : wf.all()) CHECK(f.past.empty());
  for (int r = 1; r <= 4; ++r) {
    wf.remove_oldest([&](int k) { return cams[k]; }, true);
    CHECK(wf.past_frame().p.isApprox(cams[1].p));  // the new slot 0
    cams.erase(cams.begin());
  }
  // Slots 1..4 left the window with their observations; the latest three (2, 3, 4) are kept, oldest first.
  for (const auto& [id, f] : wf.all()) {
    REQUIRE(f.past.size() == 3);
    for (int i = 0; i < 3; ++i) {
      const CameraPose c = s.camera(2 + i);
      const Eigen::Vector3d p_c = c.R.transpose() * (s.points[id] - c.p);
      CHECK(f.past[i].cam.p.isApprox(c.p));
      CHECK((f.past[i].xy - p_c.head<2>() / p_c.z()).norm() < 1e-12);
    }
  }
  wf.clear();
  CHECK(wf.past_frame().p.isZero());
}

TEST_CASE("keyframe decision follows parallax and new features", "[window_features]") {
  const Scene s = make_scene(100);
  const Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  WindowFeatures wf;
  CHECK(wf.add_frame(0, s.frame(0, 0, 100, T), 10.0 / kNominalFocalPx, false));  // early in the window
  CHECK(wf.add_frame(1, s.frame(1, 0, 100, T), 10.0 / kNominalFocalPx, false));
  // 0.3 m steps at 4-12 m give tens of pixels of parallax: keyframe.
  CHECK(wf.add_frame(2, s.frame(2, 0, 100, T), 10.0 / kNominalFocalPx, false));
  CHECK(wf.last_tracked_count() == 100);
  // An impossible parallax threshold, all tracked, long tracks: not a keyframe.
  CHECK(wf.add_frame(3, s.frame(3, 0, 100, T), 1e3, false) == false);
  // Most features new: keyframe whatever the parallax.
  WindowFeatures wf2;
  for (int k = 0; k < 3; ++k) wf2.add_frame(k, s.frame(k, 0, 60, T), 1e3, false);
  CHECK(wf2.add_frame(3, s.frame(3, 30, 70, T), 1e3, false));
}
