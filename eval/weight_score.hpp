#pragma once
// Feature rejection against the simulator's labels (DESIGN.md §6): the share of features on moving
// objects the robust BA rejected (weight < 0.5) and of static features it kept (weight > 0.5).

#include <cstdint>
#include <map>

namespace dynavins::eval {

/// A feature's last robust-BA weight, as last seen in a window, and its simulator label.
struct FeatureOutcome {
  float weight = 1.f;
  int8_t sim_label = -1;  ///< object id: 0 static, > 0 moving, -1 unknown
  int times_solved = 0;
};

struct WeightScore {
  int moving = 0, stationary = 0;  ///< labelled features that went through at least one solve
  double moving_rejected = 0;   ///< share of `moving` with weight < 0.5
  double static_kept = 0;       ///< share of `stationary` with weight > 0.5
};

/// Scores features (by id) that went through at least one solve; unlabelled ones are left out.
WeightScore score_weights(const std::map<int64_t, FeatureOutcome>& features);

}  // namespace dynavins::eval
