// libFuzzer harness: the wire-type decoders (lcm-gen's C++ decode of every type in lcm_types/) as
// the project calls them (pipeline::decode_payload, which LcmLogReader::decode, `dynavins decode`
// and the live LCM source go through), then the conversion to the in-process messages where one
// exists. Input: one selector byte (which type, modulo their count), then the encoded payload.
// Contract: a payload either decodes or is rejected with a std::runtime_error; never a crash, a
// sanitizer report, an allocation far beyond the payload's size, or another exception type.

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include <dynavins_lcm/loop_hypotheses_t.hpp>
#include <dynavins_lcm/path_t.hpp>
#include <dynavins_lcm/pipeline_stats_t.hpp>
#include <dynavins_lcm/status_t.hpp>

#include "pipeline/lcm_convert.hpp"
#include "pipeline/wire_decode.hpp"

namespace {

using dynavins::pipeline::decode_payload;

template <typename Msg>
void decode_only(const std::vector<uint8_t>& payload) {
  (void)decode_payload<Msg>(payload, "fuzz");
}

template <typename Msg>
void decode_and_convert(const std::vector<uint8_t>& payload) {
  const Msg msg = decode_payload<Msg>(payload, "fuzz");
  (void)dynavins::pipeline::from_lcm(msg);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::vector<uint8_t> payload(data + 1, data + size);
  try {
    switch (data[0] % 10) {
      case 0: decode_and_convert<dynavins_lcm::stereo_image_t>(payload); break;
      case 1: decode_and_convert<dynavins_lcm::imu_t>(payload); break;
      case 2: decode_and_convert<dynavins_lcm::ground_truth_t>(payload); break;
      case 3: (void)dynavins::pipeline::image_from_lcm(decode_payload<dynavins_lcm::image_t>(payload, "fuzz")); break;
      case 4: decode_and_convert<dynavins_lcm::pose_t>(payload); break;
      case 5: decode_and_convert<dynavins_lcm::weighted_feature_set_t>(payload); break;
      case 6: decode_only<dynavins_lcm::path_t>(payload); break;
      case 7: decode_only<dynavins_lcm::loop_hypotheses_t>(payload); break;
      case 8: decode_only<dynavins_lcm::status_t>(payload); break;
      default: decode_only<dynavins_lcm::pipeline_stats_t>(payload); break;
    }
  } catch (const std::runtime_error&) {
  }
  return 0;
}
