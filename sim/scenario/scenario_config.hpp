#pragma once
// The estimator options a simulated scenario implies: the same VINS-Fusion yaml that `dynavins sim --euroc`
// writes next to its EuRoC folder, written to a scratch directory and loaded like any user's config.

#include "sim/scenario/scenario.hpp"
#include "stages/common/estimator_options.hpp"

namespace dynavins::sim {

EstimatorOptions scenario_estimator_options(const Scenario& scenario);

}  // namespace dynavins::sim
