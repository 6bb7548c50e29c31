#pragma once
// The switches that make every baseline one binary and one run (DESIGN §1).

#include <string>

namespace dynavins::estimator {

enum class BaLoss {
  Huber,     ///< VINS-Fusion: Huber loss (delta 1, in units of the reprojection noise), no weights
  Dynavins,  ///< paper III: per-feature weights, regularisation + momentum, alternating optimisation
};

/// "huber" / "dynavins"; throws std::invalid_argument naming the value otherwise.
BaLoss parse_ba_loss(const std::string& s);
const char* to_string(BaLoss loss);

}  // namespace dynavins::estimator
