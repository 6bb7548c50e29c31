// Reading TUM trajectories (plain and gzip, with errors that name file and line) and fitting real
// EuRoC / TUM-VI ground truth: residuals, glitch removal, and the strongest check available here: the IMU
// simulated from the fitted EuRoC V1_01 ground truth against the real ADIS16448 of that flight.
#include <catch2/catch.hpp>

#include <zlib.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <unistd.h>

#include "sim/motion/imu_simulator.hpp"
#include "sim/motion/tum_trajectory.hpp"

using namespace dynavins::sim;

namespace {

const std::string kTraj = std::string(DYNAVINS_SHARED_DIR) + "/data/trajectories/";

// A scratch file that removes itself.
struct TempFile {
  std::string path;
  explicit TempFile(const std::string& name) : path("/tmp/dynavins_test_tum_" + std::to_string(getpid()) + "_" + name) {}
  ~TempFile() { std::remove(path.c_str()); }
  void write(const std::string& text) const { std::ofstream(path) << text; }
  void write_gz(const std::string& text) const {
    gzFile f = gzopen(path.c_str(), "wb");
    gzwrite(f, text.data(), static_cast<unsigned>(text.size()));
    gzclose(f);
  }
};

const char* kGood =
    "# timestamp tx ty tz qx qy qz qw\n"
    "100.0 1 2 3 0 0 0 1\n"
    "\n"
    "100.5 1.5 2 3 0 0 0.7071068 0.7071068\n"
    "101.0 2 2 3 0 0 1 0";

std::string error_of(const std::string& path) {
  try {
    read_tum_trajectory(path);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

// EuRoC imu0/data.csv: t_ns, gyro xyz, acc xyz.
struct RealImu {
  std::vector<int64_t> t;
  std::vector<Eigen::Vector3d> gyr, acc;
};
RealImu read_euroc_imu(const std::string& path) {
  std::ifstream in(path);
  REQUIRE(in.good());
  RealImu r;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    for (char& c : line)
      if (c == ',') c = ' ';
    std::istringstream ss(line);
    long long t;
    double v[6];
    ss >> t >> v[0] >> v[1] >> v[2] >> v[3] >> v[4] >> v[5];
    r.t.push_back(t);
    r.gyr.emplace_back(v[0], v[1], v[2]);
    r.acc.emplace_back(v[3], v[4], v[5]);
  }
  return r;
}

}  // namespace

TEST_CASE("read_tum_trajectory reads plain and gzip files alike", "[sim][tum_trajectory]") {
  TempFile plain("good.txt"), gz("good.txt.gz");
  plain.write(kGood);
  gz.write_gz(kGood);
  const std::vector<TimedPose> a = read_tum_trajectory(plain.path), b = read_tum_trajectory(gz.path);
  REQUIRE(a.size() == 3);  // comment and blank line skipped, last line without newline kept
  REQUIRE(b.size() == 3);
  for (size_t i = 0; i < 3; ++i) {
    CHECK(a[i].t == b[i].t);
    CHECK(a[i].p == b[i].p);
    CHECK(a[i].q.coeffs() == b[i].q.coeffs());
  }
  CHECK(a[1].t == 100.5);
  CHECK(a[1].p == Eigen::Vector3d(1.5, 2, 3));
  // File order is qx qy qz qw: a 90° yaw.
  CHECK(a[1].q.angularDistance(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()))) < 1e-6);
  CHECK(std::abs(a[1].q.norm() - 1.0) < 1e-15);
}

TEST_CASE("read_tum_trajectory reads a real EuRoC ground truth file", "[sim][tum_trajectory]") {
  const std::vector<TimedPose> p = read_tum_trajectory(kTraj + "euroc_tum/MH_01_easy.txt.gz");
  // 181.9 s at 200 Hz; first row: 1403636580.83856 4.688319 -1.786938 0.783338 -0.153029 -0.827383 -0.082152 0.534108
  CHECK(p.size() == 36382);
  CHECK(p.front().t == 1403636580.83856);
  CHECK(p.front().p == Eigen::Vector3d(4.688319, -1.786938, 0.783338));
  CHECK(std::abs(p.front().q.w() - 0.534108) < 1e-6);
  CHECK(p.back().t - p.front().t == Approx(181.9).margin(0.05));
}

TEST_CASE("read_tum_trajectory names file and line of bad input", "[sim][tum_trajectory]") {
  TempFile f("bad.txt");
  f.write("# header\n1.0 0 0 0 0 0 0 1\n2.0 0 0 0 0 0 1\n");
  std::string e = error_of(f.path);
  CHECK_THAT(e, Catch::Contains(f.path + ":3:") && Catch::Contains("8 columns"));

  f.write("1.0 0 0 0 0 0 0 1\n2.0 0 zero 0 0 0 0 1\n");
  CHECK_THAT(error_of(f.path), Catch::Contains(":2:") && Catch::Contains("column 3") && Catch::Contains("zero"));

  f.write("1.0 0 0 0 0 0 0 1\n2.0 0 0 0 0 0 0 1\n1.5 0 0 0 0 0 0 1\n");
  CHECK_THAT(error_of(f.path), Catch::Contains(":3:") && Catch::Contains("goes back"));

  f.write("1.0 0 0 0 0 0 0 1\n1.0 0 0 0 0 0 0 1\n");
  CHECK_THAT(error_of(f.path), Catch::Contains(":2:"));

  f.write("1.0 0 0 0 0 0 0 2\n");
  CHECK_THAT(error_of(f.path), Catch::Contains(":1:") && Catch::Contains("quaternion"));

  f.write("1.0 0 0 nan 0 0 0 1\n");
  CHECK_THAT(error_of(f.path), Catch::Contains(":1:") && Catch::Contains("finite"));

  f.write("# only a comment\n");
  CHECK_THAT(error_of(f.path), Catch::Contains("no poses"));

  CHECK_THAT(error_of("/nonexistent/dir/traj.txt"), Catch::Contains("/nonexistent/dir/traj.txt") && Catch::Contains("no such file"));

  // A truncated gzip stream is a read error, not a silently shorter trajectory.
  TempFile gz("trunc.txt.gz");
  std::string big;
  for (int i = 0; i < 2000; ++i) big += std::to_string(i) + ".0 1 2 3 0 0 0 1\n";
  gz.write_gz(big);
  std::ifstream in(gz.path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  in.close();
  std::ofstream(gz.path, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  CHECK_THAT(error_of(gz.path), Catch::Contains(gz.path) && Catch::Contains("read error"));
}

TEST_CASE("remove_position_jumps removes steps and outliers but keeps hard motion", "[sim][tum_trajectory]") {
  // 200 Hz, 1 m/s along x, a vertical bump of 10 g peak acceleration starting abruptly (real, violent
  // motion), then a 5 cm step and a 2 cm single-sample outlier (glitches).
  const double kPi = 3.14159265358979323846, f = 7.0, amp = 0.05;  // peak acc amp (2 pi f)^2 = 96.7 m/s^2
  auto bump = [&](double t) { return t > 1.0 && t < 1.0 + 1.0 / f ? amp * (1.0 - std::cos(2 * kPi * f * (t - 1.0))) : 0.0; };
  std::vector<TimedPose> p;
  for (int m = 0; m < 600; ++m) {
    TimedPose s;
    s.t = m * 0.005;
    s.p = Eigen::Vector3d(s.t, 0, bump(s.t));
    if (m >= 300) s.p.y() += 0.05;
    if (m == 450) s.p.z() += 0.02;
    p.push_back(s);
  }
  std::vector<TimedPose> q = p;
  CHECK(remove_position_jumps(q, 50.0) == 3);  // the step, and the outlier's way out and back
  for (size_t m = 0; m < q.size(); ++m) {
    INFO("sample " << m);
    CHECK(std::abs(q[m].p.y()) < 1e-12);
    CHECK(std::abs(q[m].p.z() - bump(q[m].t)) < 1e-12);
  }
  q = p;
  CHECK(remove_position_jumps(q, 0.0) == 0);  // disabled
}

TEST_CASE("fit_tum_trajectory window, time shift and residual on real EuRoC data", "[sim][tum_trajectory]") {
  const std::string path = kTraj + "euroc_tum/V1_02_medium.txt.gz";
  const std::vector<TimedPose> all = read_tum_trajectory(path);
  TumFitOptions o;
  o.window_start = 20.0;
  o.window_duration = 10.0;
  TumFitReport rep;
  const SmoothTrajectory tr = fit_tum_trajectory(path, o, &rep);
  const std::vector<TimedPose> win = select_window(all, 20.0, 10.0);
  CHECK(tr.t_min() == 0.0);
  CHECK(tr.duration() == Approx(win.back().t - win.front().t));
  CHECK(rep.time_offset == win.front().t);
  CHECK(rep.fit.num_samples == static_cast<int>(win.size()));
  CHECK(rep.fit.converged);
  CHECK(rep.removed_jumps == 0);
  INFO("V1_02 [20 s, 30 s]: residual pos RMS " << rep.fit.position_rms << " max " << rep.fit.position_max
                                               << " m, rot RMS " << rep.fit.rotation_rms << " max "
                                               << rep.fit.rotation_max << " rad; max |a| " << rep.fit.max_acceleration
                                               << " m/s^2, max |ω| " << rep.fit.max_angular_velocity << " rad/s");
  // The spline stays within the accuracy of the motion capture itself (~1 mm, ~0.1°; the fit's σ).
  CHECK(rep.fit.position_rms < 1e-3);
  CHECK(rep.fit.rotation_rms < 2e-3);
  CHECK(rep.fit.position_max < 3e-3);
  // Samples inside the window map to trajectory time t - offset.
  const TimedPose& s = win[win.size() / 2];
  CHECK((tr.position(s.t - rep.time_offset) - s.p).norm() < 3e-3);

  TumFitOptions keep = o;
  keep.shift_to_zero = false;
  TumFitReport rep2;
  const SmoothTrajectory tr2 = fit_tum_trajectory(path, keep, &rep2);
  CHECK(rep2.time_offset == 0.0);
  CHECK(tr2.t_min() == win.front().t);

  o.window_start = 1000.0;
  CHECK_THROWS_AS(fit_tum_trajectory(path, o), std::invalid_argument);
}

TEST_CASE("fit_tum_trajectory places the file's world in ours and renames the body axes", "[sim][tum_trajectory]") {
  const std::string path = kTraj + "euroc_tum/V1_02_medium.txt.gz";
  TumFitOptions o;
  o.window_start = 20.0;
  o.window_duration = 5.0;
  TumFitReport rep;
  const SmoothTrajectory plain = fit_tum_trajectory(path, o, &rep);
  TumFitOptions placed = o;
  placed.world_from_file.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  placed.world_from_file.translation() = Eigen::Vector3d(20, -3, 0.5);
  placed.file_body_from_body << 0, 0, 1, 0, -1, 0, 1, 0, 0;
  const SmoothTrajectory moved = fit_tum_trajectory(path, placed);
  for (double t : {0.5, 2.0, 4.5}) {
    INFO("t = " << t);
    // The body origin moves with the world; the body axes are renamed, not moved.
    CHECK((moved.position(t) - placed.world_from_file * plain.position(t)).norm() < 1e-6);
    const Eigen::Matrix3d expect = placed.world_from_file.linear() * plain.rotation(t) * placed.file_body_from_body;
    CHECK(Eigen::AngleAxisd(moved.rotation(t).transpose() * expect).angle() < 1e-6);
    // The IMU sees the same motion in the renamed axes: ω_new = R_bodyᵀ ω_file.
    CHECK((moved.angular_velocity(t) - placed.file_body_from_body.transpose() * plain.angular_velocity(t)).norm() <
          1e-5);
  }
}

TEST_CASE("fit_tum_trajectory removes EuRoC MH_04's 13 cm ground-truth glitch", "[sim][tum_trajectory]") {
  // MH_04_difficult has a position step of 13 cm within 5 ms at 45.005 s after its start.
  const std::string path = kTraj + "euroc_tum/MH_04_difficult.txt.gz";
  TumFitOptions o;
  o.window_start = 40.0;
  o.window_duration = 10.0;
  TumFitReport on, off;
  fit_tum_trajectory(path, o, &on);
  o.glitch_acceleration = 0.0;
  fit_tum_trajectory(path, o, &off);
  INFO("with removal: " << on.removed_jumps << " glitches, max |a| " << on.fit.max_acceleration << " m/s^2, max residual "
                        << on.fit.position_max << " m; without: max |a| " << off.fit.max_acceleration
                        << " m/s^2, max residual " << off.fit.position_max << " m");
  CHECK(on.removed_jumps >= 1);
  // A 13 cm jump in 5 ms is not motion; fitted as such it becomes a ~50 m/s^2 spike.
  CHECK(off.fit.max_acceleration > 30.0);
  CHECK(on.fit.max_acceleration < 15.0);
  CHECK(on.fit.position_max < 0.01);
}

TEST_CASE("IMU simulated from EuRoC V1_01 ground truth matches the real ADIS16448", "[sim][tum_trajectory]") {
  // vicon2gt ground truth (20 Hz, with IMU biases in the csv) fitted with default options; the real IMU of
  // the same flight ships in euroc_v1_01_micro. Both are averaged over 0.1 s (20 samples), which removes
  // the airframe vibration (1.5 m/s^2 RMS raw) that no trajectory fit can know.
  TumFitOptions o;
  o.shift_to_zero = false;
  TumFitReport rep;
  const SmoothTrajectory tr = fit_tum_trajectory(kTraj + "euroc_tum/V1_01_easy_vicon2gt_20hz.txt.gz", o, &rep);
  const RealImu real = read_euroc_imu(std::string(DYNAVINS_SHARED_DIR) + "/data/euroc_v1_01_micro/mav0/imu0/data.csv");
  ImuSimulatorOptions so;
  so.noise = ImuNoiseModel::noise_free();
  const ImuSimulator sim(so);
  std::vector<Eigen::Vector3d> rg, ra, sg, sa;
  for (size_t k = 0; k < real.t.size(); ++k) {
    const double t = real.t[k] * 1e-9;
    if (t < tr.t_min() + 1.0 || t > tr.t_max() - 1.0) continue;
    const dynavins::ImuSample s = sim.ideal_sample(tr, t);
    rg.push_back(real.gyr[k]);
    ra.push_back(real.acc[k]);
    sg.push_back(s.gyr);
    sa.push_back(s.acc);
  }
  REQUIRE(rg.size() > 20000);
  const size_t n = rg.size();
  Eigen::Vector3d bg = Eigen::Vector3d::Zero(), ba = Eigen::Vector3d::Zero(), ma = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < n; ++k) {
    bg += (rg[k] - sg[k]) / n;
    ba += (ra[k] - sa[k]) / n;
    ma += sa[k] / n;
  }
  // Box averages of the bias-corrected differences and of the simulated signal (minus its mean).
  auto compare = [&](int W, const std::vector<Eigen::Vector3d>& real_x, const std::vector<Eigen::Vector3d>& sim_x,
                     const Eigen::Vector3d& offset, const Eigen::Vector3d& mean, double& err, double& sig) {
    err = sig = 0.0;
    int m = 0;
    for (size_t k = 0; k + W <= n; k += W) {
      Eigen::Vector3d d = Eigen::Vector3d::Zero(), x = Eigen::Vector3d::Zero();
      for (size_t j = k; j < k + W; ++j) {
        d += (real_x[j] - sim_x[j] - offset) / W;
        x += (sim_x[j] - mean) / W;
      }
      err += d.squaredNorm();
      sig += x.squaredNorm();
      ++m;
    }
    err = std::sqrt(err / m);
    sig = std::sqrt(sig / m);
  };
  double eg, sig_g, ea, sig_a, ea_long, sig_a_long;
  compare(20, rg, sg, bg, Eigen::Vector3d::Zero(), eg, sig_g);  // 0.1 s
  compare(20, ra, sa, ba, ma, ea, sig_a);                       // 0.1 s
  compare(100, ra, sa, ba, ma, ea_long, sig_a_long);            // 0.5 s
  // Biases the csv of the same ground truth reports (first row; they drift by < 0.05 m/s^2 over the run).
  const Eigen::Vector3d csv_bg(-0.00224703, 0.0215352, 0.0770299), csv_ba(-0.0180115, 0.0659796, 0.0309774);
  INFO("fit residual pos " << rep.fit.position_rms << " m rot " << rep.fit.rotation_rms << " rad");
  INFO("gyro: error RMS " << eg << " rad/s of signal " << sig_g << "; mean offset " << bg.transpose() << " vs csv bias "
                          << csv_bg.transpose());
  INFO("acc: error RMS " << ea << " m/s^2 of dynamic signal " << sig_a << " (0.5 s averages: " << ea_long << " of "
                         << sig_a_long << "); mean offset " << ba.transpose() << " vs csv bias " << csv_ba.transpose());
  // The simulated rates carry the real motion: the error is a small fraction of the signal.
  CHECK(eg < 0.1 * sig_g);
  CHECK(ea < 0.5 * sig_a);
  // V1_01 is a gentle flight (0.3-0.4 m/s^2 of dynamic signal), so the accelerometer is judged in absolute
  // terms, over 0.5 s where the vibration has averaged out. What the fit cannot know: bias drift (the csv's
  // b_a moves by 0.04 m/s^2 over the run, ±0.02), the ground truth's orientation error (~0.2° = 0.035 m/s^2
  // of gravity), leftover vibration (~0.03): about 0.05 m/s^2 together; twice that is the bound.
  CHECK(ea_long < 0.1);
  // Frames, signs and gravity are right: what remains on average is the sensor's own bias.
  CHECK((bg - csv_bg).norm() < 0.002);
  CHECK((ba - csv_ba).norm() < 0.15);
}

TEST_CASE("Fitted EuRoC velocity agrees with the velocity of the ground-truth csv", "[sim][tum_trajectory]") {
  // V1_02_medium: the TUM file holds the poses of the ASL state csv, whose velocity column the fit never
  // sees. The spline's derivative must reproduce it; what it smooths away (> ~7 Hz, ~0.1 mm) is worth
  // ~2 pi 10 Hz * 1e-4 m ~ 0.006 m/s, so 0.03 m/s RMS is a generous bound (the motion reaches ~1.5 m/s).
  TumFitOptions o;
  o.shift_to_zero = false;
  const SmoothTrajectory tr = fit_tum_trajectory(kTraj + "euroc_tum/V1_02_medium.txt.gz", o);
  gzFile f = gzopen((kTraj + "euroc_state_csv/V1_02_medium.csv.gz").c_str(), "rb");
  REQUIRE(f != nullptr);
  char buf[1024];
  double e2 = 0.0, vmax = 0.0;
  int n = 0;
  while (gzgets(f, buf, sizeof(buf))) {
    if (buf[0] == '#') continue;
    std::string line(buf);
    for (char& c : line)
      if (c == ',') c = ' ';
    std::istringstream ss(line);
    long long t_ns;
    double v[16];
    ss >> t_ns;
    for (double& x : v) ss >> x;
    const double t = t_ns * 1e-9;
    if (t < tr.t_min() + 0.5 || t > tr.t_max() - 0.5) continue;
    const Eigen::Vector3d v_csv(v[7], v[8], v[9]);
    e2 += (tr.velocity(t) - v_csv).squaredNorm();
    vmax = std::max(vmax, v_csv.norm());
    ++n;
  }
  gzclose(f);
  REQUIRE(n > 15000);
  const double rms = std::sqrt(e2 / n);
  INFO("velocity difference RMS " << rms << " m/s over " << n << " samples, max speed " << vmax << " m/s");
  CHECK(vmax > 1.0);
  CHECK(rms < 0.03);
}

TEST_CASE("fit_tum_trajectory handles TUM-VI mocap with dropouts", "[sim][tum_trajectory]") {
  // room1 is ~120 Hz with dropouts up to 1 s (no glitch removal across them) and fast hand-held motion.
  TumFitReport rep;
  const SmoothTrajectory tr = fit_tum_trajectory(kTraj + "tumvi_tum/dataset-room1_512_16.txt.gz", {}, &rep);
  INFO("room1: " << rep.fit.num_samples << " poses, residual pos RMS " << rep.fit.position_rms << " max "
                 << rep.fit.position_max << " m, rot RMS " << rep.fit.rotation_rms << " max " << rep.fit.rotation_max
                 << " rad; glitches " << rep.removed_jumps << "; max |a| " << rep.fit.max_acceleration
                 << " max |ω| " << rep.fit.max_angular_velocity);
  CHECK(rep.fit.converged);
  CHECK(tr.duration() > 100.0);
  CHECK(rep.fit.position_rms < 1e-3);
  CHECK(rep.fit.rotation_rms < 5e-3);
}
