#include "stages/estimator/ba_mode.hpp"

#include <stdexcept>

namespace dynavins::estimator {

BaLoss parse_ba_loss(const std::string& s) {
  if (s == "huber") return BaLoss::Huber;
  if (s == "dynavins") return BaLoss::Dynavins;
  throw std::invalid_argument("unknown BA loss '" + s + "' (expected huber or dynavins)");
}

const char* to_string(BaLoss loss) { return loss == BaLoss::Huber ? "huber" : "dynavins"; }

}  // namespace dynavins::estimator
