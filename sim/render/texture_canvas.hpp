#pragma once
// A float albedo image laid out in metres, with the painting and noise primitives the procedural
// textures are made of. Noise is anchored to metric coordinates (x0, y0 = the canvas' corner in the
// surface's own frame), so adjacent ground tiles painted with the same key join without seams.

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

namespace dynavins::sim {

class TextureCanvas {
 public:
  /// cols x rows texels of `texel_m` metres; texel (0, 0) has its lower corner at (x0_m, y0_m).
  TextureCanvas(int cols, int rows, double texel_m, double x0_m = 0.0, double y0_m = 0.0, float fill = 0.5f);

  cv::Mat1f& image() { return img_; }
  const cv::Mat1f& image() const { return img_; }
  int cols() const { return img_.cols; }
  int rows() const { return img_.rows; }
  double texel() const { return texel_; }
  double x0() const { return x0_; }
  double y0() const { return y0_; }
  double width_m() const { return img_.cols * texel_; }
  double height_m() const { return img_.rows * texel_; }
  /// Metric coordinates of the centre of texel (col, row).
  Eigen::Vector2d centre(int col, int row) const {
    return {x0_ + (col + 0.5) * texel_, y0_ + (row + 0.5) * texel_};
  }

  // Painting: inside the shape, albedo moves toward `value` by `alpha` (1 = opaque).
  /// Axis-aligned rectangle [xa, xb] x [ya, yb] in metres.
  void fill_rect(double xa, double ya, double xb, double yb, float value, float alpha = 1.0f);
  /// Rectangle with half-extents `half`, rotated by `angle` [rad] about `c`.
  void fill_rotated_rect(const Eigen::Vector2d& c, const Eigen::Vector2d& half, double angle, float value,
                         float alpha = 1.0f);
  /// Closed polygon (any winding).
  void fill_polygon(const std::vector<Eigen::Vector2d>& pts, float value, float alpha = 1.0f);
  /// Ellipse with semi-axes (ax, ay) rotated by `angle` [rad].
  void fill_ellipse(const Eigen::Vector2d& c, double ax, double ay, double angle, float value,
                    float alpha = 1.0f);
  /// Polyline of the given width.
  void stroke(const std::vector<Eigen::Vector2d>& pts, double width_m, float value, float alpha = 1.0f);

  // Noise, all deterministic in (key, metric position).
  /// Smooth value noise in [-1, 1] with feature size `cell_m`, rotated by a key-dependent angle so the
  /// lattice leaves no axis-aligned marks.
  cv::Mat1f noise_field(uint64_t key, double cell_m) const;
  /// Adds `amplitude` times a sum of octaves (cell halves, amplitude times `persistence` each).
  void add_fractal_noise(uint64_t key, double cell_m, int octaves, float amplitude, float persistence = 0.55f);
  /// Multiplies the albedo by (1 + amplitude * fractal noise): texture that follows the paint.
  void modulate_fractal_noise(uint64_t key, double cell_m, int octaves, float amplitude,
                              float persistence = 0.55f);
  /// Sharp-edged patches where the noise exceeds `threshold`: albedo moves toward `value` by `alpha`.
  void add_blotches(uint64_t key, double cell_m, float threshold, float value, float alpha);
  /// Like add_blotches but relative: inside the patches the albedo is multiplied toward `factor`, so dark
  /// paint stays dark (dirt, scratches).
  void scale_blotches(uint64_t key, double cell_m, float threshold, float factor, float alpha);
  /// Independent per-texel grain of the given amplitude, keyed on the global texel index.
  void add_grain(uint64_t key, float amplitude);

  /// Albedo clamped to [lo, hi] and quantised to CV_8UC1 (value * 255).
  cv::Mat to_u8(float lo = 0.02f, float hi = 0.78f) const;

 private:
  // Blends toward value inside the mask drawn by `draw` over the texel box [c0,c1) x [r0,r1).
  template <class Draw>
  void blend_region(double xa, double ya, double xb, double yb, float value, float alpha, Draw draw);

  cv::Mat1f img_;
  double texel_;
  double x0_;
  double y0_;
};

}  // namespace dynavins::sim
