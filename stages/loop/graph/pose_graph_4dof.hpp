#pragma once
// The 4-DoF pose graph of the loop closer (paper IV-C eq. 15, VINS-Fusion's pose_graph): per keyframe
// the position and yaw are free, roll and pitch stay at the odometry's (the IMU makes them observable, so
// they do not drift). Sequential edges tie consecutive keyframes to the odometry's relative pose, loop
// edges tie a query keyframe to its match through the verified T_m^k. The first keyframe is fixed (gauge).
// Loop edges can be plain, Huber (LoopMode::All), switchable, or scaled by a fixed factor (the
// hypothesis weights of eq. 16, set by the caller). Ceres stays inside the .cpp.

#include <cstddef>
#include <vector>

#include "stages/loop/graph/rigid_pose.hpp"

namespace dynavins::loop {

struct PoseGraphOptions {
  // Edge covariances (diagonal). Sequential and loop edges weigh the same, as in VINS-Fusion's pose graph
  // (unit weights on both). The loop edges of eq. 16 carry (w/|H|)^2, so they are weak against the
  // sequential chain, and the balance matters (measured on tests/loop/test_loop_graph_optimizer.cpp's
  // scene): with sequential 0.05 m / 0.5 deg and loop 0.05 m / 1 deg the true hypotheses settle at
  // w = 0.66-0.97 instead of 0.95-1.0, and with false loops present one true group next to them fell to
  // w = 0.18 (a local minimum of the alternation started from odometry with 2.2 m of drift).
  double seq_sigma_t_m = 0.1;                                        ///< sequential edge, translation [m]
  double seq_sigma_yaw_rad = 1.0 * 3.14159265358979323846 / 180.0;   ///< sequential edge, yaw
  double loop_sigma_t_m = 0.1;                                       ///< loop edge (P_L), translation [m]
  double loop_sigma_yaw_rad = 1.0 * 3.14159265358979323846 / 180.0;  ///< loop edge (P_L), yaw
  double huber_delta = 1.0;         ///< Huber loss of LoopEdgeLoss::Huber, on the whitened residual
  double switch_prior_sigma = 1.0;  ///< switchable constraints: prior residual (1 - s) / sigma (Ξ = sigma^2)
  int max_iterations = 100;         ///< Ceres iterations per solve
};

/// A loop edge between keyframe nodes `match` (C_m) and `query` (C_k, newer).
struct LoopEdge {
  int match = 0;
  int query = 0;
  RigidPose T_m_k;     ///< query body in the match body's frame (VerifiedLoop)
  double scale = 1.0;  ///< the residual is multiplied by this (eq. 16: w^h / |H^h|); 0 disables the edge
};

enum class LoopEdgeLoss {
  Plain,       ///< ||scale * r||^2
  Huber,       ///< scale^2 * huber(||r||^2), VINS-Fusion
  Switchable,  ///< ||s * r||^2 + ((1 - s) / sigma)^2 with s in [0, 1] solved jointly (Sünderhauf 2012)
};

struct PoseGraphSolveReport {
  double initial_cost = 0.0;
  double final_cost = 0.0;
  int iterations = 0;
  bool usable = false;
};

class PoseGraph4Dof {
 public:
  /// Nodes are the keyframes in time order with their odometry poses; the estimate starts there.
  explicit PoseGraph4Dof(const std::vector<RigidPose>& odometry, const PoseGraphOptions& options = {});

  std::size_t num_nodes() const { return odometry_.size(); }
  /// Current estimate of node i: (x, y, z, yaw) solved, roll and pitch from the odometry.
  RigidPose pose(std::size_t i) const;
  std::vector<RigidPose> poses() const;
  void reset_to_odometry();
  /// Sets node i's estimate from a full pose: its position and yaw (roll and pitch stay the odometry's).
  /// Used to warm-start a solve from a previous optimisation's poses.
  void set_estimate(std::size_t i, const RigidPose& T_W_i);

  /// The whitened 4-vector residual of a loop edge at the current estimate, without scale:
  /// [R_m^T (p_k - p_m) - t_mk] / sigma_t, normalize(yaw_k - yaw_m - yaw_mk) / sigma_yaw.
  double loop_residual_sq(const LoopEdge& edge) const;

  /// Solves the graph with all sequential edges and the given loop edges. For LoopEdgeLoss::Switchable,
  /// `switches` holds one value per loop (in/out; resized to loops.size() with 1.0 if its size differs).
  PoseGraphSolveReport solve(const std::vector<LoopEdge>& loops, LoopEdgeLoss loss,
                             std::vector<double>* switches = nullptr);

  const PoseGraphOptions& options() const { return options_; }

 private:
  struct Node {
    double p[3];
    double yaw[1];
  };
  PoseGraphOptions options_;
  std::vector<RigidPose> odometry_;
  std::vector<double> pitch_, roll_;
  std::vector<Node> nodes_;
};

}  // namespace dynavins::loop
