// trajectory_io: TUM / EuRoC csv reading (plain and gzip), format detection, TUM writing and
// the bad-input errors that must name the file and the line.
#include "eval/trajectory_io.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>

using namespace dynavins::eval;
namespace fs = std::filesystem;

namespace {

const std::string kData = std::string(DYNAVINS_SHARED_DIR) + "/data/trajectories/";

// A fresh directory under the system temp dir, removed at scope exit.
struct TempDir {
  fs::path path;
  TempDir() {
    std::random_device rd;
    path = fs::temp_directory_path() / ("dynavins_test_eval_" + std::to_string(rd()) + std::to_string(rd()));
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::string write(const std::string& name, const std::string& content) const {
    const fs::path p = path / name;
    std::ofstream(p, std::ios::binary) << content;
    return p.string();
  }
};

// Reads `path` expecting a TrajectoryFileError at `line`; checks the message names file and line.
void require_error_at(const std::string& path, std::size_t line, const std::string& phrase) {
  try {
    read_trajectory(path);
    FAIL("no exception for " << path);
  } catch (const TrajectoryFileError& e) {
    const std::string what = e.what();
    INFO(what);
    CHECK(e.file() == path);
    CHECK(e.line() == line);
    CHECK(what.find(path + ":" + std::to_string(line) + ":") == 0);
    CHECK(what.find(phrase) != std::string::npos);
  }
}

const std::string kTumRows =
    "# timestamp tx ty tz qx qy qz qw\n"
    "1.0 0 0 0 0 0 0 1\n"
    "2.0 1 0 0 0 0 0 1\n"
    "3.0 2 0 0 0 0 0 1\n";

}  // namespace

TEST_CASE("read_trajectory reads the TUM fixture", "[eval][io]") {
  const std::string path = kData + "evo_fixture/freiburg1_xyz-groundtruth.txt";
  const Trajectory t = read_trajectory(path);
  CHECK(t.source == path);
  REQUIRE(t.size() == 3000);
  const StampedPose& first = t.poses.front();
  CHECK(first.t == 1305031098.6659);
  CHECK(first.t_ns == 1305031098665900000LL);  // exact from the digits, not via the double
  CHECK(first.p.isApprox(Eigen::Vector3d(1.3563, 0.6305, 1.6380)));
  // x y z w in the file; stored normalised.
  const Eigen::Quaterniond q = Eigen::Quaterniond(-0.3986, 0.6132, 0.5962, -0.3311).normalized();
  CHECK(first.q.coeffs().isApprox(q.coeffs()));
  CHECK(std::abs(first.q.norm() - 1.0) < 1e-12);
  CHECK(t.poses.back().t_ns == 1305031128755500000LL);
}

TEST_CASE("read_trajectory reads gzip TUM and gzip 17-column EuRoC csv", "[eval][io]") {
  const Trajectory tum = read_trajectory(kData + "euroc_tum/MH_01_easy.txt.gz");
  REQUIRE(tum.size() == 36382);
  CHECK(tum.poses.back().t_ns == 1403636762743560000LL);
  CHECK(tum.poses.back().p.isApprox(Eigen::Vector3d(4.572531, -1.942023, 0.619620)));

  const Trajectory csv = read_trajectory(kData + "euroc_state_csv/V1_02_medium.csv.gz");
  REQUIRE(csv.size() == 16702);
  const StampedPose& first = csv.poses.front();
  CHECK(first.t_ns == 1403715524907143168LL);
  CHECK(first.t == static_cast<double>(1403715524907143168LL) / 1e9);
  CHECK(first.p.isApprox(Eigen::Vector3d(0.515356, 1.996773, 0.971104)));
  // w x y z in EuRoC csv.
  CHECK(first.q.w() == Approx(0.161996).margin(1e-5));
  CHECK(first.q.x() == Approx(0.789985).margin(1e-5));
  CHECK(first.q.z() == Approx(0.554528).margin(1e-5));
  CHECK(csv.poses.back().t_ns == 1403715608412143104LL);
}

TEST_CASE("read_trajectory reads an 11-column VINS-Fusion csv with trailing commas", "[eval][io]") {
  TempDir dir;
  const std::string path = dir.write("vins_result.csv",
                                     "1403636580838555648,1.0,2.0,3.0,1,0,0,0,0.1,0.2,0.3,\n"
                                     "1403636580888555648,1.5,2.0,3.0,0.7071068,0,0,0.7071068,0.1,0.2,0.3,\n");
  const Trajectory t = read_trajectory(path);
  REQUIRE(t.size() == 2);
  CHECK(t.poses[1].t_ns == 1403636580888555648LL);
  CHECK(t.poses[1].p.x() == 1.5);
  CHECK(t.poses[1].q.z() == Approx(std::sqrt(0.5)));
}

TEST_CASE("format detection and explicit formats", "[eval][io]") {
  const std::string csv = "#timestamp,x,y,z,qw,qx,qy,qz\n100,0,0,0,1,0,0,0\n200,1,0,0,1,0,0,0\n";
  CHECK(parse_trajectory(csv, "a.csv").size() == 2);
  CHECK(parse_trajectory(csv, "a.csv", TrajectoryFormat::EurocCsv).size() == 2);
  CHECK(parse_trajectory(kTumRows, "a.txt", TrajectoryFormat::Tum).size() == 3);
  // Forcing the wrong layout is an error on the first data row, not a silent misread.
  CHECK_THROWS_WITH(parse_trajectory(csv, "a.csv", TrajectoryFormat::Tum), Catch::StartsWith("a.csv:2:"));
  CHECK_THROWS_WITH(parse_trajectory(kTumRows, "a.txt", TrajectoryFormat::EurocCsv), Catch::StartsWith("a.txt:2:"));
  // Windows line endings and blank lines are fine.
  CHECK(parse_trajectory("1 0 0 0 0 0 0 1\r\n\r\n2 0 0 0 0 0 0 1\r\n", "crlf.txt").size() == 2);
}

TEST_CASE("write_tum round-trips time stamps exactly", "[eval][io]") {
  TempDir dir;
  const Trajectory in = read_trajectory(kData + "euroc_state_csv/V1_02_medium.csv.gz");
  const std::string out = (dir.path / "out.txt").string();
  write_tum(out, in);
  const Trajectory back = read_trajectory(out);
  REQUIRE(back.size() == in.size());
  for (std::size_t i = 0; i < in.size(); i += 997) {
    CHECK(back.poses[i].t_ns == in.poses[i].t_ns);
    CHECK((back.poses[i].p - in.poses[i].p).norm() < 1e-8);
    CHECK(back.poses[i].q.angularDistance(in.poses[i].q) < 1e-7);
  }
  CHECK_THROWS_WITH(write_tum((dir.path / "no_dir" / "x.txt").string(), in), Catch::Contains("no_dir"));
}

TEST_CASE("bad input: wrong column count names file and line", "[eval][io][bad]") {
  TempDir dir;
  require_error_at(dir.write("short_row.txt", kTumRows + "4.0 3 0 0 0 0 1\n"), 5, "found 7");
  require_error_at(dir.write("long_row.txt", "1.0 0 0 0 0 0 0 1 9\n"), 1, "found 9");
  require_error_at(dir.write("csv_row.csv", "#t,...\n100,0,0,0,1,0,0,0,5\n200,0,0,0,1,0,0,0\n"), 3,
                   "expected 9 columns");
  require_error_at(dir.write("csv_narrow.csv", "100,0,0,0,1,0,0\n"), 1, "at least 8");
}

TEST_CASE("bad input: a non-number names file, line and column", "[eval][io][bad]") {
  TempDir dir;
  require_error_at(dir.write("nan_text.txt", kTumRows + "4.0 3 0 0x 0 0 0 1\n"), 5, "column 4: '0x' is not a number");
  require_error_at(dir.write("word.txt", "1.0 0 0 0 0 0 0 one\n"), 1, "'one' is not a number");
  require_error_at(dir.write("inf.txt", "1.0 inf 0 0 0 0 0 1\n"), 1, "not finite");
  require_error_at(dir.write("empty_field.csv", "100,0,,0,1,0,0,0\n"), 1, "column 3 is empty");
  require_error_at(dir.write("float_ns.csv", "100.5,0,0,0,1,0,0,0\n"), 1, "not an integer number of nanoseconds");
  require_error_at(dir.write("extra_col.csv", "100,0,0,0,1,0,0,0,abc\n"), 1, "column 9");
  require_error_at(dir.write("zero_quat.txt", "1.0 0 0 0 0 0 0 0\n"), 1, "quaternion norm");
}

TEST_CASE("bad input: duplicate or decreasing time stamps", "[eval][io][bad]") {
  TempDir dir;
  require_error_at(dir.write("dup.txt", kTumRows + "3.0 3 0 0 0 0 0 1\n"), 5, "duplicates the one on line 4");
  require_error_at(dir.write("back.txt", kTumRows + "# comment\n2.5 3 0 0 0 0 0 1\n"), 6,
                   "goes back before the one on line 4");
  require_error_at(dir.write("dup.csv", "100,0,0,0,1,0,0,0\n100,0,0,0,1,0,0,0\n"), 2, "duplicates");
}

TEST_CASE("bad input: missing, empty, directory and truncated gzip files", "[eval][io][bad]") {
  TempDir dir;
  const std::string missing = (dir.path / "missing.txt").string();
  CHECK_THROWS_AS(read_trajectory(missing), TrajectoryFileError);
  CHECK_THROWS_WITH(read_trajectory(missing), Catch::StartsWith(missing + ": ") && Catch::Contains("no such file"));
  const std::string empty = dir.write("empty.txt", "# only a header\n\n");
  CHECK_THROWS_WITH(read_trajectory(empty), Catch::StartsWith(empty + ": ") && Catch::Contains("no poses"));
  CHECK_THROWS_WITH(read_trajectory(dir.path.string()), Catch::Contains("directory"));

  std::ifstream gz(kData + "euroc_tum/MH_02_easy.txt.gz", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(gz)), std::istreambuf_iterator<char>());
  REQUIRE(bytes.size() > 1000);
  const std::string cut = dir.write("cut.txt.gz", bytes.substr(0, bytes.size() / 2));
  CHECK_THROWS_WITH(read_trajectory(cut), Catch::StartsWith(cut + ": ") && Catch::Contains("read error"));
}
