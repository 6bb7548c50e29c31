// `dynavins info`: what this build is: version, libraries, LCM wire types and channels.
// `dynavins info --options-markdown`: the config keys as the README's Markdown table.
#include <cstdio>
#include <memory>

#include <CLI/CLI.hpp>
#include <Eigen/Core>
#include <lcm/lcm.h>
#include <opencv2/core/version.hpp>
#include <spdlog/version.h>

#include <dynavins_lcm/ground_truth_t.hpp>
#include <dynavins_lcm/image_t.hpp>
#include <dynavins_lcm/imu_t.hpp>
#include <dynavins_lcm/loop_hypotheses_t.hpp>
#include <dynavins_lcm/path_t.hpp>
#include <dynavins_lcm/pipeline_stats_t.hpp>
#include <dynavins_lcm/pose_t.hpp>
#include <dynavins_lcm/stereo_image_t.hpp>
#include <dynavins_lcm/weighted_feature_set_t.hpp>

#include "bin/commands.hpp"
#include "pipeline/lcm_channels.hpp"
#include "stages/common/estimator_options.hpp"

namespace dynavins::cli {
namespace {

template <typename Msg>
void print_type(const char* channel) {
  std::printf("  %-36s fingerprint 0x%016llx  %s\n", Msg::getTypeName(),
              static_cast<unsigned long long>(Msg::getHash()), channel);
}

void run_info() {
  std::printf("dynavins %s (%s build)\n", DYNAVINS_VERSION, DYNAVINS_BUILD_TYPE);
  std::printf("libraries: Eigen %d.%d.%d, OpenCV %s, LCM %d.%d.%d, spdlog %d.%d.%d, CLI11 %s\n",
              EIGEN_WORLD_VERSION, EIGEN_MAJOR_VERSION, EIGEN_MINOR_VERSION, CV_VERSION, LCM_MAJOR_VERSION,
              LCM_MINOR_VERSION, LCM_MICRO_VERSION, SPDLOG_VER_MAJOR, SPDLOG_VER_MINOR, SPDLOG_VER_PATCH,
              CLI11_VERSION);
  std::printf("LCM wire types (package dynavins_lcm) and their channels:\n");
  print_type<dynavins_lcm::stereo_image_t>(pipeline::channels::kStereo);
  print_type<dynavins_lcm::imu_t>(pipeline::channels::kImu);
  print_type<dynavins_lcm::ground_truth_t>(pipeline::channels::kGroundTruth);
  print_type<dynavins_lcm::image_t>(pipeline::channels::kSimLabels);
  print_type<dynavins_lcm::pose_t>("DYNAVINS_POSE, DYNAVINS_POSE_IMU");
  print_type<dynavins_lcm::weighted_feature_set_t>(pipeline::channels::kFeatures);
  print_type<dynavins_lcm::loop_hypotheses_t>(pipeline::channels::kLoops);
  print_type<dynavins_lcm::path_t>(pipeline::channels::kPath);
  print_type<dynavins_lcm::pipeline_stats_t>(pipeline::channels::kStats);
  std::printf("lcm-spy: CLASSPATH=build/share/java/dynavins_lcm_types.jar lcm-spy\n");
}

}  // namespace

void add_info_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("info", "Show the version, libraries, LCM wire types and channels");
  auto markdown = std::make_shared<bool>(false);
  cmd->add_flag("--options-markdown", *markdown, "Print the config keys (yaml and --set) as a Markdown table");
  cmd->callback([markdown] {
    if (*markdown)
      std::fputs(options_markdown_table().c_str(), stdout);
    else
      run_info();
  });
}

}  // namespace dynavins::cli
