// What `dynavins sim --euroc` writes reads back: the EuRoC folder through our reader, the
// VINS-Fusion config through OpenCV FileStorage the way VINS-Fusion reads it.
#include <filesystem>

#include <catch2/catch.hpp>
#include <opencv2/core.hpp>

#include "io/euroc_dataset.hpp"
#include "io/euroc_writer.hpp"
#include "io/vins_config_writer.hpp"

using namespace dynavins;
using namespace dynavins::io;
namespace fs = std::filesystem;

TEST_CASE("EurocWriter output reads back through EurocDataset unchanged", "[euroc]") {
  const fs::path dir = fs::temp_directory_path() / "dynavins_test_euroc_writer";
  fs::remove_all(dir);
  {
    EurocWriter w(dir.string());
    for (int k = 0; k < 30; ++k) {
      const int64_t t = 1'700'000'000'000'000'000 + k * 5'000'000LL;
      ImuSample s;
      s.t_ns = t;
      s.acc = {0.1 * k, -0.2, 9.81};
      s.gyr = {0.01, 0.002 * k, -0.03};
      w.write(s);
      GroundTruthState g;
      g.t_ns = t;
      g.p_wb = {k * 0.1, 1.0 / 3.0, 2.0};
      g.q_wb = Eigen::Quaterniond(Eigen::AngleAxisd(0.01 * k, Eigen::Vector3d::UnitZ()));
      g.v_wb = {2, 0, 0};
      g.bias_acc = {0.1, 0.2, 0.3};
      g.has_velocity = g.has_biases = true;
      w.write(g);
      if (k % 10 == 0) {
        StereoFrame f;
        f.t_ns = t;
        f.left = cv::Mat(6, 8, CV_8UC1, cv::Scalar(k));
        f.right = cv::Mat(6, 8, CV_8UC1, cv::Scalar(k + 1));
        f.labels = cv::Mat(6, 8, CV_8UC1, cv::Scalar(3));
        w.write(f);
      }
    }
    w.close();
  }
  EurocDataset d(dir.string());
  REQUIRE(d.frames().size() == 3);
  REQUIRE(d.imu().size() == 30);
  REQUIRE(d.ground_truth().size() == 30);
  CHECK(d.imu()[7].acc.isApprox(Eigen::Vector3d(0.7, -0.2, 9.81), 1e-15));
  CHECK(d.imu()[7].gyr.isApprox(Eigen::Vector3d(0.01, 0.014, -0.03), 1e-15));
  CHECK(d.ground_truth()[4].p_wb.isApprox(Eigen::Vector3d(0.4, 1.0 / 3.0, 2.0), 1e-15));
  CHECK(d.ground_truth()[4].q_wb.angularDistance(
            Eigen::Quaterniond(Eigen::AngleAxisd(0.04, Eigen::Vector3d::UnitZ()))) < 1e-12);
  const StereoFrame f = d.load(2);
  CHECK(f.t_ns == 1'700'000'000'000'000'000 + 20 * 5'000'000LL);
  CHECK(f.left.at<uint8_t>(0, 0) == 20);
  CHECK(f.right.at<uint8_t>(0, 0) == 21);
  CHECK(f.labels.at<uint8_t>(5, 7) == 3);
  CHECK_THROWS_WITH(EurocWriter(dir.string()), Catch::Contains("already holds"));
}

TEST_CASE("The VINS-Fusion config reads back with the values written", "[vins]") {
  const fs::path dir = fs::temp_directory_path() / "dynavins_test_vins_config";
  VinsStereoConfig c;
  c.cam0 = {752, 480, 458.5, 457.25, 367.125, 248.375, -0.28, 0.07, 2e-4, 2e-5};
  c.cam1 = c.cam0;
  c.body_T_cam0.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  c.body_T_cam0.translation() = Eigen::Vector3d(0.06, 0.03, -0.02);
  c.body_T_cam1 = c.body_T_cam0 * Eigen::Translation3d(0.11, 0, 0);
  write_vins_stereo_config(dir.string(), c);

  cv::FileStorage fs((dir / "vins_config.yaml").string(), cv::FileStorage::READ);
  REQUIRE(fs.isOpened());
  CHECK(static_cast<int>(fs["num_of_cam"]) == 2);
  CHECK(static_cast<std::string>(fs["cam0_calib"]) == "cam0_pinhole.yaml");
  CHECK(static_cast<double>(fs["acc_n"]) == 0.1);
  cv::Mat T;
  fs["body_T_cam1"] >> T;
  REQUIRE(T.rows == 4);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) CHECK(T.at<double>(i, j) == Approx(c.body_T_cam1.matrix()(i, j)).margin(1e-12));
  cv::FileStorage cam((dir / "cam0_pinhole.yaml").string(), cv::FileStorage::READ);
  REQUIRE(cam.isOpened());
  CHECK(static_cast<std::string>(cam["model_type"]) == "PINHOLE");
  CHECK(static_cast<double>(cam["projection_parameters"]["fx"]) == 458.5);
  CHECK(static_cast<double>(cam["distortion_parameters"]["k1"]) == -0.28);
}
