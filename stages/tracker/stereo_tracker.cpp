#include "stages/tracker/stereo_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include <opencv2/calib3d.hpp>
#include <opencv2/video/tracking.hpp>

#include "stages/tracker/corner_detector.hpp"

namespace dynavins::tracker {

namespace {

float distance(const cv::Point2f& a, const cv::Point2f& b) { return static_cast<float>(cv::norm(a - b)); }

Eigen::Vector2d to_eigen(const cv::Point2f& p) { return {p.x, p.y}; }

/// Keeps the elements of `v` whose `keep` flag is set, in order.
template <typename T>
void compact(std::vector<T>& v, const std::vector<uchar>& keep) {
  std::size_t j = 0;
  for (std::size_t i = 0; i < v.size(); ++i)
    if (keep[i]) v[j++] = v[i];
  v.resize(j);
}

}  // namespace

StereoTracker::StereoTracker(const TrackerOptions& options, CameraModelPtr cam0, CameraModelPtr cam1)
    : opt_(options), cam0_(std::move(cam0)), cam1_(std::move(cam1)) {
  if (!cam0_) throw std::invalid_argument("StereoTracker: cam0 is required");
  if (opt_.max_cnt <= 0 || opt_.min_dist < 0 || opt_.window < 3 || opt_.pyramid_levels < 0 ||
      opt_.stereo_retry_interval < 1)
    throw std::invalid_argument(
        "StereoTracker: bad options (max_cnt > 0, min_dist >= 0, window >= 3, levels >= 0, stereo_retry_interval >= 1)");
  if (opt_.clahe) clahe_ = cv::createCLAHE(opt_.clahe_clip, cv::Size(8, 8));
}

void StereoTracker::reset() {
  tracks_.clear();
  rejected_.clear();
  prev_pyr_.clear();
}

cv::Mat StereoTracker::prepare(const cv::Mat& img, const char* which, int64_t t_ns) const {
  const std::string at = "frame at t = " + std::to_string(t_ns / 1000000000) + "." +
                         std::to_string(1000000000 + t_ns % 1000000000).substr(1) + " s, " + which + " image";
  if (img.type() != CV_8UC1) throw std::invalid_argument(at + ": must be 8-bit gray");
  if (cam0_->width() > 0 && (img.cols != cam0_->width() || img.rows != cam0_->height()))
    throw std::invalid_argument(at + " is " + std::to_string(img.cols) + "x" + std::to_string(img.rows) +
                                " but the camera calibration says " + std::to_string(cam0_->width()) + "x" +
                                std::to_string(cam0_->height()) + " (image_width/image_height of the camera file)");
  if (!clahe_) return img;
  cv::Mat out;
  clahe_->apply(img, out);
  return out;
}

void StereoTracker::pyramid(const cv::Mat& img, Pyramid& pyr) const {
  // Built once per image and shared by the forward, backward and stereo KLT calls; into the levels
  // `pyr` already holds when their sizes match. Level 0 is always a copy: were it the caller's image
  // (OpenCV's default for a submatrix with room round it), the next build would write into it.
  cv::buildOpticalFlowPyramid(img, pyr, cv::Size(opt_.window, opt_.window), opt_.pyramid_levels, true,
                              cv::BORDER_REFLECT_101, cv::BORDER_CONSTANT, false);
}

bool StereoTracker::in_border(const cv::Point2f& p, const cv::Size& size) const {
  const int u = cvRound(p.x), v = cvRound(p.y);
  return u >= opt_.border && v >= opt_.border && u < size.width - opt_.border && v < size.height - opt_.border;
}

std::vector<StereoTracker::Track> StereoTracker::track_temporal(const Pyramid& curr,
                                                                const std::optional<Eigen::Matrix3d>& R_prev_curr,
                                                                std::vector<cv::Point2f>& prev_px,
                                                                TrackerStats& stats) const {
  std::vector<Track> tracks = tracks_;
  const std::size_t n = tracks.size();
  prev_px.resize(n);
  for (std::size_t i = 0; i < n; ++i) prev_px[i] = tracks[i].px;
  if (n == 0) return tracks;
  const cv::Size size = curr[0].size();
  const cv::Size win(opt_.window, opt_.window);
  const cv::TermCriteria crit(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, opt_.max_iterations, opt_.epsilon);
  // No error output from the KLT calls (here and in match_stereo): nothing reads it, and OpenCV spends
  // a pass over each window on it.

  std::vector<cv::Point2f> px = prev_px;
  std::vector<uchar> status(n, 0), predicted(n, 0);
  if (R_prev_curr) {
    // A pure rotation moves every pixel the same whatever its depth: a good start.
    const Eigen::Matrix3d R_curr_prev = R_prev_curr->transpose();
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d b = R_curr_prev * tracks[i].bearing;
      if (b.z() <= 1e-3) continue;
      const Eigen::Vector2d q = cam0_->project(b);
      const cv::Point2f g(static_cast<float>(q.x()), static_cast<float>(q.y()));
      if (!in_border(g, size)) continue;
      px[i] = g;
      predicted[i] = 1;
    }
    // The whole pyramid from the prediction: the fine levels alone lose fast-moving objects, whose
    // image motion the camera's rotation does not explain.
    cv::calcOpticalFlowPyrLK(prev_pyr_, curr, prev_px, px, status, cv::noArray(), win, opt_.pyramid_levels, crit,
                             cv::OPTFLOW_USE_INITIAL_FLOW);
    // Retry the failures (and the unpredicted) from scratch with the whole pyramid.
    std::vector<std::size_t> redo;
    for (std::size_t i = 0; i < n; ++i)
      if (!status[i] || !predicted[i]) redo.push_back(i);
    if (!redo.empty()) {
      std::vector<cv::Point2f> from(redo.size()), to;
      for (std::size_t k = 0; k < redo.size(); ++k) from[k] = prev_px[redo[k]];
      std::vector<uchar> st;
      cv::calcOpticalFlowPyrLK(prev_pyr_, curr, from, to, st, cv::noArray(), win, opt_.pyramid_levels, crit);
      for (std::size_t k = 0; k < redo.size(); ++k) {
        px[redo[k]] = to[k];
        status[redo[k]] = st[k];
        predicted[redo[k]] = 0;
      }
    }
  } else {
    cv::calcOpticalFlowPyrLK(prev_pyr_, curr, prev_px, px, status, cv::noArray(), win, opt_.pyramid_levels, crit);
  }
  for (std::size_t i = 0; i < n; ++i)
    if (status[i] && !in_border(px[i], size)) status[i] = 0;
  for (std::size_t i = 0; i < n; ++i) stats.lost_flow += !status[i];

  if (opt_.flow_back) {
    // Back from the new pixel, starting at the old one: a track that does not come home slid. Only
    // the tracks still alive go back (each point is tracked on its own).
    std::vector<std::size_t> alive;
    for (std::size_t i = 0; i < n; ++i)
      if (status[i]) alive.push_back(i);
    std::vector<cv::Point2f> from(alive.size()), back(alive.size());
    for (std::size_t k = 0; k < alive.size(); ++k) from[k] = px[alive[k]], back[k] = prev_px[alive[k]];
    std::vector<uchar> back_status;
    if (!alive.empty())
      cv::calcOpticalFlowPyrLK(curr, prev_pyr_, from, back, back_status, cv::noArray(), win,
                               std::min(1, opt_.pyramid_levels), crit, cv::OPTFLOW_USE_INITIAL_FLOW);
    for (std::size_t k = 0; k < alive.size(); ++k) {
      if (!back_status[k] || distance(back[k], prev_px[alive[k]]) > opt_.max_back_error) {
        status[alive[k]] = 0;
        ++stats.lost_back;
      }
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    tracks[i].px = px[i];
    tracks[i].length += 1;
    stats.predicted += status[i] && predicted[i];
  }
  compact(tracks, status);
  compact(prev_px, status);
  return tracks;
}

void StereoTracker::refine_with_patches(const cv::Mat& img, std::vector<Track>& tracks,
                                        std::vector<cv::Point2f>& prev_px, TrackerStats& stats) const {
  std::vector<uchar> keep(tracks.size(), 1);
  const float noise_sigma = image_noise_sigma(img);
  for (std::size_t i = 0; i < tracks.size(); ++i) {
    Track& t = tracks[i];
    if (!t.patch) continue;
    AffineWarp w = t.warp;
    w.t = Eigen::Vector2f(t.px.x, t.px.y);
    const RefineOutcome o = refine_patch(*t.patch, img, &w, noise_sigma);
    const RefineResult r = o.result;
    if (r == RefineResult::OutOfImage) continue;  // near the border: keep the KLT answer as it is
    const cv::Point2f refined(w.t.x(), w.t.y());
    if (r == RefineResult::Diverged || distance(refined, t.px) > opt_.patch_max_shift ||
        !in_border(refined, img.size())) {
      // The first patch no longer settles (its look changed beyond an affine warp: occluded, seen from
      // too far round) or settles elsewhere (the KLT slid): the track cannot be trusted any longer.
      keep[i] = 0;
      ++stats.lost_patch;
      continue;
    }
    t.px = refined;
    t.warp = w;
    const double s = w.scale();
    if (s > opt_.patch_recapture_scale || s < 1.0 / opt_.patch_recapture_scale) {
      t.patch = capture_patch(img, w.t);
      t.warp = AffineWarp{};
      ++stats.patch_recaptured;
    }
  }
  compact(tracks, keep);
  compact(prev_px, keep);
}

void StereoTracker::reject_with_f(std::vector<Track>& tracks, std::vector<cv::Point2f>& prev_px,
                                  TrackerStats& stats) const {
  if (tracks.size() < 8) return;
  // On the undistorted plane scaled to a virtual 460 px focal length, so the threshold is in
  // pixels of an ideal camera whatever the lens (VINS-Fusion's rejectWithF).
  constexpr double kFocal = 460.0;
  const double cx = cam0_->width() / 2.0, cy = cam0_->height() / 2.0;
  std::vector<cv::Point2f> a, b;
  for (std::size_t i = 0; i < tracks.size(); ++i) {
    const Eigen::Vector2d p = cam0_->lift_normalized(to_eigen(prev_px[i]));
    const Eigen::Vector3d& c = tracks[i].bearing;
    a.emplace_back(static_cast<float>(kFocal * p.x() + cx), static_cast<float>(kFocal * p.y() + cy));
    b.emplace_back(static_cast<float>(kFocal * c.x() / c.z() + cx), static_cast<float>(kFocal * c.y() / c.z() + cy));
  }
  std::vector<uchar> inlier;
  cv::findFundamentalMat(a, b, cv::FM_RANSAC, opt_.f_threshold, 0.99, inlier);
  if (inlier.size() != tracks.size()) return;  // degenerate: keep everything
  for (uchar s : inlier) stats.lost_ransac += !s;
  compact(tracks, inlier);
  compact(prev_px, inlier);
}

void StereoTracker::enforce_spacing_and_detect(const cv::Mat& img, std::vector<Track>& tracks,
                                               std::vector<cv::Point2f>& prev_px, TrackerStats& stats) {
  // Longest tracks claim their neighbourhood first (ties: the older id), so a crowding newcomer
  // gives way to a long-lived feature and not the reverse.
  std::vector<std::size_t> order(tracks.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) {
    const Track &a = tracks[i], &b = tracks[j];
    return a.length != b.length ? a.length > b.length : a.id < b.id;
  });
  cv::Mat& mask = mask_;
  mask.create(img.size(), CV_8UC1);
  mask.setTo(255);
  const int radius = static_cast<int>(std::lround(opt_.min_dist));
  // Tracks the estimator rejected (set_rejected) do not count against max_cnt; one with another rejected
  // track within kObjectReach min_dist is taken for part of a moving object, whose surface is no place
  // for a fresh corner: it masks kObjectMask min_dist around it instead of one.
  constexpr double kObjectReach = 4.0, kObjectMask = 2.0;
  std::vector<uchar> rejected(tracks.size(), 0), on_object(tracks.size(), 0);
  for (std::size_t i = 0; i < tracks.size(); ++i)
    rejected[i] = std::binary_search(rejected_.begin(), rejected_.end(), tracks[i].id);
  for (std::size_t i = 0; i < tracks.size(); ++i) {
    if (!rejected[i]) continue;
    for (std::size_t j = 0; j < tracks.size() && !on_object[i]; ++j)
      on_object[i] = j != i && rejected[j] && distance(tracks[i].px, tracks[j].px) < kObjectReach * opt_.min_dist;
  }
  std::vector<Track> kept;
  std::vector<cv::Point2f> kept_prev;
  int counted = 0, uncounted = 0;  // against max_cnt, and rejected ones beside it (at most max_cnt)
  for (std::size_t i : order) {
    const cv::Point2f& p = tracks[i].px;
    if ((rejected[i] ? uncounted : counted) >= opt_.max_cnt || mask.at<uchar>(cvRound(p.y), cvRound(p.x)) == 0) {
      ++stats.lost_mask;
      continue;
    }
    ++(rejected[i] ? uncounted : counted);
    kept.push_back(tracks[i]);
    kept_prev.push_back(prev_px[i]);
    const int r = on_object[i] ? static_cast<int>(std::lround(kObjectMask * opt_.min_dist)) : radius;
    if (r > 0) cv::circle(mask, cv::Point(cvRound(p.x), cvRound(p.y)), r, cv::Scalar(0), cv::FILLED);
  }
  stats.tracked = static_cast<int>(kept.size());
  stats.uncounted = uncounted;
  const int wanted = opt_.max_cnt - counted;
  if (wanted > 0) {
    const std::vector<cv::Point2f> corners =
        detect_corners(img, mask, wanted, opt_.quality_level, opt_.min_dist, &corner_scratch_);
    for (const auto& c : corners) {
      if (!in_border(c, img.size())) continue;
      kept.push_back(Track{next_id_++, 1, c, cam0_->lift(to_eigen(c))});
      if (opt_.patch_refine) kept.back().patch = capture_patch(img, Eigen::Vector2f(c.x, c.y));
      kept_prev.emplace_back(std::numeric_limits<float>::quiet_NaN(), 0.f);  // new: no velocity
      ++stats.detected;
    }
  }
  tracks = std::move(kept);
  prev_px = std::move(kept_prev);
}

void StereoTracker::set_rejected(std::vector<int64_t> ids) {
  std::sort(ids.begin(), ids.end());
  rejected_ = std::move(ids);
}

void StereoTracker::match_stereo(const Pyramid& curr, const cv::Mat& right_in, std::vector<Track>& tracks,
                                 TrackedFrame& out) {
  cv::Mat right = right_in;
  const cv::Mat& left = curr[0];
  if (right.size() != left.size()) throw std::invalid_argument("StereoTracker: left and right sizes differ");
  if (opt_.stereo_gain_match) {
    // KLT assumes equal brightness; the two sensors' exposure / gain differ (EuRoC: ~10 %), which
    // pulls the left-right match off. One global gain brings the right image to the left's mean.
    const double ml = cv::mean(left)[0], mr = cv::mean(right)[0];
    if (mr > 1.0 && std::abs(ml / mr - 1.0) > 0.01) {
      // Never in place: `right` may share the caller's pixels.
      right.convertTo(right_scaled_, CV_8U, ml / mr);
      right = right_scaled_;
    }
  }
  pyramid(right, right_pyr_);
  const Pyramid& rpyr = right_pyr_;
  const cv::Size win(opt_.window, opt_.window);
  const cv::TermCriteria crit(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, opt_.max_iterations, opt_.epsilon);
  const std::size_t n = tracks.size();
  std::vector<cv::Point2f> lpx(n), rpx(n), back;
  std::vector<uchar> st(n, 0), back_st;
  // Left -> right (no rectification, so no epipolar prior). A track matched in the last frame starts
  // at its last disparity, which moves by a fraction of a pixel from frame to frame, so the full-size
  // level alone finds it (measured: the same match rate and disparity error as with one more level,
  // for half the cost); the rest, and the failures, search the whole pyramid from the left pixel.
  // A track the right camera did not match waits stereo_retry_interval - 1 frames before searching
  // again: features outside the overlap or on an occluded side keep failing, and a failing search
  // costs the most (it runs to the iteration cap on every level).
  std::vector<std::size_t> seeded, unseeded;
  std::vector<uchar> searched(n, 1);
  for (std::size_t i = 0; i < n; ++i) {
    Track& t = tracks[i];
    lpx[i] = t.px;
    if (!std::isnan(t.stereo_offset.x)) {
      seeded.push_back(i);
    } else if (t.stereo_wait > 0) {
      --t.stereo_wait;
      searched[i] = 0;
    } else {
      unseeded.push_back(i);
    }
  }
  auto klt = [&](const std::vector<std::size_t>& idx, bool from_offset) {
    if (idx.empty()) return;
    std::vector<cv::Point2f> from(idx.size()), to(idx.size());
    for (std::size_t k = 0; k < idx.size(); ++k) {
      from[k] = lpx[idx[k]];
      to[k] = from_offset ? from[k] + tracks[idx[k]].stereo_offset : from[k];
    }
    std::vector<uchar> s;
    cv::calcOpticalFlowPyrLK(curr, rpyr, from, to, s, cv::noArray(), win, from_offset ? 0 : opt_.pyramid_levels,
                             crit, from_offset ? cv::OPTFLOW_USE_INITIAL_FLOW : 0);
    for (std::size_t k = 0; k < idx.size(); ++k) rpx[idx[k]] = to[k], st[idx[k]] = s[k];
  };
  klt(seeded, true);
  for (std::size_t i : seeded)
    if (!st[i]) unseeded.push_back(i);
  klt(unseeded, false);
  // Right -> left: a match that does not return to its start is ambiguous and left mono. The way back
  // starts at the answer, so the fine levels suffice (as the temporal check). Only the matches go back
  // (each point is tracked on its own, so leaving the rest out changes nothing).
  std::vector<std::size_t> matched;
  for (std::size_t i = 0; i < n; ++i)
    if (searched[i] && st[i] && in_border(rpx[i], right.size())) matched.push_back(i);
  std::vector<cv::Point2f> from(matched.size());
  back.resize(matched.size());
  for (std::size_t k = 0; k < matched.size(); ++k) from[k] = rpx[matched[k]], back[k] = lpx[matched[k]];
  if (!matched.empty())
    cv::calcOpticalFlowPyrLK(rpyr, curr, from, back, back_st, cv::noArray(), win, std::min(1, opt_.pyramid_levels),
                             crit, cv::OPTFLOW_USE_INITIAL_FLOW);
  std::vector<uchar> stereo_ok(n, 0);
  for (std::size_t k = 0; k < matched.size(); ++k)
    stereo_ok[matched[k]] = back_st[k] && distance(back[k], lpx[matched[k]]) <= opt_.max_back_error;
  for (std::size_t i = 0; i < n; ++i) {
    Track& t = tracks[i];
    t.stereo_offset.x = std::numeric_limits<float>::quiet_NaN();
    if (!searched[i]) continue;  // waiting (see above)
    if (!stereo_ok[i]) {
      t.stereo_wait = std::max(0, opt_.stereo_retry_interval - 1);
      continue;
    }
    t.stereo_offset = rpx[i] - lpx[i];
    TrackedFeature& f = out.features[i];
    f.has_right = true;
    f.px_right = to_eigen(rpx[i]);
    f.bearing_right = cam1_->lift(f.px_right);
    f.xy_right = f.bearing_right.head<2>() / f.bearing_right.z();
    ++out.stats.stereo;
  }
}

namespace {
// Copies the simulator's label under each feature's rounded left pixel (for scoring only).
void label_features(const cv::Mat& labels, std::vector<TrackedFeature>& features) {
  if (labels.type() != CV_8UC1) throw std::invalid_argument("StereoTracker: labels must be CV_8U (one channel)");
  for (TrackedFeature& f : features) {
    const int c = static_cast<int>(std::lround(f.px.x())), r = static_cast<int>(std::lround(f.px.y()));
    if (r < 0 || c < 0 || r >= labels.rows || c >= labels.cols) continue;
    f.sim_label = static_cast<int8_t>(labels.at<uint8_t>(r, c));
  }
}
}  // namespace

TrackedFrame StereoTracker::process(const StereoFrame& frame, std::optional<Eigen::Matrix3d> R_prev_curr_cam0) {
  const cv::Mat left = prepare(frame.left, "left", frame.t_ns);
  const bool stereo = !frame.right.empty();
  if (!frame.labels.empty() && frame.labels.size() != frame.left.size())
    throw std::invalid_argument("StereoTracker: label image size differs from the left image");
  if (stereo && !cam1_) throw std::invalid_argument("StereoTracker: a right image but no cam1 model");
  TrackedFrame out;
  out.t_ns = frame.t_ns;
  out.seq = frame.seq;
  out.image = frame.left;  // shallow: the estimator keeps it while the frame is in its window (keyframes)

  pyramid(left, curr_pyr_);
  const Pyramid& curr = curr_pyr_;
  std::vector<cv::Point2f> prev_px;
  std::vector<Track> tracks = track_temporal(curr, R_prev_curr_cam0, prev_px, out.stats);
  if (opt_.patch_refine) refine_with_patches(left, tracks, prev_px, out.stats);
  // Bearings once the pixels are final (the lift iterates for distorted lenses).
  for (auto& t : tracks) t.bearing = cam0_->lift(to_eigen(t.px));
  if (opt_.f_ransac) reject_with_f(tracks, prev_px, out.stats);
  enforce_spacing_and_detect(left, tracks, prev_px, out.stats);

  const double dt = prev_pyr_.empty() ? 0.0 : static_cast<double>(frame.t_ns - prev_t_ns_) * 1e-9;
  out.features.resize(tracks.size());
  for (std::size_t i = 0; i < tracks.size(); ++i) {
    TrackedFeature& f = out.features[i];
    const Track& t = tracks[i];
    f.id = t.id;
    f.track_length = t.length;
    f.px = to_eigen(t.px);
    if (dt > 0 && !std::isnan(prev_px[i].x)) f.px_velocity = (f.px - to_eigen(prev_px[i])) / dt;
    f.bearing = t.bearing;
    f.xy = t.bearing.head<2>() / t.bearing.z();
  }
  if (!frame.labels.empty()) label_features(frame.labels, out.features);

  if (stereo && !tracks.empty()) match_stereo(curr, prepare(frame.right, "right", frame.t_ns), tracks, out);
  else
    for (Track& t : tracks) t.stereo_offset.x = std::numeric_limits<float>::quiet_NaN();

  tracks_ = std::move(tracks);
  std::swap(prev_pyr_, curr_pyr_);
  prev_t_ns_ = frame.t_ns;
  return out;
}

}  // namespace dynavins::tracker
