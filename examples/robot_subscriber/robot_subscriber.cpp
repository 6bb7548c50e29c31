// A robot's view of DynaVINS: subscribe to its window pose and weighted features on LCM, and print each
// pose with the share of that window's features the robust BA rejected (weight < 0.5).
// Usage: robot_subscriber [LCM_URL] [MAX_POSES]   (default: LCM's default URL, run until Ctrl-C)
#include <cstdio>
#include <cstdlib>
#include <string>

#include <lcm/lcm-cpp.hpp>

#include <dynavins_lcm/pose_t.hpp>
#include <dynavins_lcm/status_t.hpp>
#include <dynavins_lcm/weighted_feature_set_t.hpp>

struct Robot {
  double rejected_share = 0.0;  // of the newest window
  int poses = 0;

  void onFeatures(const lcm::ReceiveBuffer*, const std::string&, const dynavins_lcm::weighted_feature_set_t* m) {
    int rejected = 0;
    for (const auto& f : m->features) rejected += f.weight < 0.5f;
    rejected_share = m->num_features > 0 ? static_cast<double>(rejected) / m->num_features : 0.0;
  }
  void onPose(const lcm::ReceiveBuffer*, const std::string&, const dynavins_lcm::pose_t* m) {
    ++poses;
    std::printf("pose t=%.3f s  p=(%.3f, %.3f, %.3f) m  rejected features %.0f %%\n", m->utime * 1e-6,
                m->position[0], m->position[1], m->position[2], 100.0 * rejected_share);
    std::fflush(stdout);
  }
  void onStatus(const lcm::ReceiveBuffer*, const std::string&, const dynavins_lcm::status_t* m) {
    if (m->status == dynavins_lcm::status_t::RESET) std::printf("DynaVINS lost: %s\n", m->reason.c_str());
  }
};

int main(int argc, char** argv) {
  lcm::LCM lcm(argc > 1 ? argv[1] : "");
  if (!lcm.good()) {
    std::fprintf(stderr, "robot_subscriber: LCM cannot open %s\n", argc > 1 ? argv[1] : "the default URL");
    return 2;
  }
  const int max_poses = argc > 2 ? std::atoi(argv[2]) : 0;
  Robot robot;
  lcm.subscribe("DYNAVINS_FEATURES", &Robot::onFeatures, &robot);
  lcm.subscribe("DYNAVINS_POSE", &Robot::onPose, &robot);
  lcm.subscribe("DYNAVINS_STATUS", &Robot::onStatus, &robot);
  while ((max_poses == 0 || robot.poses < max_poses) && lcm.handle() == 0) {
  }
  return 0;
}
