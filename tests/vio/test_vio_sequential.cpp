// run_vio_sequential is the threaded run without its threads: at rate 0 (every queue blocks, solves bounded by
// their iteration budget alone) both must give the same estimates bit for bit, on the real EuRoC clip.
#include <catch2/catch.hpp>

#include <vector>

#include "io/euroc_dataset.hpp"
#include "io/euroc_source.hpp"
#include "pipeline/vio/vio_pipeline.hpp"

using namespace dynavins;
using namespace dynavins::pipeline;

namespace {

const std::string kClip = std::string(DYNAVINS_SHARED_DIR) + "/data/euroc_v1_01_micro";
const std::string kConfig = std::string(DYNAVINS_SHARED_DIR) + "/data/vins_fusion_euroc_config/euroc_stereo_imu_config.yaml";

/// What must match: every estimate's time, status, state and feature weights.
struct Estimate {
  int64_t t_ns;
  int status;
  Eigen::Vector3d p, v;
  Eigen::Quaterniond q;
  std::vector<std::pair<int64_t, float>> weights;
};

using Driver = VioRunResult (*)(io::SensorSource&, const VioRunOptions&, const VioSinks&, const StopFlag*);

std::vector<Estimate> run_clip(Driver drive, estimator::BaLoss loss, bool stereo, bool rejected_feedback = false) {
  VioRunOptions o;
  o.estimator = EstimatorOptions::load(kConfig);
  o.estimator.rejected_feedback = rejected_feedback;
  o.mode.loss = loss;
  o.mode.stereo = stereo;
  o.show_progress = false;
  std::vector<Estimate> out;
  VioSinks sinks;
  sinks.estimate = [&out](const estimator::WindowEstimate& e) {
    Estimate x{e.t_ns, static_cast<int>(e.status), e.state.p_wb, e.state.v_wb, e.state.q_wb, {}};
    for (const auto& f : e.features.features) x.weights.emplace_back(f.id, f.weight);
    out.push_back(std::move(x));
  };
  io::EurocSource src(std::make_shared<io::EurocDataset>(kClip));
  const VioRunResult r = drive(src, o, sinks, nullptr);
  REQUIRE(r.report.ok);
  CHECK_FALSE(r.solver_time_budget);
  CHECK(r.frames_estimated == static_cast<int64_t>(out.size()));
  return out;
}

void require_identical(const std::vector<Estimate>& a, const std::vector<Estimate>& b) {
  REQUIRE(a.size() == b.size());
  int tracking = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    INFO("estimate " << i << " at t = " << a[i].t_ns << " ns");
    REQUIRE(a[i].t_ns == b[i].t_ns);
    REQUIRE(a[i].status == b[i].status);
    // Exact equality on purpose: same stages, same inputs, same order of floating-point operations.
    CHECK(a[i].p == b[i].p);
    CHECK(a[i].v == b[i].v);
    CHECK(a[i].q.coeffs() == b[i].q.coeffs());
    CHECK(a[i].weights == b[i].weights);
    tracking += a[i].status == static_cast<int>(estimator::EstimatorStatus::Tracking);
  }
  CHECK(tracking > 50);  // the comparison covered real solves, not only initialisation
}

}  // namespace

TEST_CASE("sequential and threaded rate-0 runs give the same estimates bit for bit", "[vio][sequential]") {
  // Stereo only: the clip stands still, so a mono run never initialises on it (no parallax).
  require_identical(run_clip(&run_vio, estimator::BaLoss::Dynavins, true),
                   run_clip(&run_vio_sequential, estimator::BaLoss::Dynavins, true));
}

TEST_CASE("with the estimator's rejections fed back to the tracker, threaded and sequential runs still agree",
          "[vio][sequential]") {
  // The threaded tracker waits for the verdict on the frames before it (RejectedTracksFeedback); the
  // sequential one has it at once: the same verdict, so the same tracks and estimates.
  const auto threaded = run_clip(&run_vio, estimator::BaLoss::Dynavins, true, true);
  require_identical(threaded, run_clip(&run_vio_sequential, estimator::BaLoss::Dynavins, true, true));
  int rejected = 0;
  for (const Estimate& e : threaded)
    for (const auto& [id, w] : e.weights) rejected += w < 0.5f;
  CHECK(rejected > 0);  // some verdicts went back (the real clip rejects a few static tracks)
}

TEST_CASE("run_vio_sequential refuses a paced rate", "[vio][sequential]") {
  VioRunOptions o;
  o.estimator = EstimatorOptions::load(kConfig);
  o.rate = 1.0;
  io::EurocSource src(std::make_shared<io::EurocDataset>(kClip));
  CHECK_THROWS_AS(run_vio_sequential(src, o, {}, nullptr), std::invalid_argument);
}
