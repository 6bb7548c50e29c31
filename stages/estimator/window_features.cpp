#include "stages/estimator/window_features.hpp"

#include <Eigen/SVD>

namespace dynavins::estimator {

bool WindowFeatures::add_frame(int slot, const TrackedFrame& frame, double min_parallax, bool use_right) {
  int tracked = 0, long_tracks = 0, new_features = 0;
  for (const TrackedFeature& tf : frame.features) {
    FeatureObservation o;
    o.xy = tf.xy;
    o.px = tf.px;
    o.has_right = use_right && tf.has_right;
    o.xy_right = tf.xy_right;
    o.px_right = tf.px_right;
    auto it = features_.find(tf.id);
    if (it == features_.end() || it->second.end_slot() != slot - 1) {
      // New to the window (or a gap in its track, which ids never have): anchor it here.
      WindowFeature f;
      f.id = tf.id;
      f.start_slot = slot;
      f.obs.push_back(o);
      f.sim_label = tf.sim_label;
      features_[tf.id] = std::move(f);
      ++new_features;
    } else {
      it->second.obs.push_back(o);
      it->second.sim_label = tf.sim_label;
      ++tracked;
      if (it->second.obs.size() >= 4) ++long_tracks;
    }
  }
  last_track_num_ = tracked;

  if (slot < 2 || tracked < 20 || long_tracks < 40 || new_features > 0.5 * tracked) return true;
  // Average parallax of slot-1 against slot-2 (VINS-Fusion's compensatedParallax2, without rotation
  // compensation, as its code does).
  double sum = 0;
  int n = 0;
  for (const auto& [id, f] : features_) {
    if (f.start_slot <= slot - 2 && f.end_slot() >= slot - 1) {
      const auto& a = f.obs[slot - 2 - f.start_slot].xy;
      const auto& b = f.obs[slot - 1 - f.start_slot].xy;
      sum += (a - b).norm();
      ++n;
    }
  }
  if (n == 0) return true;
  return sum / n >= min_parallax;
}

Eigen::Vector3d triangulate_two_view(const CameraPose& c0, const CameraPose& c1, const Eigen::Vector2d& x0,
                                   const Eigen::Vector2d& x1) {
  // Rows x * P3 - P1 and y * P3 - P2 of each camera's projection P = [R^T | -R^T p].
  auto projection = [](const CameraPose& c) {
    Eigen::Matrix<double, 3, 4> P;
    P.leftCols<3>() = c.R.transpose();
    P.col(3) = -c.R.transpose() * c.p;
    return P;
  };
  const Eigen::Matrix<double, 3, 4> P0 = projection(c0), P1 = projection(c1);
  Eigen::Matrix4d A;
  A.row(0) = x0.x() * P0.row(2) - P0.row(0);
  A.row(1) = x0.y() * P0.row(2) - P0.row(1);
  A.row(2) = x1.x() * P1.row(2) - P1.row(0);
  A.row(3) = x1.y() * P1.row(2) - P1.row(1);
  const Eigen::Vector4d X = Eigen::JacobiSVD<Eigen::Matrix4d>(A, Eigen::ComputeFullV).matrixV().col(3);
  return X.head<3>() / X(3);
}

void WindowFeatures::triangulate(const SlotCameraPose& cam, const Eigen::Isometry3d& T_c0c1, bool use_right) {
  for (auto& [id, f] : features_) {
    if (f.has_depth) continue;
    const CameraPose c0 = cam(f.start_slot);
    Eigen::Vector3d p_w;
    if (use_right && f.obs[0].has_right) {
      const CameraPose c1{c0.R * T_c0c1.linear(), c0.p + c0.R * T_c0c1.translation()};
      p_w = triangulate_two_view(c0, c1, f.obs[0].xy, f.obs[0].xy_right);
    } else if (f.obs.size() >= 2) {
      p_w = triangulate_two_view(c0, cam(f.start_slot + 1), f.obs[0].xy, f.obs[1].xy);
    } else {
      continue;
    }
    const double depth = (c0.R.transpose() * (p_w - c0.p)).z();
    if (std::isfinite(depth) && depth > 0.1 && depth < 1000.0) {
      f.inv_depth = 1.0 / depth;
      f.has_depth = true;
    }
  }
}

void WindowFeatures::reanchor(WindowFeature& f, const CameraPose& old_anchor, const CameraPose& new_anchor) const {
  if (!f.has_depth) return;
  const Eigen::Vector3d p_c = Eigen::Vector3d(f.obs[0].xy.x(), f.obs[0].xy.y(), 1.0) / f.inv_depth;
  const Eigen::Vector3d p_w = old_anchor.R * p_c + old_anchor.p;
  const double depth = (new_anchor.R.transpose() * (p_w - new_anchor.p)).z();
  if (std::isfinite(depth) && depth > 0.1) {
    f.inv_depth = 1.0 / depth;
  } else {
    f.has_depth = false;  // re-triangulated later
  }
}

void WindowFeatures::remove_oldest(const SlotCameraPose& cam, bool keep_past) {
  const CameraPose c0 = cam(0), c1 = cam(1);
  keep_past = keep_past && max_past_ > 0;
  if (keep_past) past_frame_ = c1;
  for (auto it = features_.begin(); it != features_.end();) {
    WindowFeature& f = it->second;
    if (f.start_slot != 0) {
      --f.start_slot;
    } else if (f.obs.size() < 2) {
      it = features_.erase(it);
      continue;
    } else {
      reanchor(f, c0, c1);
      if (keep_past) {
        if (static_cast<int>(f.past.size()) >= max_past_) f.past.erase(f.past.begin());
        f.past.push_back({c0, f.obs[0].xy});
      }
      f.obs.erase(f.obs.begin());
    }
    ++it;
  }
}

void WindowFeatures::remove_slot(int slot, const SlotCameraPose& cam) {
  for (auto it = features_.begin(); it != features_.end();) {
    WindowFeature& f = it->second;
    if (f.start_slot > slot) {
      --f.start_slot;
    } else if (f.start_slot == slot) {
      if (f.obs.size() < 2) {
        it = features_.erase(it);
        continue;
      }
      reanchor(f, cam(slot), cam(slot + 1));
      f.obs.erase(f.obs.begin());  // the next observation is now the anchor, at the same slot index
    } else if (f.end_slot() >= slot) {
      f.obs.erase(f.obs.begin() + (slot - f.start_slot));
    }
    ++it;
  }
}

int WindowFeatures::remove_bad_depths() {
  int n = 0;
  for (auto it = features_.begin(); it != features_.end();) {
    if (it->second.has_depth && !(it->second.inv_depth > 0)) {
      it = features_.erase(it);
      ++n;
    } else {
      ++it;
    }
  }
  return n;
}

}  // namespace dynavins::estimator
