#include "eval/weight_score.hpp"

namespace dynavins::eval {

WeightScore score_weights(const std::map<int64_t, FeatureOutcome>& features) {
  WeightScore s;
  int moving_low = 0, static_high = 0;
  for (const auto& [id, f] : features) {
    if (f.times_solved == 0 || f.sim_label < 0) continue;
    if (f.sim_label > 0) {
      ++s.moving;
      moving_low += f.weight < 0.5f;
    } else {
      ++s.stationary;
      static_high += f.weight > 0.5f;
    }
  }
  s.moving_rejected = s.moving ? static_cast<double>(moving_low) / s.moving : 0;
  s.static_kept = s.stationary ? static_cast<double>(static_high) / s.stationary : 0;
  return s;
}

}  // namespace dynavins::eval
