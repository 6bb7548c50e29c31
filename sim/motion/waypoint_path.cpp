#include "sim/motion/waypoint_path.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "stages/common/so3.hpp"

namespace dynavins::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

double wrap_angle(double a) { return std::remainder(a, 2.0 * kPi); }  // to [-pi, pi]

std::invalid_argument path_error(const std::string& what) { return std::invalid_argument("path: " + what); }

// A straight line or a circular arc of the rounded path, parametrised by arc length s in [0, length].
struct Piece {
  bool arc = false;
  Eigen::Vector3d a = Eigen::Vector3d::Zero();  // start point
  Eigen::Vector3d u = Eigen::Vector3d::Zero();  // initial unit tangent
  Eigen::Vector3d n = Eigen::Vector3d::Zero();  // arc: unit normal pointing to the centre
  double r = 0.0;                               // arc radius
  double length = 0.0;
  // Arc: centre c = a + r n, point at angle φ = s/r is c + r(-n cos φ + u sin φ).
  Eigen::Vector3d position(double s) const {
    if (!arc) return a + s * u;
    const double phi = s / r;
    return a + r * ((1.0 - std::cos(phi)) * n + std::sin(phi) * u);
  }
  Eigen::Vector3d tangent(double s) const {
    if (!arc) return u;
    const double phi = s / r;
    return std::cos(phi) * u + std::sin(phi) * n;
  }
};

// The path between two consecutive stops, with its speed profile on a grid of arc length.
struct Move {
  std::vector<Piece> pieces;
  std::vector<double> piece_start;         // cumulative arc length at each piece's start
  std::vector<std::pair<double, int>> wp;  // (arc length, waypoint index) of the waypoints on this move
  double length = 0.0;
  // Grid
  double ds = 0.0;
  std::vector<double> t, v;            // time since the move started, speed
  std::vector<Eigen::Matrix3d> R;      // orientation at the nodes

  Eigen::Vector3d position(double s) const {
    const auto it = std::upper_bound(piece_start.begin(), piece_start.end(), s);
    const size_t k = it == piece_start.begin() ? 0 : static_cast<size_t>(it - piece_start.begin()) - 1;
    return pieces[k].position(std::clamp(s - piece_start[k], 0.0, pieces[k].length));
  }
  Eigen::Vector3d tangent(double s) const {
    const auto it = std::upper_bound(piece_start.begin(), piece_start.end(), s);
    const size_t k = it == piece_start.begin() ? 0 : static_cast<size_t>(it - piece_start.begin()) - 1;
    return pieces[k].tangent(std::clamp(s - piece_start[k], 0.0, pieces[k].length));
  }
  double speed_limit(double s, const PathProfile& prof) const {
    const auto it = std::upper_bound(piece_start.begin(), piece_start.end(), s);
    const size_t k = it == piece_start.begin() ? 0 : static_cast<size_t>(it - piece_start.begin()) - 1;
    double lim = prof.cruise_speed;
    // Nodes exactly at a piece boundary belong to both pieces: take the stricter limit.
    for (size_t j : {k, k > 0 ? k - 1 : k})
      if (pieces[j].arc && s >= piece_start[j] - 1e-12 && s <= piece_start[j] + pieces[j].length + 1e-12)
        lim = std::min(lim, std::sqrt(prof.max_lateral_acc * pieces[j].r));
    return lim;
  }
  double duration() const { return t.back(); }
  // Arc length and orientation at time tau since the move started. Within a grid interval the
  // acceleration is constant (exact for the forward-backward profile), so s(τ) = v_j τ + a_j τ^2 / 2.
  void at(double tau, double& s, Eigen::Matrix3d& Rout) const {
    tau = std::clamp(tau, 0.0, t.back());
    auto it = std::upper_bound(t.begin(), t.end(), tau);
    size_t j = it == t.begin() ? 0 : static_cast<size_t>(it - t.begin()) - 1;
    j = std::min(j, t.size() - 2);
    const double acc = (v[j + 1] * v[j + 1] - v[j] * v[j]) / (2.0 * ds);
    const double d = tau - t[j];
    const double frac = std::clamp((v[j] * d + 0.5 * acc * d * d) / ds, 0.0, 1.0);
    s = std::min((static_cast<double>(j) + frac) * ds, length);
    Rout = R[j] * so3::exp(frac * so3::log(R[j].transpose() * R[j + 1]));
  }
};

// Quintic smoothstep: zero first and second derivatives at both ends; peak slope 15/8.
double smoothstep5(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * x * (10.0 + x * (-15.0 + 6.0 * x));
}

void validate(const std::vector<PathWaypoint>& w, const PathProfile& p) {
  if (w.size() < 2) throw path_error("need at least 2 waypoints, got " + std::to_string(w.size()));
  for (size_t i = 0; i < w.size(); ++i) {
    const std::string at = "waypoint " + std::to_string(i) + ": ";
    if (!w[i].p.allFinite() || !std::isfinite(w[i].pitch) || !std::isfinite(w[i].roll) ||
        (w[i].yaw && !std::isfinite(*w[i].yaw)) || !std::isfinite(w[i].dwell) || w[i].dwell < 0.0)
      throw path_error(at + "non-finite value or negative dwell");
    if (p.heading == HeadingMode::kWaypoints && !w[i].yaw) throw path_error(at + "yaw required by HeadingMode::kWaypoints");
    if (i > 0 && (w[i].p - w[i - 1].p).norm() < 1e-6)
      throw path_error(at + "coincides with the previous waypoint (use dwell to wait)");
  }
  auto pos = [](double x) { return x > 0.0 && std::isfinite(x); };
  if (!pos(p.cruise_speed) || !pos(p.max_lateral_acc) || !pos(p.max_longitudinal_acc) || !pos(p.corner_radius) ||
      !pos(p.max_yaw_rate) || !pos(p.sample_dt) || !(p.max_corner_angle > 0.0 && p.max_corner_angle <= kPi) ||
      !(p.start_dwell >= 0.0) || !(p.end_dwell >= 0.0) || !std::isfinite(p.yaw_offset) ||
      !(p.smoothing_time >= 0.0) || !std::isfinite(p.smoothing_time))
    throw path_error("profile limits must be > 0 (dwells and smoothing >= 0, max_corner_angle in (0, pi])");
}

// Orientation of each waypoint's scripted angles, with yaws unwrapped along the list (shortest turn).
std::vector<double> unwrapped_waypoint_yaws(const std::vector<PathWaypoint>& w) {
  std::vector<double> y(w.size(), 0.0);
  for (size_t i = 0; i < w.size(); ++i) {
    const double raw = w[i].yaw.value_or(0.0);
    y[i] = i == 0 ? raw : y[i - 1] + wrap_angle(raw - y[i - 1]);
  }
  return y;
}

// Linear interpolation of per-waypoint values along the move's arc length.
double interpolate_along(const Move& m, const std::vector<double>& values, double s) {
  const auto& wp = m.wp;
  if (s <= wp.front().first) return values[wp.front().second];
  for (size_t k = 1; k < wp.size(); ++k)
    if (s <= wp[k].first) {
      const double f = (s - wp[k - 1].first) / std::max(wp[k].first - wp[k - 1].first, 1e-12);
      return (1.0 - f) * values[wp[k - 1].second] + f * values[wp[k].second];
    }
  return values[wp.back().second];
}

// Builds the rounded geometry of the waypoints a..b (a and b are stops, the ones between are rounded).
Move build_move(const std::vector<PathWaypoint>& w, int a, int b, const PathProfile& prof) {
  // Tangent length and arc of each interior corner.
  const int n = b - a + 1;
  std::vector<double> tl(n, 0.0);
  std::vector<Piece> arcs(n);
  for (int k = 1; k + 1 < n; ++k) {
    const int i = a + k;
    const Eigen::Vector3d din = w[i].p - w[i - 1].p, dout = w[i + 1].p - w[i].p;
    const Eigen::Vector3d uin = din.normalized(), uout = dout.normalized();
    const double theta = std::acos(std::clamp(uin.dot(uout), -1.0, 1.0));
    if (theta < 1e-6) continue;
    const double tan_half = std::tan(0.5 * theta);
    // Half of each adjacent leg at most, so neighbouring roundings never overlap.
    const double r = std::min(prof.corner_radius, 0.5 * std::min(din.norm(), dout.norm()) / tan_half);
    tl[k] = r * tan_half;
    Piece& arc = arcs[k];
    arc.arc = true;
    arc.r = r;
    arc.a = w[i].p - tl[k] * uin;
    arc.u = uin;
    arc.n = (uout - uout.dot(uin) * uin).normalized();
    arc.length = r * theta;
  }
  Move m;
  double s = 0.0;
  auto push = [&](const Piece& p) {
    if (p.length <= 0.0) return;
    m.piece_start.push_back(s);
    m.pieces.push_back(p);
    s += p.length;
  };
  m.wp.emplace_back(0.0, a);
  for (int k = 0; k + 1 < n; ++k) {
    const int i = a + k;
    const Eigen::Vector3d u = (w[i + 1].p - w[i].p).normalized();
    Piece line;
    line.a = w[i].p + tl[k] * u;
    line.u = u;
    line.length = std::max(0.0, (w[i + 1].p - w[i].p).norm() - tl[k] - tl[k + 1]);
    push(line);
    if (k + 2 < n) {
      m.wp.emplace_back(s + 0.5 * arcs[k + 1].length, i + 1);  // the rounded corner's midpoint
      if (arcs[k + 1].arc) push(arcs[k + 1]);
    }
  }
  m.wp.emplace_back(s, b);
  m.length = s;
  return m;
}

// Speed profile on a grid: limits (cruise, lateral acceleration on arcs, rotation rate), then a forward
// pass (speeding up) and a backward pass (braking) at the longitudinal limit, rest at both ends.
void profile_move(Move& m, const PathProfile& prof, const std::vector<double>& pitch, const std::vector<double>& roll,
                 const std::vector<double>& wp_yaw, double& last_yaw) {
  const int segs = std::max(20, static_cast<int>(std::ceil(m.length / 0.005)));
  const int nn = segs + 1;
  m.ds = m.length / segs;
  std::vector<double> yaw(nn, std::numeric_limits<double>::quiet_NaN());
  if (prof.heading == HeadingMode::kAlongPath) {
    for (int j = 0; j < nn; ++j) {
      const Eigen::Vector3d tg = m.tangent(j * m.ds);
      if (tg.head<2>().norm() > 1e-6) yaw[j] = std::atan2(tg.y(), tg.x()) + prof.yaw_offset;
    }
    // Vertical stretches keep the last horizontal heading; a move starting vertically takes its first one.
    double carry = last_yaw;
    for (int j = 0; j < nn; ++j)
      if (!std::isnan(yaw[j])) {
        carry = yaw[j];
        break;
      }
    carry = last_yaw + wrap_angle(carry - last_yaw);
    for (int j = 0; j < nn; ++j) {
      if (std::isnan(yaw[j])) {
        yaw[j] = carry;
      } else {
        yaw[j] = carry + wrap_angle(yaw[j] - carry);
        carry = yaw[j];
      }
    }
  } else {
    for (int j = 0; j < nn; ++j) yaw[j] = interpolate_along(m, wp_yaw, j * m.ds);
  }
  last_yaw = yaw.back();
  m.R.resize(nn);
  for (int j = 0; j < nn; ++j) {
    const double s = j * m.ds;
    m.R[j] = so3::from_yaw_pitch_roll(yaw[j], interpolate_along(m, pitch, s), interpolate_along(m, roll, s));
  }
  std::vector<double> lim(nn);
  for (int j = 0; j < nn; ++j) lim[j] = m.speed_limit(j * m.ds, prof);
  for (int j = 0; j + 1 < nn; ++j) {
    const double rate = so3::log(m.R[j].transpose() * m.R[j + 1]).norm() / m.ds;  // rad per metre
    if (rate > 0.0) {
      const double vmax = prof.max_yaw_rate / rate;
      lim[j] = std::min(lim[j], vmax);
      lim[j + 1] = std::min(lim[j + 1], vmax);
    }
  }
  m.v.assign(nn, 0.0);
  const double two_a_ds = 2.0 * prof.max_longitudinal_acc * m.ds;
  for (int j = 1; j + 1 < nn; ++j) m.v[j] = std::min(lim[j], std::sqrt(m.v[j - 1] * m.v[j - 1] + two_a_ds));
  for (int j = nn - 2; j >= 1; --j) m.v[j] = std::min(m.v[j], std::sqrt(m.v[j + 1] * m.v[j + 1] + two_a_ds));
  m.t.assign(nn, 0.0);
  for (int j = 1; j < nn; ++j) m.t[j] = m.t[j - 1] + 2.0 * m.ds / (m.v[j - 1] + m.v[j]);
}

// One stretch of the timeline.
struct Phase {
  enum Kind { kStill, kTurn, kMove } kind = kStill;
  double t0 = 0.0, duration = 0.0;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R0 = Eigen::Matrix3d::Identity(), R1 = Eigen::Matrix3d::Identity();
  const Move* move = nullptr;
};

// Centred moving average over 2h+1 samples, the ends extended by repeating the end samples (the path
// stands still there). Orientations are averaged in the tangent space of the centre sample.
void box_filter(std::vector<TimedPose>& x, int h) {
  if (h <= 0) return;
  const int n = static_cast<int>(x.size());
  auto at = [&](int i) -> const TimedPose& { return x[std::clamp(i, 0, n - 1)]; };
  std::vector<TimedPose> y = x;
  const double w = 1.0 / (2 * h + 1);
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3d p = Eigen::Vector3d::Zero(), phi = Eigen::Vector3d::Zero();
    const Eigen::Matrix3d Rc = x[i].q.toRotationMatrix();
    for (int k = -h; k <= h; ++k) {
      p += at(i + k).p;
      phi += so3::log(Rc.transpose() * at(i + k).q.toRotationMatrix());
    }
    y[i].p = w * p;
    y[i].q = Eigen::Quaterniond(Rc * so3::exp(w * phi)).normalized();
  }
  x = std::move(y);
}

}  // namespace

TrajectoryFitOptions default_script_fit_options() {
  TrajectoryFitOptions o;
  o.knot_spacing = 0.1;
  o.position_sigma = 1e-3;
  o.rotation_sigma = 1e-3;
  return o;
}

SmoothTrajectory trajectory_from_timed_waypoints(const std::vector<Waypoint>& waypoints, const TrajectoryFitOptions& fit,
                                              TrajectoryFitReport* report) {
  std::vector<TimedPose> poses;
  poses.reserve(waypoints.size());
  for (size_t i = 0; i < waypoints.size(); ++i) {
    const Waypoint& w = waypoints[i];
    if (!std::isfinite(w.yaw) || !std::isfinite(w.pitch) || !std::isfinite(w.roll))
      throw std::invalid_argument("timed waypoint " + std::to_string(i) + ": non-finite angle");
    poses.push_back({w.t, w.p, Eigen::Quaterniond(so3::from_yaw_pitch_roll(w.yaw, w.pitch, w.roll))});
  }
  return fit_trajectory(poses, fit, report);
}

PathProfile PathProfile::car() {
  PathProfile p;
  p.cruise_speed = 8.0;
  p.max_lateral_acc = 2.5;
  p.max_longitudinal_acc = 1.5;
  p.corner_radius = 8.0;
  p.max_yaw_rate = 0.6;
  p.smoothing_time = 1.2;
  return p;
}

PathProfile PathProfile::drone() {
  PathProfile p;
  p.cruise_speed = 1.5;
  p.max_lateral_acc = 1.5;
  p.max_longitudinal_acc = 1.0;
  p.corner_radius = 1.0;
  p.max_yaw_rate = 1.0;
  return p;
}

PathProfile PathProfile::handheld() {
  PathProfile p;
  p.cruise_speed = 1.2;
  p.max_lateral_acc = 1.0;
  p.max_longitudinal_acc = 0.8;
  p.corner_radius = 0.6;
  p.max_yaw_rate = 1.0;
  p.smoothing_time = 0.5;
  return p;
}

std::vector<TimedPose> densify_path(const std::vector<PathWaypoint>& w, const PathProfile& prof) {
  validate(w, prof);
  const int nw = static_cast<int>(w.size());
  // Stops: ends, dwell / stop flags, and corners too sharp to round.
  std::vector<int> stops{0};
  for (int i = 1; i + 1 < nw; ++i) {
    const Eigen::Vector3d uin = (w[i].p - w[i - 1].p).normalized(), uout = (w[i + 1].p - w[i].p).normalized();
    const double theta = std::acos(std::clamp(uin.dot(uout), -1.0, 1.0));
    if (w[i].dwell > 0.0 || w[i].stop || theta > prof.max_corner_angle) stops.push_back(i);
  }
  stops.push_back(nw - 1);

  std::vector<double> pitch(nw), roll(nw);
  for (int i = 0; i < nw; ++i) {
    pitch[i] = w[i].pitch;
    roll[i] = w[i].roll;
  }
  const std::vector<double> wp_yaw = unwrapped_waypoint_yaws(w);
  std::vector<Move> moves;
  moves.reserve(stops.size() - 1);
  double last_yaw = prof.heading == HeadingMode::kWaypoints ? wp_yaw[0] : w[0].yaw.value_or(0.0) + prof.yaw_offset;
  for (size_t k = 0; k + 1 < stops.size(); ++k) {
    moves.push_back(build_move(w, stops[k], stops[k + 1], prof));
    profile_move(moves.back(), prof, pitch, roll, wp_yaw, last_yaw);
  }

  // Timeline: still, move, (still, turn in place, still), move, ..., still.
  std::vector<Phase> phases;
  double t = 0.0;
  auto add = [&](Phase ph) {
    if (ph.duration <= 0.0) return;
    ph.t0 = t;
    t += ph.duration;
    phases.push_back(ph);
  };
  {
    Phase still;
    still.p = w[0].p;
    still.R0 = still.R1 = moves.front().R.front();
    still.duration = prof.start_dwell;
    add(still);
  }
  for (size_t k = 0; k < moves.size(); ++k) {
    Phase mv;
    mv.kind = Phase::kMove;
    mv.move = &moves[k];
    mv.duration = moves[k].duration();
    add(mv);
    if (k + 1 == moves.size()) break;
    const int wi = stops[k + 1];
    Phase still;
    still.p = w[wi].p;
    still.R0 = still.R1 = moves[k].R.back();
    still.duration = 0.5 * w[wi].dwell;
    add(still);
    Phase turn = still;
    turn.kind = Phase::kTurn;
    turn.R1 = moves[k + 1].R.front();
    // Quintic smoothstep peaks at 15/8 times the mean rate: size the turn so the peak is max_yaw_rate.
    turn.duration = 1.875 * so3::log(turn.R0.transpose() * turn.R1).norm() / prof.max_yaw_rate;
    add(turn);
    still.R0 = still.R1 = turn.R1;
    add(still);
  }
  {
    Phase still;
    still.p = w.back().p;
    still.R0 = still.R1 = moves.back().R.back();
    still.duration = prof.end_dwell;
    add(still);
  }
  // Lengthen the end dwell so that the last sample lies on the grid.
  const auto count = static_cast<long>(std::ceil(t / prof.sample_dt - 1e-9));
  phases.back().duration += static_cast<double>(count) * prof.sample_dt - t;

  std::vector<TimedPose> out;
  size_t ph = 0;
  for (long k = 0; k <= count; ++k) {
    const double tk = static_cast<double>(k) * prof.sample_dt;
    while (ph + 1 < phases.size() && tk >= phases[ph].t0 + phases[ph].duration) ++ph;
    const Phase& P = phases[ph];
    const double tau = tk - P.t0;
    TimedPose s;
    s.t = tk;
    Eigen::Matrix3d R;
    if (P.kind == Phase::kMove) {
      double sa;
      P.move->at(tau, sa, R);
      s.p = P.move->position(sa);
    } else {
      s.p = P.p;
      R = P.kind == Phase::kStill ? P.R0
                                  : Eigen::Matrix3d(P.R0 * so3::exp(smoothstep5(tau / P.duration) *
                                                                    so3::log(P.R0.transpose() * P.R1)));
    }
    s.q = Eigen::Quaterniond(R).normalized();
    out.push_back(s);
  }
  // Two box passes of half the smoothing time each = a triangle kernel of the full width.
  const int h = static_cast<int>(std::lround(0.25 * prof.smoothing_time / prof.sample_dt));
  box_filter(out, h);
  box_filter(out, h);
  return out;
}

SmoothTrajectory trajectory_from_path(const std::vector<PathWaypoint>& waypoints, const PathProfile& profile,
                                    TrajectoryFitReport* report) {
  return fit_trajectory(densify_path(waypoints, profile), profile.fit, report);
}

}  // namespace dynavins::sim
