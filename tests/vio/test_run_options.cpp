// `run`'s option handling: --set key=value overrides (parsing, unknown keys, bad values, fixed keys),
// missing config, options the pipeline cannot run, and the exact seconds format of the TUM output.
#include <catch2/catch.hpp>

#include <string>

#include "io/euroc_dataset.hpp"
#include "io/euroc_source.hpp"
#include "pipeline/vio/run_outputs.hpp"
#include "pipeline/vio/vio_pipeline.hpp"
#include "stages/common/config_error.hpp"
#include "stages/common/estimator_options.hpp"

using namespace dynavins;
using Catch::Contains;

namespace {
const std::string kConfigDir = std::string(DYNAVINS_SHARED_DIR) + "/data/vins_fusion_euroc_config/";
const std::string kStereo = kConfigDir + "euroc_stereo_imu_config.yaml";
}  // namespace

TEST_CASE("override: --set key=value overrides the yaml and is printed as (--set)", "[vio][options]") {
  const auto o = EstimatorOptions::load(kStereo, {{"max_cnt", "200"},
                                                  {"regularization_lambda", "2"},
                                                  {"dyna_on", "false"},
                                                  {"td", "-0.01"}});
  CHECK(o.max_cnt == 200);
  CHECK(o.regularization_gamma == 2.0);
  CHECK(o.lambda_w == 4.0);
  CHECK_FALSE(o.dyna_on);
  CHECK(o.td == -0.01);
  const std::string printed = o.print();
  CHECK(printed.find("max_cnt                = 200  (--set)") != std::string::npos);
  CHECK(printed.find("(--set)") != std::string::npos);
  const auto plain = EstimatorOptions::load(kStereo);
  CHECK(plain.print().find("(--set)") == std::string::npos);
}

TEST_CASE("override: --set rejects malformed text, unknown keys, bad values and rig keys, naming the key", "[vio][options]") {
  CHECK(EstimatorOptions::parse_override(" max_cnt = 120 ") == std::make_pair(std::string("max_cnt"), std::string("120")));
  CHECK_THROWS_WITH(EstimatorOptions::parse_override("max_cnt"), Contains("--set") && Contains("key=value"));
  CHECK_THROWS_WITH(EstimatorOptions::parse_override("=3"), Contains("--set") && Contains("empty key"));
  CHECK_THROWS_WITH(EstimatorOptions::parse_override("max_cnt="), Contains("--set") && Contains("'max_cnt'"));

  EstimatorOptions o = EstimatorOptions::load(kStereo);
  CHECK_THROWS_AS(o.apply("max_cnt", "12x"), ConfigError);
  CHECK_THROWS_WITH(o.apply("max_cnt", "12x"), Contains("--set") && Contains("'max_cnt'") && Contains("12x"));
  CHECK_THROWS_WITH(o.apply("max_cnt", "0"), Contains("'max_cnt'") && Contains("must be in [10, 2000]"));
  CHECK_THROWS_WITH(o.apply("no_such_option", "1"), Contains("--set") && Contains("'no_such_option'") && Contains("unknown"));
  CHECK_THROWS_WITH(o.apply("dyna_on", "yes"), Contains("'dyna_on'") && Contains("true/false"));
  CHECK_THROWS_WITH(o.apply("alternating_converge", "1.5"), Contains("'alternating_converge'"));
  CHECK_THROWS_WITH(o.apply("acc_n", "nan"), Contains("'acc_n'"));
  CHECK_THROWS_WITH(o.apply("num_of_cam", "1"), Contains("'num_of_cam'") && Contains("cannot be overridden"));
  CHECK(o.max_cnt == 150);  // nothing applied by the failed calls
  CHECK(o.keys_from_override.empty());
}

TEST_CASE("a missing config names the file", "[vio][options]") {
  const std::string missing = kConfigDir + "no_such_config.yaml";
  CHECK_THROWS_WITH(EstimatorOptions::load(missing, {{"max_cnt", "100"}}), Contains(missing));
}

TEST_CASE("run_vio refuses options it cannot run before starting any thread", "[vio][options]") {
  auto source = io::EurocSource(std::make_shared<io::EurocDataset>(std::string(DYNAVINS_SHARED_DIR) +
                                                                   "/data/euroc_v1_01_micro"));
  pipeline::VioRunOptions o;
  o.show_progress = false;
  o.estimator = EstimatorOptions::load(kConfigDir + "euroc_mono_imu_config.yaml");
  o.mode.stereo = true;
  CHECK_THROWS_WITH(pipeline::run_vio(source, o, {}), Contains("--mono"));
  o.mode.stereo = false;
  o.rate = -1;
  CHECK_THROWS_WITH(pipeline::run_vio(source, o, {}), Contains("rate"));
}

TEST_CASE("TUM time stamps are exact seconds with 9 decimals", "[vio][options]") {
  CHECK(pipeline::format_seconds(1403715273262142976) == "1403715273.262142976");
  CHECK(pipeline::format_seconds(5) == "0.000000005");
  CHECK(pipeline::format_seconds(-1'500'000'000) == "-1.500000000");
}
