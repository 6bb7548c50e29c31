#pragma once
// Procedural albedo textures for the surfaces of the synthetic street: building facades, walls, roofs,
// and the faces of cars and trucks. Deterministic in the seed; rich in corners at every scale so a KLT
// tracker finds features everywhere, and free of strictly periodic patterns.

#include <cstdint>
#include <memory>

#include <opencv2/core/mat.hpp>

#include "sim/render/mip_texture.hpp"

namespace dynavins::sim {

/// What a textured face shows. Vehicle faces of one vehicle share the seed (same body colour).
enum class SurfaceKind {
  Facade,      ///< building front with floors, windows, shops and signs
  Wall,        ///< boundary wall: concrete panels, posters, graffiti, stains
  Roof,        ///< flat roof: gravel, vents
  CarSide,
  CarFront,
  CarBack,
  CarTop,
  TruckSide,
  TruckFront,
  TruckBack,
  TruckTop,
};

/// One face to paint: its size in metres (u along the face, v up or along its second edge).
struct SurfaceSpec {
  SurfaceKind kind = SurfaceKind::Facade;
  double width_m = 10.0;
  double height_m = 10.0;
  double texel_m = 0.02;
  uint64_t seed = 1;
  bool front_at_u0 = true;  ///< vehicle sides: the vehicle's front is at u = 0 (else at u = width)
};

/// Paints the face; returns a CV_8UC1 albedo image (row 0 at v = 0, i.e. the bottom of a wall).
/// Its size is width/texel x height/texel, the texel grown if a side would exceed 8192.
cv::Mat paint_surface(const SurfaceSpec& spec);

/// paint_surface wrapped into a mip-mapped texture.
std::shared_ptr<const MipTexture> make_surface_texture(const SurfaceSpec& spec);

}  // namespace dynavins::sim
