#pragma once
// How the pose graph treats verified loops: the loop-handling baselines of DESIGN.md §1.

#include <string>

namespace dynavins::loop {

enum class LoopMode {
  Off,         ///< no loop edges: the result is the odometry
  All,         ///< every verified loop, Huber loss (VINS-Fusion)
  Switchable,  ///< Sünderhauf & Protzel 2012: one switch variable s in [0, 1] per loop, prior (1 - s)^2
  Dynavins,    ///< paper IV-C eq. 16-17: per group, hypotheses H^0, H^1 weighted as a whole
};

/// "off" / "all" / "switchable" / "dynavins"; throws std::invalid_argument naming the value otherwise.
LoopMode parse_loop_mode(const std::string& s);
const char* loop_mode_name(LoopMode mode);

}  // namespace dynavins::loop
