#pragma once
// Ground albedo painted in world coordinates (z-up world, metres): asphalt roads with lane markings,
// curbs, paved sidewalks with irregular slabs, and grass/gravel verges beyond. Everything is a function
// of the world position and the seed, so tiles painted separately join without seams.

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

namespace dynavins::sim {

/// A straight road segment on the ground, from a to b (world x, y).
struct Road {
  Eigen::Vector2d a = Eigen::Vector2d::Zero();
  Eigen::Vector2d b = Eigen::Vector2d(100.0, 0.0);
  double width_m = 7.0;     ///< carriageway, curb to curb
  bool centre_line = true;  ///< dashed centre marking
};

/// Where the ground is road, sidewalk or verge. With no roads the whole ground is asphalt.
struct GroundLayout {
  std::vector<Road> roads;
  double curb_m = 0.2;
  double sidewalk_m = 3.0;
  uint64_t seed = 1;
};

/// Ground classes, as painted.
enum class GroundClass : uint8_t { Road = 0, Curb = 1, Sidewalk = 2, Verge = 3 };

/// Class of the ground at world (x, y).
GroundClass classify_ground(const GroundLayout& layout, const Eigen::Vector2d& p);

/// Paints the rectangle [x0, x0 + w] x [y0, y0 + h]; CV_8UC1 albedo, row index along +y.
cv::Mat paint_ground(const GroundLayout& layout, double x0, double y0, double w, double h, double texel_m);

}  // namespace dynavins::sim
