// Loop handling mode names (see loop_mode.hpp).
#include "stages/loop/graph/loop_mode.hpp"

#include <stdexcept>

namespace dynavins::loop {

LoopMode parse_loop_mode(const std::string& s) {
  if (s == "off") return LoopMode::Off;
  if (s == "all") return LoopMode::All;
  if (s == "switchable") return LoopMode::Switchable;
  if (s == "dynavins") return LoopMode::Dynavins;
  throw std::invalid_argument("unknown loop mode '" + s + "' (expected off, all, switchable or dynavins)");
}

const char* loop_mode_name(LoopMode mode) {
  switch (mode) {
    case LoopMode::Off:
      return "off";
    case LoopMode::All:
      return "all";
    case LoopMode::Switchable:
      return "switchable";
    case LoopMode::Dynavins:
      return "dynavins";
  }
  return "?";
}

}  // namespace dynavins::loop
