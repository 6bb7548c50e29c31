#include "eval/trajectory_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace dynavins::eval {

ErrorStats error_stats(const std::vector<double>& errors) {
  if (errors.empty()) throw std::invalid_argument("error_stats: no errors to summarise");
  ErrorStats s;
  s.count = errors.size();
  const double n = static_cast<double>(errors.size());
  double sum = 0.0;
  for (double e : errors) {
    sum += e;
    s.sse += e * e;
  }
  s.mean = sum / n;
  s.rmse = std::sqrt(s.sse / n);
  double var = 0.0;
  for (double e : errors) var += (e - s.mean) * (e - s.mean);
  s.std = std::sqrt(var / n);

  std::vector<double> sorted = errors;
  std::sort(sorted.begin(), sorted.end());
  s.min = sorted.front();
  s.max = sorted.back();
  const std::size_t mid = sorted.size() / 2;
  s.median = sorted.size() % 2 == 1 ? sorted[mid] : 0.5 * (sorted[mid - 1] + sorted[mid]);
  return s;
}

std::vector<double> ate_translation_errors(const std::vector<Eigen::Vector3d>& gt,
                                           const std::vector<Eigen::Vector3d>& est) {
  if (gt.size() != est.size()) {
    throw std::invalid_argument("ate: " + std::to_string(gt.size()) + " ground-truth positions but " +
                                std::to_string(est.size()) + " estimated ones");
  }
  std::vector<double> e(gt.size());
  for (std::size_t i = 0; i < gt.size(); ++i) e[i] = (est[i] - gt[i]).norm();
  return e;
}

std::vector<double> rpe_translation_errors(const std::vector<Eigen::Isometry3d>& gt,
                                           const std::vector<Eigen::Isometry3d>& est, std::size_t delta) {
  if (gt.size() != est.size()) {
    throw std::invalid_argument("rpe: " + std::to_string(gt.size()) + " ground-truth poses but " +
                                std::to_string(est.size()) + " estimated ones");
  }
  if (delta == 0) throw std::invalid_argument("rpe: delta must be at least 1 frame");
  if (gt.size() <= delta) {
    throw std::invalid_argument("rpe: delta = " + std::to_string(delta) + " frames needs more than " +
                                std::to_string(delta) + " associated poses, got " + std::to_string(gt.size()));
  }
  std::vector<double> e;
  e.reserve(gt.size() / delta);
  for (std::size_t i = 0; i + delta < gt.size(); i += delta) {
    const std::size_t j = i + delta;
    const Eigen::Isometry3d gt_rel = gt[i].inverse() * gt[j];
    const Eigen::Isometry3d est_rel = est[i].inverse() * est[j];
    e.push_back((gt_rel.inverse() * est_rel).translation().norm());
  }
  return e;
}

}  // namespace dynavins::eval
