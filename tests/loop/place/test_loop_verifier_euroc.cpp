// LoopVerifier end to end on the real EuRoC clip (V1_01_easy, drone standing still): descriptors from
// the images, the match keyframe's 3-D points from a stereo triangulation of cam0/cam1 at frame 21, the
// query at frame 90 (3.45 s later) seen by cam0 and, with cam1's extrinsic, by cam1. The recovered T_m^k
// is checked against the ground-truth body motion between the two frames (2.6 mm, 0.1 deg).
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "stages/loop/place/hamming.hpp"
#include "stages/loop/place/keyframe_descriptors.hpp"
#include "stages/loop/place/loop_verifier.hpp"
#include "tests/loop/place/euroc_images.hpp"

using namespace dynavins;
using namespace dynavins::loop;

namespace {

/// The real calibration of one EuRoC camera (mav0/camN/sensor.yaml).
struct EurocCamera {
  cv::Mat K, D;
  Eigen::Vector3d p_bc;
  Eigen::Quaterniond q_bc;
};

EurocCamera load_camera(int n) {
  const std::string path =
      std::string(DYNAVINS_SHARED_DIR) + "/data/euroc_v1_01_micro/mav0/cam" + std::to_string(n) + "/sensor.yaml";
  cv::FileStorage fs(path, cv::FileStorage::READ);
  REQUIRE(fs.isOpened());
  std::vector<double> T, in, d;
  fs["T_BS"]["data"] >> T;
  fs["intrinsics"] >> in;
  fs["distortion_coefficients"] >> d;
  REQUIRE(T.size() == 16);
  REQUIRE(in.size() == 4);
  REQUIRE(d.size() == 4);
  EurocCamera c;
  c.K = (cv::Mat_<double>(3, 3) << in[0], 0, in[2], 0, in[1], in[3], 0, 0, 1);
  c.D = cv::Mat(d, true).reshape(1, 1);
  Eigen::Matrix3d R;
  R << T[0], T[1], T[2], T[4], T[5], T[6], T[8], T[9], T[10];
  c.q_bc = Eigen::Quaterniond(R).normalized();
  c.p_bc = Eigen::Vector3d(T[3], T[7], T[11]);
  return c;
}

KeyframeDescriptors describe(int frame, const EurocCamera& cam, const Eigen::Vector3d& p_wb,
                             const Eigen::Quaterniond& q_wb) {
  Keyframe kf;
  kf.t_ns = frame;
  kf.image = test::euroc_cam0_image(frame);
  kf.p_wb = p_wb;
  kf.q_wb = q_wb;
  kf.p_bc = cam.p_bc;
  kf.q_bc = cam.q_bc;
  DescriptorOptions opts;
  opts.max_points = 500;
  return compute_keyframe_descriptors(kf, opts, [&](const Eigen::Vector2d& px) {
    std::vector<cv::Point2d> in{{px.x(), px.y()}}, out;
    cv::undistortPoints(in, out, cam.K, cam.D);
    return Eigen::Vector2d(out[0].x, out[0].y);
  });
}

// Ground truth (../shared/data/trajectories/euroc_tum/V1_01_easy_original.txt.gz, T_world_body, body = IMU)
// at frames 21 (t = 1403715274.31214 s) and 90 (t = 1403715277.76214 s).
const Eigen::Vector3d kP21(0.878703, 2.142317, 0.947242);
const Eigen::Quaterniond kQ21(0.060600, -0.828405, -0.059100, -0.553697);  // w, x, y, z
const Eigen::Vector3d kP90(0.879514, 2.140561, 0.949023);
const Eigen::Quaterniond kQ90(0.062057, -0.827625, -0.058033, -0.554813);

}  // namespace

TEST_CASE("loop verifier: real EuRoC revisit from a stereo-triangulated keyframe") {
  const EurocCamera cam0 = load_camera(0), cam1 = load_camera(1);
  const Eigen::Quaterniond q21 = kQ21.normalized(), q90 = kQ90.normalized();
  KeyframeDescriptors match = describe(21, cam0, kP21, q21);
  const KeyframeDescriptors right = [&] {
    Keyframe kf;
    kf.image = test::euroc_image(1, 21);
    DescriptorOptions opts;
    opts.max_points = 500;
    return compute_keyframe_descriptors(kf, opts, [&](const Eigen::Vector2d& px) {
      std::vector<cv::Point2d> in{{px.x(), px.y()}}, out;
      cv::undistortPoints(in, out, cam1.K, cam1.D);
      return Eigen::Vector2d(out[0].x, out[0].y);
    });
  }();

  // Stereo triangulation at frame 21: cam0 -> cam1 is T_c1_c0 = T_bc1^-1 T_bc0.
  const Eigen::Quaterniond q_10 = cam1.q_bc.conjugate() * cam0.q_bc;
  const Eigen::Vector3d p_10 = cam1.q_bc.conjugate() * (cam0.p_bc - cam1.p_bc);
  cv::Mat P0 = cv::Mat::eye(3, 4, CV_64F), P1(3, 4, CV_64F);
  const Eigen::Matrix3d R10 = q_10.toRotationMatrix();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) P1.at<double>(r, c) = R10(r, c);
    P1.at<double>(r, 3) = p_10(r);
  }
  const Eigen::Quaterniond q_wc = q21 * cam0.q_bc;
  const Eigen::Vector3d p_wc = kP21 + q21 * cam0.p_bc;
  const double max_err = 1.0 / 458.0;
  int triangulated = 0;
  for (int i = 0; i < match.descriptors.rows; ++i) {
    int best = 1000, second = 1000, best_j = -1;
    for (int j = 0; j < right.descriptors.rows; ++j) {
      const int d = hamming_distance(match.descriptors.ptr<uint8_t>(i), right.descriptors.ptr<uint8_t>(j));
      if (d < best) second = best, best = d, best_j = j;
      else if (d < second) second = d;
    }
    if (best_j < 0 || best > 40 || best >= 0.7 * second) continue;
    const Eigen::Vector2d x0 = match.points[i].xy, x1 = right.points[best_j].xy;
    cv::Mat X;
    cv::triangulatePoints(P0, P1, cv::Mat(cv::Point2d(x0.x(), x0.y())), cv::Mat(cv::Point2d(x1.x(), x1.y())), X);
    X.convertTo(X, CV_64F);
    const Eigen::Vector3d p0(X.at<double>(0) / X.at<double>(3), X.at<double>(1) / X.at<double>(3),
                             X.at<double>(2) / X.at<double>(3));
    const Eigen::Vector3d p1 = q_10 * p0 + p_10;
    if (!(p0.z() > 0.5 && p0.z() < 15.0 && p1.z() > 0.5)) continue;
    if ((p0.head<2>() / p0.z() - x0).norm() > max_err || (p1.head<2>() / p1.z() - x1).norm() > max_err) continue;
    match.points[i].has_p_w = true;
    match.points[i].p_w = q_wc * p0 + p_wc;
    ++triangulated;
  }
  INFO("triangulated " << triangulated << " of " << match.points.size());
  REQUIRE(triangulated >= 50);

  const Eigen::Vector3d p_true = q21.conjugate() * (kP90 - kP21);
  const Eigen::Quaterniond q_true = q21.conjugate() * q90;
  const LoopVerifier verifier;

  SECTION("query seen by cam0") {
    // The query's odometry pose is deliberately off: the verifier uses only its extrinsic.
    const KeyframeDescriptors query = describe(90, cam0, kP90 + Eigen::Vector3d(1, 0, 0), q90);
    const LoopVerification v = verifier.verify(query, match);
    const double dp = (v.loop.p_mq - p_true).norm();
    const double dq = Eigen::AngleAxisd(v.loop.q_mq.conjugate() * q_true).angle() * 180 / M_PI;
    INFO(to_string(v.rejection) << ": matches " << v.matches << ", inliers " << v.inliers << ", error " << dp * 100
                                << " cm, " << dq << " deg");
    REQUIRE(v.accepted);
    CHECK(v.inliers >= 30);
    CHECK(dp < 0.02);
    CHECK(dq < 0.5);
  }
  SECTION("query seen by cam1, 11 cm from cam0: the extrinsic is taken into account") {
    KeyframeDescriptors query;
    {
      Keyframe kf;
      kf.t_ns = 90;
      kf.image = test::euroc_image(1, 90);
      kf.p_bc = cam1.p_bc;
      kf.q_bc = cam1.q_bc;
      DescriptorOptions opts;
      opts.max_points = 500;
      query = compute_keyframe_descriptors(kf, opts, [&](const Eigen::Vector2d& px) {
        std::vector<cv::Point2d> in{{px.x(), px.y()}}, out;
        cv::undistortPoints(in, out, cam1.K, cam1.D);
        return Eigen::Vector2d(out[0].x, out[0].y);
      });
    }
    const LoopVerification v = verifier.verify(query, match);
    const double dp = (v.loop.p_mq - p_true).norm();
    const double dq = Eigen::AngleAxisd(v.loop.q_mq.conjugate() * q_true).angle() * 180 / M_PI;
    INFO(to_string(v.rejection) << ": matches " << v.matches << ", inliers " << v.inliers << ", error " << dp * 100
                                << " cm, " << dq << " deg");
    REQUIRE(v.accepted);
    CHECK(v.inliers >= 30);
    CHECK(dp < 0.02);
    CHECK(dq < 0.5);
    // With cam0's extrinsic in its place the answer is off by the stereo baseline.
    query.p_bc = cam0.p_bc;
    query.q_bc = cam0.q_bc;
    const LoopVerification wrong = verifier.verify(query, match);
    INFO("with cam0's extrinsic: error " << (wrong.loop.p_mq - p_true).norm() * 100 << " cm");
    CHECK((wrong.loop.p_mq - p_true).norm() > 0.08);
  }
}
