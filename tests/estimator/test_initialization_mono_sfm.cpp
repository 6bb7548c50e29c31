// solve_mono_sfm: camera poses and points match the truth up to a similarity; pure rotation and too few
// features fail with a reason; the helper geometry (triangulation, rotation-compensated parallax).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "stages/common/so3.hpp"
#include "stages/estimator/initialization/mono_sfm.hpp"
#include "tests/estimator/test_initialization_scenario.hpp"

using namespace dynavins;
using namespace dynavins::estimator;
using namespace dynavins::estimator::test;

namespace {

struct SfmErrors {
  double max_rot_deg = 0.0;      // camera rotations vs truth (in frame l)
  double max_dir_deg = 0.0;      // direction of p_lc vs truth, frames farther than 30% of the longest
  double max_pos_rel = 0.0;      // |s p - p_true| / max |p_true|
  double median_point_rel = 0.0; // |s P - P_true| / |P_true - p_true(l)|
  double scale = 0.0;            // least-squares similarity scale
};

SfmErrors compare(const Scenario& s, const MonoSfmResult& r) {
  SfmErrors e;
  const int l = r.reference_frame;
  const Eigen::Matrix3d R_wl = s.R_wc(l);
  const Eigen::Vector3d p_wl = s.p_wc(l);
  std::vector<Eigen::Vector3d> p_true;
  double num = 0.0, den = 0.0, longest = 0.0;
  for (int k = 0; k < s.frames(); ++k) {
    e.max_rot_deg = std::max(e.max_rot_deg, angle_deg((R_wl.transpose() * s.R_wc(k)).transpose() * r.R_lc[k]));
    p_true.push_back(R_wl.transpose() * (s.p_wc(k) - p_wl));
    num += p_true[k].dot(r.p_lc[k]);
    den += r.p_lc[k].squaredNorm();
    longest = std::max(longest, p_true[k].norm());
  }
  e.scale = num / den;
  for (int k = 0; k < s.frames(); ++k) {
    e.max_pos_rel = std::max(e.max_pos_rel, (e.scale * r.p_lc[k] - p_true[k]).norm() / longest);
    if (p_true[k].norm() > 0.3 * longest) {
      const double c = p_true[k].normalized().dot(r.p_lc[k].normalized());
      e.max_dir_deg = std::max(e.max_dir_deg, std::acos(std::min(1.0, c)) * 180.0 / M_PI);
    }
  }
  std::vector<double> rel;
  for (const auto& [id, P] : r.points_l) {
    const Eigen::Vector3d P_true = R_wl.transpose() * (s.landmarks_w.at(id) - p_wl);
    rel.push_back((e.scale * P - P_true).norm() / P_true.norm());
  }
  std::sort(rel.begin(), rel.end());
  e.median_point_rel = rel.empty() ? 1e9 : rel[rel.size() / 2];
  return e;
}

/// The bounds of the 0.5 px noise case (measured there over five seeds; see that test).
void check_half_pixel_bounds(const Scenario& s, const MonoSfmResult& r) {
  const SfmErrors e = compare(s, r);
  INFO("rot " << e.max_rot_deg << " deg, dir " << e.max_dir_deg << " deg, pos " << e.max_pos_rel << ", points "
              << e.median_point_rel << ", rms " << r.rms_reprojection_px << " px");
  CHECK(e.max_rot_deg < 0.2);
  CHECK(e.max_dir_deg < 1.0);
  CHECK(e.max_pos_rel < 0.015);
  CHECK(e.median_point_rel < 0.015);
}

}  // namespace

TEST_CASE("mono SfM matches the truth up to a similarity on noise-free data", "[estimator][initialization]") {
  const Scenario s = make_scenario();
  const MonoSfmResult r = solve_mono_sfm(s.features);
  INFO(r.reason);
  REQUIRE(r.success);
  REQUIRE(static_cast<int>(r.R_lc.size()) == s.frames());
  const SfmErrors e = compare(s, r);
  INFO("l " << r.reference_frame << " rot " << e.max_rot_deg << " deg, dir " << e.max_dir_deg << " deg, pos "
            << e.max_pos_rel << ", points " << e.median_point_rel << ", rms " << r.rms_reprojection_px << " px");
  CHECK(r.points_l.size() > 150);
  CHECK(r.rms_reprojection_px < 1e-3);
  CHECK(e.max_rot_deg < 0.01);
  CHECK(e.max_dir_deg < 0.1);
  CHECK(e.max_pos_rel < 1e-3);
  CHECK(e.median_point_rel < 1e-3);
}

TEST_CASE("mono SfM with 0.5 px noise", "[estimator][initialization]") {
  const uint64_t seed = GENERATE(7, 8, 9, 10, 11);
  ScenarioOptions o;
  o.pixel_noise_px = 0.5;
  o.seed = seed;
  const Scenario s = make_scenario(o);
  const MonoSfmResult r = solve_mono_sfm(s.features);
  INFO("seed " << seed << ": " << r.reason);
  REQUIRE(r.success);
  const SfmErrors e = compare(s, r);
  INFO("l " << r.reference_frame << " rot " << e.max_rot_deg << " deg, dir " << e.max_dir_deg << " deg, pos "
            << e.max_pos_rel << ", points " << e.median_point_rel << ", rms " << r.rms_reprojection_px << " px");
  // The BA residual is the noise itself: RMS of a 2-D 0.5 px Gaussian is ~0.7 px, a bit less after fitting.
  CHECK(r.rms_reprojection_px > 0.4);
  CHECK(r.rms_reprojection_px < 0.8);
  // Measured over these seeds: rot <= 0.04 deg, dir <= 0.44 deg, pos <= 0.4 %, points <= 0.6 %.
  CHECK(e.max_rot_deg < 0.2);
  CHECK(e.max_dir_deg < 1.0);
  CHECK(e.max_pos_rel < 0.015);
  CHECK(e.median_point_rel < 0.015);
}

TEST_CASE("mono SfM fails on a pure rotation", "[estimator][initialization]") {
  ScenarioOptions o;
  o.pure_rotation = true;
  o.pixel_noise_px = 0.5;
  const Scenario s = make_scenario(o);
  const MonoSfmResult r = solve_mono_sfm(s.features);
  INFO(r.reason);
  CHECK_FALSE(r.success);
  CHECK(r.reason.find("pure rotation") != std::string::npos);
}

namespace {
/// Adds `count` features that keep their pixels in every frame (riders, or points at infinity on a
/// straight drive) at random positions, with `noise_px` of pixel noise; returns the first one's id.
FeatureId add_still_features(Scenario& s, int count, unsigned seed, double noise_px) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.6, 0.6);
  std::normal_distribution<double> noise(0.0, (noise_px > 0.0 ? noise_px : 1.0) / Scenario::kFocal);  // stddev > 0
  const FeatureId first = FeatureId(1) << 40;
  for (int j = 0; j < count; ++j) {
    const Eigen::Vector2d x(u(rng), u(rng));
    for (FrameFeatures& f : s.features)
      f[first + j] = noise_px > 0.0 ? Eigen::Vector2d(x + Eigen::Vector2d(noise(rng), noise(rng))) : x;
  }
  return first;
}
}  // namespace

TEST_CASE("mono SfM initialises while most of the view moves with the camera", "[estimator][initialization]") {
  // Issue 23: a truck leading the camera a few metres ahead stays at the same pixels while the camera
  // drives. Here twice as many such features as static ones (fixed image positions in every frame, the
  // same 0.5 px noise). Taken in as VINS-Fusion does, they dilute the mean parallax (behind the sim's
  // leading truck: "not enough parallax", 20.7 px of 30) or, where the motion is large enough, are
  // triangulated and wreck the SfM bundle adjustment (here: it keeps none of the points). Judged on the
  // features that moved, and with the still ones never triangulated, SfM succeeds.
  ScenarioOptions o;
  o.pixel_noise_px = 0.5;
  Scenario s = make_scenario(o);
  const FeatureId rider0 = add_still_features(s, 2 * static_cast<int>(s.features.back().size()), 5, o.pixel_noise_px);

  MonoSfmOptions vins_mean;  // VINS-Fusion's test: the mean over all common features
  vins_mean.min_feature_motion_px = 0.0;
  const MonoSfmResult diluted = solve_mono_sfm(s.features, vins_mean);
  INFO("mean over all features: " << diluted.reason);
  CHECK_FALSE(diluted.success);

  MonoSfmResult r = solve_mono_sfm(s.features);
  INFO(r.reason);
  REQUIRE(r.success);
  for (auto it = r.points_l.begin(); it != r.points_l.end();) {  // compare() scores the static points only
    if (it->first >= rider0) it = r.points_l.erase(it);
    else ++it;
  }
  check_half_pixel_bounds(s, r);
}

TEST_CASE("mono SfM is VINS-Fusion's while few features are still", "[estimator][initialization]") {
  // Far points on a straight drive keep their pixels too; while they are at most max_still_share of the
  // common features they count in the mean parallax, are used by the essential matrix and triangulated,
  // as in VINS (static scenes measured 6-9 % still at initialisation; judging the moved ones only made
  // mono start earlier on a weaker scale there). Here one still feature per nine moving ones (10 %): the
  // result is bit for bit the one of a threshold that never suspects riders. (Two thirds still: the
  // test above, where the VINS mean fails.)
  ScenarioOptions o;
  o.pixel_noise_px = 0.5;
  Scenario s = make_scenario(o);
  REQUIRE(s.features.back().size() >= 27);
  add_still_features(s, static_cast<int>(s.features.back().size()) / 9, 6, 0.0);
  MonoSfmOptions vins;  // never suspects riders
  vins.max_still_share = 1.0;
  const MonoSfmResult a = solve_mono_sfm(s.features), b = solve_mono_sfm(s.features, vins);
  INFO(a.reason);
  REQUIRE(a.success);
  CHECK(a.reference_frame == b.reference_frame);
  CHECK(a.points_l.size() == b.points_l.size());
  CHECK(a.rms_reprojection_px == b.rms_reprojection_px);
}

TEST_CASE("mono SfM fails with too few common features", "[estimator][initialization]") {
  Scenario s = make_scenario();
  // Keep only 15 features in the newest frame.
  FrameFeatures& newest = s.features.back();
  while (newest.size() > 15) newest.erase(std::prev(newest.end()));
  const MonoSfmResult r = solve_mono_sfm(s.features);
  INFO(r.reason);
  CHECK_FALSE(r.success);
  CHECK(r.reason.find("common features") != std::string::npos);
  CHECK_FALSE(solve_mono_sfm({}).success);
}

TEST_CASE("rotation-compensated parallax separates rotation from translation", "[estimator][initialization]") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0), depth(3.0, 10.0);
  const Eigen::Matrix3d R_ba = so3::exp(Eigen::Vector3d(0.1, -0.2, 0.05));  // x_b ~ R_ba x_a + t
  std::vector<Eigen::Vector2d> xa, xb_rot, xb_move;
  const Eigen::Vector3d t(0.3, 0.0, 0.1);
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d P(u(rng), u(rng), 1.0);
    const Eigen::Vector3d Pa = depth(rng) * P;
    xa.push_back(P.head<2>());
    const Eigen::Vector3d r = R_ba * Pa, m = R_ba * Pa + t;
    xb_rot.push_back(r.head<2>() / r.z());
    xb_move.push_back(m.head<2>() / m.z());
  }
  CHECK(rotation_compensated_parallax_px(xa, xb_rot, 460.0) < 1e-6);
  CHECK(rotation_compensated_parallax_px(xa, xb_move, 460.0) > 5.0);
}

TEST_CASE("two-view triangulation recovers a point and rejects one behind", "[estimator][initialization]") {
  const Eigen::Matrix3d Ra = Eigen::Matrix3d::Identity();
  const Eigen::Vector3d ta = Eigen::Vector3d::Zero();
  const Eigen::Matrix3d Rb = so3::exp(Eigen::Vector3d(0.0, 0.1, 0.0));
  const Eigen::Vector3d tb(-0.5, 0.0, 0.0);
  const Eigen::Vector3d P(0.3, -0.2, 4.0);
  const Eigen::Vector3d pa = Ra * P + ta, pb = Rb * P + tb;
  Eigen::Vector3d X;
  REQUIRE(triangulate_two_views(Ra, ta, pa.head<2>() / pa.z(), Rb, tb, pb.head<2>() / pb.z(), X));
  CHECK((X - P).norm() < 1e-9);
  const Eigen::Vector3d Q(0.3, -0.2, -4.0);  // behind camera a
  const Eigen::Vector3d qa = Ra * Q + ta, qb = Rb * Q + tb;
  CHECK_FALSE(triangulate_two_views(Ra, ta, qa.head<2>() / qa.z(), Rb, tb, qb.head<2>() / qb.z(), X));
}

TEST_CASE("mono SfM with a reference frame after the first one", "[estimator][initialization]") {
  // Frames 0 and 1 keep only 10 features that the newest frame sees: l must be 2, and frames 0, 1 are
  // placed by PnP going backwards from l.
  ScenarioOptions o;
  o.pixel_noise_px = 0.5;
  Scenario s = make_scenario(o);
  const FrameFeatures& newest = s.features.back();
  for (int k : {0, 1}) {
    int kept = 0;
    for (auto it = s.features[k].begin(); it != s.features[k].end();) {
      if (newest.count(it->first) && ++kept > 10) it = s.features[k].erase(it);
      else ++it;
    }
  }
  const MonoSfmResult r = solve_mono_sfm(s.features);
  INFO(r.reason);
  REQUIRE(r.success);
  CHECK(r.reference_frame == 2);
  CHECK(r.R_lc[2].isIdentity(1e-12));
  CHECK(r.p_lc[2].norm() < 1e-12);
  CHECK(r.p_lc.back().norm() == Approx(1.0).epsilon(1e-9));  // the scale gauge
  check_half_pixel_bounds(s, r);
}

TEST_CASE("mono SfM tolerates a few gross outliers", "[estimator][initialization]") {
  // 10 % of the tracks get one observation at a random image position (a tracker slip); the rest 0.5 px noise.
  ScenarioOptions o;
  o.pixel_noise_px = 0.5;
  Scenario s = make_scenario(o);
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> u(0.0, 1.0), x(-0.8, 0.8);
  std::set<int> corrupted;
  for (const auto& [id, p] : s.landmarks_w) {
    (void)p;
    if (u(rng) >= 0.1) continue;
    std::vector<int> seen;
    for (int k = 0; k < s.frames(); ++k)
      if (s.features[k].count(id)) seen.push_back(k);
    if (seen.size() < 2) continue;
    const int k = seen[static_cast<size_t>(u(rng) * seen.size())];
    s.features[k][id] = Eigen::Vector2d(x(rng), 0.8 * x(rng));
    corrupted.insert(id);
  }
  const MonoSfmResult r = solve_mono_sfm(s.features);
  INFO(r.reason);
  REQUIRE(r.success);
  const SfmErrors e = compare(s, r);
  INFO("rot " << e.max_rot_deg << " deg, dir " << e.max_dir_deg << " deg, pos " << e.max_pos_rel << ", points "
              << e.median_point_rel << ", rms " << r.rms_reprojection_px << " px, points kept " << r.points_l.size()
              << ", corrupted tracks " << corrupted.size());
  CHECK(e.max_rot_deg < 0.2);
  CHECK(e.max_dir_deg < 1.0);
  CHECK(e.max_pos_rel < 0.015);
  CHECK(e.median_point_rel < 0.015);
  CHECK(r.rms_reprojection_px < 0.8);
  // The corrupted tracks are the ones dropped (a slip of a few px may survive), few good ones lost.
  CHECK(r.points_l.size() + corrupted.size() >= 290);
  CHECK(r.points_l.size() <= 300 - corrupted.size() + 3);
}
