// HypothesisClusterer (paper IV-B, eq. 13-14) on a constructed group: odometry that has drifted by a
// common rigid offset, loops to old keyframes whose poses are correct. Loops on static features all
// estimate the true T_W^i (one cluster); loops on an object relocated by 2 m estimate a T_W^i 2 m away
// (a second hypothesis); the two largest clusters are kept, largest first.
#include <catch2/catch.hpp>

#include <cmath>

#include "stages/loop/graph/hypothesis_clusterer.hpp"

using namespace dynavins::loop;

namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

RigidPose make_pose(double x, double y, double z, double yaw, double pitch = 0.0, double roll = 0.0) {
  return RigidPose{Eigen::Vector3d(x, y, z), quat_from_ypr(yaw, pitch, roll)};
}

struct Scene {
  std::vector<RigidPose> gt;    // group members C_i = gt[0] .. C_9
  std::vector<RigidPose> odom;  // drifted: D * gt
  Scene() {
    const RigidPose D = make_pose(1.0, -0.5, 0.2, 7.0 * kDeg);
    for (int k = 0; k < 10; ++k) {
      gt.push_back(make_pose(10.0 + 0.4 * k, 3.0 + 0.05 * k * k, 1.0, 0.5 + 0.03 * k, 2.0 * kDeg, -1.0 * kDeg));
      odom.push_back(compose(D, gt.back()));
    }
  }
  /// A loop from C_k to a match keyframe seen from an offset of (dx, dy, dyaw); `shift` is how far the
  /// matched features' object has moved since C_m (zero for static features). `jitter` is a small
  /// deterministic measurement error.
  GroupLoop loop(std::size_t index, int k, double dx, double dy, const Eigen::Vector3d& shift, double jitter) const {
    GroupLoop l;
    l.loop_index = index;
    l.T_W_m = make_pose(gt[k].p.x() + dx, gt[k].p.y() + dy, 1.1, 0.5 + 0.2 * dy);
    RigidPose seen = gt[k];  // where PnP against the (possibly moved) features puts C_k
    seen.p -= shift;
    l.T_m_k = compose(inverse(l.T_W_m), seen);
    l.T_m_k.p += Eigen::Vector3d(jitter, -jitter, 0.5 * jitter);
    l.T_m_k.q = (l.T_m_k.q * Eigen::AngleAxisd(10.0 * jitter * kDeg, Eigen::Vector3d::UnitZ())).normalized();
    l.T_W_k_odom = odom[k];
    return l;
  }
};

double jitter_of(std::size_t i) { return 0.03 * std::sin(1.7 * static_cast<double>(i) + 0.3); }

}  // namespace

TEST_CASE("loop_group_start_pose: eq. 13-14 recover the true T_W^i from drifted odometry", "[loop][cluster]") {
  const Scene s;
  const GroupLoop l = s.loop(0, 6, -1.5, 0.7, Eigen::Vector3d::Zero(), 0.0);
  const RigidPose T_W_k = loop_query_pose(l.T_W_m, l.T_m_k);
  CHECK((T_W_k.p - s.gt[6].p).norm() < 1e-9);
  const RigidPose est = loop_group_start_pose(l.T_W_m, l.T_m_k, l.T_W_k_odom, s.odom[0]);
  CHECK((est.p - s.gt[0].p).norm() < 1e-9);
  CHECK(est.q.angularDistance(s.gt[0].q) < 1e-9);
  // The odometry estimate of C_i is about 0.9 m off; the loop's estimate is not.
  CHECK((s.odom[0].p - s.gt[0].p).norm() > 0.5);
}

TEST_CASE("HypothesisClusterer: loops on static features agree -> one hypothesis", "[loop][cluster]") {
  const Scene s;
  std::vector<GroupLoop> loops;
  for (std::size_t j = 0; j < 6; ++j)
    loops.push_back(
        s.loop(100 + j, static_cast<int>(j + 2), -1.0 + 0.3 * j, 0.2 * j, Eigen::Vector3d::Zero(), jitter_of(j)));
  const GroupHypotheses h = HypothesisClusterer().cluster(s.odom[0], loops);
  REQUIRE(h.hypotheses.size() == 1);
  CHECK(h.hypotheses[0].loop_indices == std::vector<std::size_t>{100, 101, 102, 103, 104, 105});
  CHECK((h.hypotheses[0].T_W_i.p - s.gt[0].p).norm() < 0.1);
  CHECK(std::abs(normalize_angle(yaw_of(h.hypotheses[0].T_W_i.q) - yaw_of(s.gt[0].q))) < 1.0 * kDeg);
  CHECK(std::abs(pitch_of(h.hypotheses[0].T_W_i.q) - 2.0 * kDeg) < 1.0 * kDeg);
}

TEST_CASE("HypothesisClusterer: a relocated object gives a second hypothesis, the top two by size are kept",
          "[loop][cluster]") {
  const Scene s;
  const Eigen::Vector3d moved(2.0, 0.0, 0.0);    // object moved 2 m
  const Eigen::Vector3d moved2(0.0, -5.0, 0.0);  // another one moved 5 m
  std::vector<GroupLoop> loops;
  std::size_t id = 0;
  auto add = [&](int count, const Eigen::Vector3d& shift) {
    for (int j = 0; j < count; ++j, ++id)
      loops.push_back(s.loop(id, static_cast<int>(id % 10), -0.8 + 0.1 * j, 0.3 * j, shift, jitter_of(id)));
  };

  SECTION("static features in the majority") {
    add(5, Eigen::Vector3d::Zero());  // loops 0..4
    add(3, moved);                    // loops 5..7
    const GroupHypotheses h = HypothesisClusterer().cluster(s.odom[0], loops);
    REQUIRE(h.hypotheses.size() == 2);
    CHECK(h.hypotheses[0].loop_indices == std::vector<std::size_t>{0, 1, 2, 3, 4});
    CHECK(h.hypotheses[1].loop_indices == std::vector<std::size_t>{5, 6, 7});
    CHECK((h.hypotheses[0].T_W_i.p - s.gt[0].p).norm() < 0.1);
    CHECK((h.hypotheses[1].T_W_i.p - (s.gt[0].p - moved)).norm() < 0.1);
  }
  SECTION("the relocated object in the majority: it is H^0") {
    add(3, Eigen::Vector3d::Zero());  // 0..2
    add(6, moved);                    // 3..8
    const GroupHypotheses h = HypothesisClusterer().cluster(s.odom[0], loops);
    REQUIRE(h.hypotheses.size() == 2);
    CHECK(h.hypotheses[0].loop_indices == std::vector<std::size_t>{3, 4, 5, 6, 7, 8});
    CHECK(h.hypotheses[1].loop_indices == std::vector<std::size_t>{0, 1, 2});
  }
  SECTION("three clusters: the smallest is dropped") {
    add(2, moved2);                   // 0..1
    add(4, Eigen::Vector3d::Zero());  // 2..5
    add(3, moved);                    // 6..8
    const GroupHypotheses h = HypothesisClusterer().cluster(s.odom[0], loops);
    REQUIRE(h.hypotheses.size() == 2);
    CHECK(h.hypotheses[0].loop_indices == std::vector<std::size_t>{2, 3, 4, 5});
    CHECK(h.hypotheses[1].loop_indices == std::vector<std::size_t>{6, 7, 8});
    CHECK(h.cluster_of == std::vector<int>{2, 2, 0, 0, 0, 0, 1, 1, 1});
  }
  SECTION("a yaw difference alone above 10 deg separates estimates") {
    add(3, Eigen::Vector3d::Zero());
    std::vector<GroupLoop> rotated = loops;
    for (GroupLoop& l : rotated) {
      l.loop_index += 10;
      // The same loops, but C_m believed 15 deg further round its own position: the estimates of C_i swing
      // by 15 deg of yaw (and by a translation, C_i being a few metres away: check yaw alone below).
      l.T_W_m.q = (Eigen::AngleAxisd(15.0 * kDeg, Eigen::Vector3d::UnitZ()) * l.T_W_m.q).normalized();
    }
    HypothesisClustererOptions loose;
    loose.max_translation_m = 100.0;
    const std::vector<GroupLoop> all = [&] {
      std::vector<GroupLoop> v = loops;
      v.insert(v.end(), rotated.begin(), rotated.end());
      return v;
    }();
    const GroupHypotheses h = HypothesisClusterer(loose).cluster(s.odom[0], all);
    REQUIRE(h.hypotheses.size() == 2);
    CHECK(h.hypotheses[0].loop_indices == std::vector<std::size_t>{0, 1, 2});
    CHECK(h.hypotheses[1].loop_indices == std::vector<std::size_t>{10, 11, 12});
  }
}

TEST_CASE("HypothesisClusterer: no loops -> no hypotheses", "[loop][cluster]") {
  const Scene s;
  const GroupHypotheses h = HypothesisClusterer().cluster(s.odom[0], {});
  CHECK(h.hypotheses.empty());
  CHECK(h.estimates.empty());
}
