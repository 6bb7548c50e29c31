#include <filesystem>
#include <fstream>

#include <catch2/catch.hpp>
#include <opencv2/imgcodecs.hpp>

#include "io/euroc_dataset.hpp"
#include "io/euroc_source.hpp"
#include "io/input_error.hpp"
#include "tests/log_capture.hpp"

using namespace dynavins;
using namespace dynavins::io;
namespace fs = std::filesystem;

namespace {

const std::string kMicro = std::string(DYNAVINS_SHARED_DIR) + "/data/euroc_v1_01_micro";

/// A tiny EuRoC folder: 3 stereo frames at 20 Hz, 200 Hz IMU, ground truth.
fs::path make_folder(const std::string& name) {
  const fs::path root = fs::temp_directory_path() / "dynavins_test_euroc" / name;
  fs::remove_all(root);
  for (const char* cam : {"cam0", "cam1"}) {
    fs::create_directories(root / "mav0" / cam / "data");
    std::ofstream csv(root / "mav0" / cam / "data.csv");
    csv << "#timestamp [ns],filename\n";
    for (int i = 0; i < 3; ++i) {
      const int64_t t = 1'000'000'000 + i * 50'000'000LL;
      csv << t << "," << t << ".png\n";
      cv::imwrite((root / "mav0" / cam / "data" / (std::to_string(t) + ".png")).string(),
                  cv::Mat(8, 10, CV_8UC1, cv::Scalar(10 * i + (cam[3] - '0'))));
    }
  }
  fs::create_directories(root / "mav0" / "imu0");
  std::ofstream imu(root / "mav0" / "imu0" / "data.csv");
  imu << "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],"
         "a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n";
  for (int i = 0; i < 25; ++i) imu << 1'000'000'000 + i * 5'000'000LL << ",0.1,0.2,0.3,1,2,9.81\n";
  fs::create_directories(root / "mav0" / "state_groundtruth_estimate0");
  std::ofstream gt(root / "mav0" / "state_groundtruth_estimate0" / "data.csv");
  gt << "#timestamp, p_RS_R_x [m], ...\n";
  gt << "1000000000,1,2,3,1,0,0,0,0.1,0.2,0.3,0.01,0.02,0.03,0.1,0.2,0.3\n";
  return root;
}

void append(const fs::path& file, const std::string& text) { std::ofstream(file, std::ios::app) << text; }

}  // namespace

TEST_CASE("EurocDataset reads a folder: frames, IMU in EuRoC column order, ground truth", "[euroc]") {
  const auto root = make_folder("ok");
  EurocDataset d(root.string());
  REQUIRE(d.stereo());
  REQUIRE(d.frames().size() == 3);
  REQUIRE(d.imu().size() == 25);
  CHECK(d.imu()[0].gyr == Eigen::Vector3d(0.1, 0.2, 0.3));  // angular rate comes first in EuRoC
  CHECK(d.imu()[0].acc == Eigen::Vector3d(1, 2, 9.81));
  REQUIRE(d.ground_truth().size() == 1);
  CHECK(d.ground_truth()[0].p_wb == Eigen::Vector3d(1, 2, 3));
  CHECK(d.ground_truth()[0].bias_acc == Eigen::Vector3d(0.1, 0.2, 0.3));
  const StereoFrame f = d.load(2);
  CHECK(f.t_ns == 1'100'000'000);
  CHECK(f.left.at<uint8_t>(0, 0) == 20);
  CHECK(f.right.at<uint8_t>(0, 0) == 21);
  // mav0/ itself is accepted too
  CHECK(EurocDataset((root / "mav0").string()).frames().size() == 3);
}

TEST_CASE("EurocDataset reads TUM-VI's motion capture (mocap0) as ground truth when there is no state estimate",
          "[euroc]") {
  const auto add_mocap = [](const fs::path& root) {
    fs::create_directories(root / "mav0" / "mocap0");
    std::ofstream(root / "mav0" / "mocap0" / "data.csv")
        << "#timestamp [ns],p_RS_R_x [m],p_RS_R_y [m],p_RS_R_z [m],q_RS_w [],q_RS_x [],q_RS_y [],q_RS_z []\n"
        << "1000000000,1,2,3,0,1,0,0\n1010000000,1.5,2,3,0,1,0,0\n";
  };
  const auto root = make_folder("tumvi");
  fs::remove_all(root / "mav0" / "state_groundtruth_estimate0");
  add_mocap(root);
  EurocDataset d(root.string());
  REQUIRE(d.ground_truth().size() == 2);
  CHECK(d.ground_truth()[1].t_ns == 1'010'000'000);
  CHECK(d.ground_truth()[1].p_wb == Eigen::Vector3d(1.5, 2, 3));
  CHECK(d.ground_truth()[1].q_wb.coeffs() == Eigen::Quaterniond(0, 1, 0, 0).coeffs());  // w first, as EuRoC
  CHECK_FALSE(d.ground_truth()[1].has_velocity);
  CHECK_FALSE(d.ground_truth()[1].has_biases);
  // The state estimate wins where both are there (EuRoC's own folders).
  const auto both = make_folder("both");
  add_mocap(both);
  CHECK(EurocDataset(both.string()).ground_truth().size() == 1);
  // Bad rows name the file and line.
  append(root / "mav0/mocap0/data.csv", "1020000000,1,2,3,0.5,0.5,0,0\n");
  CHECK_THROWS_WITH(EurocDataset(root.string()),
                    Catch::Contains("mocap0/data.csv:4") && Catch::Contains("not a unit quaternion"));
}

TEST_CASE("EurocSource merges frames, IMU and ground truth in time order, IMU first on ties", "[euroc]") {
  EurocSource src(std::make_shared<EurocDataset>(make_folder("merge").string()));
  SensorEvent e;
  int64_t last = INT64_MIN;
  int frames = 0, imu = 0;
  bool imu_seen_at_first_frame = false;
  while (src.next(e)) {
    CHECK(event_time_ns(e) >= last);
    last = event_time_ns(e);
    if (std::holds_alternative<StereoFrame>(e)) {
      if (frames == 0) imu_seen_at_first_frame = imu > 0;
      ++frames;
    }
    imu += std::holds_alternative<ImuSample>(e);
  }
  CHECK(frames == 3);
  CHECK(imu == 25);
  CHECK(imu_seen_at_first_frame);
  CHECK(src.progress() == 1.0);
}

TEST_CASE("EurocDataset: bad input is an error naming the file and line", "[euroc]") {
  SECTION("a listed image that does not exist is skipped and counted, its partner left unmatched") {
    const auto root = make_folder("missing");
    fs::remove(root / "mav0/cam1/data/1050000000.png");
    EurocDataset d(root.string());
    CHECK(d.missing_images() == 1);
    CHECK(d.frames().size() == 2);
    CHECK(d.unmatched_left() == 1);
  }
  SECTION("missing images are counted per camera in the warnings, and in total") {
    const auto root = make_folder("missing_both");
    fs::remove(root / "mav0/cam0/data/1000000000.png");
    fs::remove(root / "mav0/cam1/data/1000000000.png");
    fs::remove(root / "mav0/cam1/data/1050000000.png");
    test::LogCapture log;
    EurocDataset d(root.string());
    CHECK(d.missing_images() == 3);
    const std::string text = log.text.str();
    INFO(text);
    CHECK(text.find("cam0/data.csv:2: image") != std::string::npos);
    CHECK(text.find("cam0/data.csv: ") == std::string::npos);  // one missing: no total line for cam0
    CHECK(text.find("cam1/data.csv:2: image") != std::string::npos);
    CHECK(text.find("cam1/data.csv: 2 listed images do not exist") != std::string::npos);
  }
  SECTION("wrong column count") {
    const auto root = make_folder("columns");
    append(root / "mav0/imu0/data.csv", "1200000000,0.1,0.2,0.3,1,2\n");
    CHECK_THROWS_WITH(EurocDataset(root.string()), Catch::Contains("imu0/data.csv:27: expected 7 columns, found 6"));
  }
  SECTION("duplicate and decreasing timestamps") {
    auto root = make_folder("dup");
    append(root / "mav0/imu0/data.csv", "1120000000,0.1,0.2,0.3,1,2,3\n");
    CHECK_THROWS_WITH(EurocDataset(root.string()), Catch::Contains("imu0/data.csv:27: duplicate timestamp"));
    root = make_folder("back");
    append(root / "mav0/imu0/data.csv", "1000000001,0.1,0.2,0.3,1,2,3\n");
    CHECK_THROWS_WITH(EurocDataset(root.string()), Catch::Contains("imu0/data.csv:27: timestamp 1000000001 goes back"));
  }
  SECTION("unreadable image") {
    const auto root = make_folder("corrupt");
    std::ofstream(root / "mav0/cam0/data/1000000000.png") << "not a png";
    EurocDataset d(root.string());
    CHECK_THROWS_WITH(d.load(0), Catch::Contains("cam0/data/1000000000.png") && Catch::Contains("cannot read"));
  }
  SECTION("not an EuRoC folder") {
    CHECK_THROWS_AS(EurocDataset(fs::temp_directory_path().string()), InputError);
  }
}

TEST_CASE("EurocDataset reads the real EuRoC V1_01 clip as it is", "[euroc][real]") {
  EurocDataset d(kMicro);
  INFO("unmatched left " << d.unmatched_left() << ", right " << d.unmatched_right());
  CHECK(d.stereo());
  // cam0 lists 95 images, cam1 99 of which the last 4 were not shipped: 95 stereo pairs.
  CHECK(d.frames().size() == 95);
  CHECK(d.missing_images() == 4);
  CHECK(d.unmatched_left() == 0);
  CHECK(d.unmatched_right() == 0);
  CHECK(d.imu().size() == 29120);
  const StereoFrame f = d.load(0);
  CHECK(f.left.cols == 752);
  CHECK(f.left.rows == 480);
  CHECK(f.right.size() == f.left.size());
}
