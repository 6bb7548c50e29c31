#include "sim/motion/imu_simulator.hpp"

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

namespace dynavins::sim {

ImuSimulator::ImuSimulator(ImuSimulatorOptions options) : opt_(std::move(options)) {
  const ImuNoiseModel& n = opt_.noise;
  if (!(opt_.rate_hz > 0.0) || !std::isfinite(opt_.rate_hz))
    throw std::invalid_argument("ImuSimulator: rate must be > 0, got " + std::to_string(opt_.rate_hz));
  if (!std::isfinite(opt_.gravity)) throw std::invalid_argument("ImuSimulator: gravity must be finite");
  if (!(n.acc_noise_density >= 0.0) || !(n.gyr_noise_density >= 0.0) || !(n.acc_random_walk >= 0.0) ||
      !(n.gyr_random_walk >= 0.0) || !n.acc_bias_initial.allFinite() || !n.gyr_bias_initial.allFinite())
    throw std::invalid_argument("ImuSimulator: noise densities must be >= 0 and biases finite");
  period_ns_ = std::llround(1e9 / opt_.rate_hz);
  if (period_ns_ <= 0) throw std::invalid_argument("ImuSimulator: rate too high");
}

GroundTruthState ground_truth_at(const SmoothTrajectory& traj, int64_t t_ns) {
  const KinematicState s = traj.evaluate(static_cast<double>(t_ns) * 1e-9);
  GroundTruthState g;
  g.t_ns = t_ns;
  g.p_wb = s.p_w;
  g.v_wb = s.v_w;
  g.q_wb = Eigen::Quaterniond(s.R_wb).normalized();
  g.has_velocity = true;
  g.has_biases = false;
  return g;
}

ImuSample ImuSimulator::ideal_sample(const SmoothTrajectory& traj, double t) const {
  const KinematicState s = traj.evaluate(t);
  const Eigen::Vector3d g_w(0.0, 0.0, -opt_.gravity);
  ImuSample m;
  m.acc = s.R_wb.transpose() * (s.a_w - g_w);
  m.gyr = s.omega_b;
  return m;
}

ImuSimulation ImuSimulator::simulate(const SmoothTrajectory& traj) const {
  // First/last whole multiples of the period inside [t_min, t_max]. With absolute (epoch) times a double
  // resolves only ~0.2 us, so step inwards until the sample times really evaluate inside the range.
  auto first = static_cast<int64_t>(std::ceil(traj.t_min() * 1e9 / period_ns_));
  auto last = static_cast<int64_t>(std::floor(traj.t_max() * 1e9 / period_ns_));
  while (static_cast<double>(first * period_ns_) * 1e-9 < traj.t_min() - 1e-9) ++first;
  while (static_cast<double>(last * period_ns_) * 1e-9 > traj.t_max() + 1e-9) --last;
  if (last < first) throw std::invalid_argument("ImuSimulator::simulate: trajectory shorter than one period");
  return simulate(traj, first * period_ns_, last * period_ns_);
}

ImuSimulation ImuSimulator::simulate(const SmoothTrajectory& traj, int64_t t_begin_ns, int64_t t_end_ns) const {
  if (t_end_ns < t_begin_ns)
    throw std::invalid_argument("ImuSimulator::simulate: end " + std::to_string(t_end_ns) + " ns before begin " +
                                std::to_string(t_begin_ns) + " ns");
  const ImuNoiseModel& nm = opt_.noise;
  const double dt = static_cast<double>(period_ns_) * 1e-9;
  const double sa = nm.acc_noise_density / std::sqrt(dt);
  const double sg = nm.gyr_noise_density / std::sqrt(dt);
  const double sba = nm.acc_random_walk * std::sqrt(dt);
  const double sbg = nm.gyr_random_walk * std::sqrt(dt);

  std::mt19937_64 rng(opt_.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  auto gauss3 = [&]() {
    // Draw in a fixed order (x, y, z) so the stream is reproducible.
    const double x = normal(rng);
    const double y = normal(rng);
    const double z = normal(rng);
    return Eigen::Vector3d(x, y, z);
  };

  ImuSimulation out;
  const size_t count = static_cast<size_t>((t_end_ns - t_begin_ns) / period_ns_) + 1;
  out.samples.reserve(count);
  out.truth.reserve(count);
  Eigen::Vector3d ba = nm.acc_bias_initial;
  Eigen::Vector3d bg = nm.gyr_bias_initial;
  for (size_t k = 0; k < count; ++k) {
    const int64_t t_ns = t_begin_ns + static_cast<int64_t>(k) * period_ns_;
    const double t = static_cast<double>(t_ns) * 1e-9;
    const KinematicState s = traj.evaluate(t);  // throws if outside the trajectory
    const Eigen::Vector3d g_w(0.0, 0.0, -opt_.gravity);

    // Four draws per sample, always, so changing one density does not reshuffle the others' noise.
    const Eigen::Vector3d na = gauss3(), ng = gauss3(), wa = gauss3(), wg = gauss3();

    ImuSample m;
    m.t_ns = t_ns;
    m.acc = s.R_wb.transpose() * (s.a_w - g_w) + ba + sa * na;
    m.gyr = s.omega_b + bg + sg * ng;
    out.samples.push_back(m);

    GroundTruthState g;
    g.t_ns = t_ns;
    g.p_wb = s.p_w;
    g.q_wb = Eigen::Quaterniond(s.R_wb).normalized();
    g.v_wb = s.v_w;
    g.bias_acc = ba;
    g.bias_gyr = bg;
    g.has_velocity = true;
    g.has_biases = true;
    out.truth.push_back(g);

    ba += sba * wa;
    bg += sbg * wg;
  }
  return out;
}

}  // namespace dynavins::sim
