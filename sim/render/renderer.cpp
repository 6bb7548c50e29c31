#include "sim/render/renderer.hpp"

#include <algorithm>
#include <cmath>
#include <future>
#include <limits>
#include <vector>

namespace dynavins::sim {
namespace {

// Tolerance of the inside test in texture units: adjacent faces overlap by a hair so no pixel falls
// through the crack between them (the z-buffer sorts the overlap out).
constexpr double kInsideEps = 1e-6;

// A quad in the camera frame, reduced to what the per-pixel work needs. For a ray d = (x, y, 1):
// depth t = h / (n . d); texture s = t (au . d) - s0, r = t (av . d) - r0.
struct CamQuad {
  double nx, ny, nz, h;
  double aux, auy, auz, s0;
  double avx, avy, avz, r0;
  const MipTexture* tex;
  float scale;  // 255 * exposure * shading
  uint8_t label;
};

struct Hit {
  double t, s, r;
};

// Intersects the ray (x, y, 1) with the quad; false if it misses or lies nearer than `near`.
inline bool intersect(const CamQuad& q, double x, double y, double near, Hit* hit) {
  const double nd = q.nx * x + q.ny * y + q.nz;
  if (!(nd < 0.0)) return false;  // h < 0 for every kept quad: the plane is hit only if n . d < 0
  const double t = q.h / nd;
  if (t < near) return false;
  const double s = t * (q.aux * x + q.auy * y + q.auz) - q.s0;
  if (s < -kInsideEps || s > 1.0 + kInsideEps) return false;
  const double r = t * (q.avx * x + q.avy * y + q.avz) - q.r0;
  if (r < -kInsideEps || r > 1.0 + kInsideEps) return false;
  *hit = Hit{t, s, r};
  return true;
}

// Shaded gray of a quad hit, with the texture footprint from the ray's derivatives per pixel step.
inline float shade(const CamQuad& q, const Hit& hit, double x, double y, float dxdu, float dydu, float dxdv,
                   float dydv, float footprint, int max_aniso) {
  // Single precision is plenty for the footprint; only the hit itself needs double.
  const float t = static_cast<float>(hit.t);
  const float inv_nd = 1.0f / static_cast<float>(q.nx * x + q.ny * y + q.nz);
  const float ad = static_cast<float>(q.aux * x + q.auy * y + q.auz);
  const float bd = static_cast<float>(q.avx * x + q.avy * y + q.avz);
  const float nx = static_cast<float>(q.nx), ny = static_cast<float>(q.ny);
  const float aux = static_cast<float>(q.aux), auy = static_cast<float>(q.auy);
  const float avx = static_cast<float>(q.avx), avy = static_cast<float>(q.avy);
  // d(t)/d(pixel) = -t (n . dd) / (n . d); d(s) = dt (au . d) + t (au . dd).
  const float dtu = -t * (nx * dxdu + ny * dydu) * inv_nd;
  const float dtv = -t * (nx * dxdv + ny * dydv) * inv_nd;
  const float dsdu = dtu * ad + t * (aux * dxdu + auy * dydu);
  const float dsdv = dtv * ad + t * (aux * dxdv + auy * dydv);
  const float drdu = dtu * bd + t * (avx * dxdu + avy * dydu);
  const float drdv = dtv * bd + t * (avx * dxdv + avy * dydv);
  const float s = std::clamp(static_cast<float>(hit.s), 0.0f, 1.0f);
  const float r = std::clamp(static_cast<float>(hit.r), 0.0f, 1.0f);
  return q.scale * (1.0f / 255.0f) *
         q.tex->sample(s, r, footprint * dsdu, footprint * drdu, footprint * dsdv, footprint * drdv, max_aniso);
}

// Clips a convex polygon (camera frame) to z >= near.
std::vector<Eigen::Vector3d> clip_near(const std::vector<Eigen::Vector3d>& poly, double near) {
  std::vector<Eigen::Vector3d> out;
  for (size_t i = 0; i < poly.size(); ++i) {
    const Eigen::Vector3d& a = poly[i];
    const Eigen::Vector3d& b = poly[(i + 1) % poly.size()];
    const bool ain = a.z() >= near, bin = b.z() >= near;
    if (ain) out.push_back(a);
    if (ain != bin) out.push_back(a + (b - a) * ((near - a.z()) / (b.z() - a.z())));
  }
  return out;
}

// The per-render state: z-buffer, winning quad per pixel, the kept quads; filled by add() and
// rasterise(), turned into the outputs by finish().
class Frame {
 public:
  Frame(const RayTable& rays, const RenderOptions& opt, const Eigen::Isometry3d& T_world_cam)
      : rays_(rays), opt_(opt), R_wc_(T_world_cam.linear()) {
    const size_t n = static_cast<size_t>(rays.width()) * rays.height();
    zbuf_.assign(n, std::numeric_limits<double>::infinity());
    qbuf_.assign(n, -1);
  }

  // Transforms and culls one quad; kept for rasterise().
  void add(const Quad& quad, const Eigen::Isometry3d& T_cam_obj, const Eigen::Matrix3d& R_world_obj,
           uint8_t label) {
    const Eigen::Vector3d o = T_cam_obj * quad.origin;
    const Eigen::Vector3d eu = T_cam_obj.linear() * quad.edge_u;
    const Eigen::Vector3d ev = T_cam_obj.linear() * quad.edge_v;
    Eigen::Vector3d n = eu.cross(ev);
    const double nn = n.norm();
    if (!(nn > 0.0)) return;
    n /= nn;
    double h = n.dot(o);
    Eigen::Vector3d n_world = R_world_obj * quad.normal();
    if (h >= 0.0) {  // camera behind the front side
      if (!quad.two_sided) return;
      n = -n;
      h = -h;
      n_world = -n_world;
    }
    if (h > -1e-12) return;  // seen edge-on

    const std::vector<Eigen::Vector3d> poly = clip_near({o, o + eu, o + eu + ev, o + ev}, opt_.near_m);
    if (poly.size() < 3) return;
    Pending pq;
    pq.poly.reserve(poly.size());
    pq.bb = Eigen::Vector4d(1e300, -1e300, 1e300, -1e300);
    pq.zmin = 1e300;
    for (const auto& p : poly) {
      const Eigen::Vector2d q(p.x() / p.z(), p.y() / p.z());
      pq.poly.push_back(q);
      pq.bb = Eigen::Vector4d(std::min(pq.bb[0], q.x()), std::max(pq.bb[1], q.x()), std::min(pq.bb[2], q.y()),
                              std::max(pq.bb[3], q.y()));
      pq.zmin = std::min(pq.zmin, p.z());
    }
    const Eigen::Vector4f& ib = rays_.image_bounds();
    if (pq.bb[1] < ib[0] || pq.bb[0] > ib[1] || pq.bb[3] < ib[2] || pq.bb[2] > ib[3]) return;

    CamQuad& cq = pq.cq;
    cq.nx = n.x(), cq.ny = n.y(), cq.nz = n.z(), cq.h = h;
    const Eigen::Vector3d au = eu / eu.squaredNorm(), av = ev / ev.squaredNorm();
    cq.aux = au.x(), cq.auy = au.y(), cq.auz = au.z(), cq.s0 = au.dot(o);
    cq.avx = av.x(), cq.avy = av.y(), cq.avz = av.z(), cq.r0 = av.dot(o);
    cq.tex = quad.texture.get();
    const double lambert = std::max(0.0, n_world.dot(opt_.sun_direction));
    cq.scale = static_cast<float>(255.0 * opt_.exposure * (opt_.ambient + opt_.diffuse * lambert));
    cq.label = label;
    pending_.push_back(std::move(pq));
  }

  // Rasterises the kept quads front to back (nearest corner first), so hidden pixels fail the depth
  // test before the inside test. Depth ties keep the earlier quad: the order is deterministic.
  void rasterise() {
    std::vector<int> order(pending_.size());
    for (size_t k = 0; k < order.size(); ++k) order[k] = static_cast<int>(k);
    std::stable_sort(order.begin(), order.end(),
                     [&](int a, int b) { return pending_[a].zmin < pending_[b].zmin; });
    quads_.reserve(pending_.size());
    for (int k : order) {
      quads_.push_back(pending_[k].cq);
      raster_one(pending_[k], static_cast<int>(quads_.size()) - 1);
    }
  }

  // Shades every pixel and fills the outputs.
  RenderedView finish() const {
    const int W = rays_.width(), H = rays_.height();
    RenderedView out;
    out.gray.create(H, W, CV_8UC1);
    out.depth.create(H, W, CV_32FC1);
    out.labels.create(H, W, CV_8UC1);
    const int aniso = opt_.max_anisotropy;
    const std::vector<uint8_t> edges = opt_.antialias_edges ? edge_mask() : std::vector<uint8_t>();
    for (int v = 0; v < H; ++v) {
      uint8_t* g = out.gray.ptr<uint8_t>(v);
      float* d = out.depth.ptr<float>(v);
      uint8_t* l = out.labels.ptr<uint8_t>(v);
      for (int u = 0; u < W; ++u) {
        const int i = v * W + u;
        const int q = qbuf_[i];
        const double x = rays_.x(i), y = rays_.y(i);
        const float dxdu = rays_.dxdu(i), dydu = rays_.dydu(i), dxdv = rays_.dxdv(i), dydv = rays_.dydv(i);
        float value;
        if (!edges.empty() && edges[i]) {
          value = supersample(u, v, x, y, dxdu, dydu, dxdv, dydv);
        } else if (q >= 0) {
          const Hit hit = recompute(quads_[q], x, y);
          value = shade(quads_[q], hit, x, y, dxdu, dydu, dxdv, dydv, 1.0f, aniso);
        } else {
          value = sky(x, y);
        }
        g[u] = static_cast<uint8_t>(std::clamp(value, 0.0f, 255.0f) + 0.5f);  // round half up
        d[u] = q >= 0 ? static_cast<float>(zbuf_[i]) : std::numeric_limits<float>::infinity();
        l[u] = q >= 0 ? quads_[q].label : 0;
      }
    }
    return out;
  }

 private:
  // A kept quad: camera-frame plane and texture mapping, its clipped projection and nearest depth.
  struct Pending {
    CamQuad cq;
    std::vector<Eigen::Vector2d> poly;
    Eigen::Vector4d bb;
    double zmin;
  };

  // Visits the raster cells the quad's projection can touch; per pixel the exact ray-plane test.
  void raster_one(const Pending& pq, int qi) {
    const CamQuad& cq = pq.cq;
    const auto& p2 = pq.poly;
    const Eigen::Vector4d& bb = pq.bb;
    double area = 0.0;  // sign gives the winding for the outward edge normals
    for (size_t i = 0; i < p2.size(); ++i) {
      const auto& a = p2[i];
      const auto& b = p2[(i + 1) % p2.size()];
      area += a.x() * b.y() - a.y() * b.x();
    }
    const double orient = area >= 0.0 ? 1.0 : -1.0;
    const double tol = 1e-6;
    const double near = opt_.near_m;
    const int W = rays_.width(), H = rays_.height(), C = RayTable::kCell;
    for (int cv = 0; cv < rays_.cells_v(); ++cv) {
      for (int cu = 0; cu < rays_.cells_u(); ++cu) {
        const Eigen::Vector4f& cb = rays_.cell_bounds(cv * rays_.cells_u() + cu);
        if (bb[1] < cb[0] - tol || bb[0] > cb[1] + tol || bb[3] < cb[2] - tol || bb[2] > cb[3] + tol) continue;
        if (std::abs(area) > 1e-12 && separated(p2, orient, cb, tol)) continue;
        for (int v = cv * C; v < std::min(H, (cv + 1) * C); ++v) {
          for (int u = cu * C; u < std::min(W, (cu + 1) * C); ++u) {
            const int i = v * W + u;
            const double x = rays_.x(i), y = rays_.y(i);
            const double nd = cq.nx * x + cq.ny * y + cq.nz;
            if (!(nd < 0.0)) continue;
            const double t = cq.h / nd;
            if (!(t < zbuf_[i]) || t < near) continue;  // depth first: cheap rejection of hidden pixels
            const double s = t * (cq.aux * x + cq.auy * y + cq.auz) - cq.s0;
            if (s < -kInsideEps || s > 1.0 + kInsideEps) continue;
            const double r = t * (cq.avx * x + cq.avy * y + cq.avz) - cq.r0;
            if (r < -kInsideEps || r > 1.0 + kInsideEps) continue;
            zbuf_[i] = t;
            qbuf_[i] = qi;
          }
        }
      }
    }
  }

  static bool separated(const std::vector<Eigen::Vector2d>& p, double orient, const Eigen::Vector4f& cb,
                        double tol) {
    const double cx[4] = {cb[0], cb[1], cb[1], cb[0]};
    const double cy[4] = {cb[2], cb[2], cb[3], cb[3]};
    for (size_t i = 0; i < p.size(); ++i) {
      const Eigen::Vector2d& a = p[i];
      const Eigen::Vector2d& b = p[(i + 1) % p.size()];
      // Outward normal of edge a->b for a counter-clockwise polygon is (ey, -ex).
      const double mx = orient * (b.y() - a.y()), my = -orient * (b.x() - a.x());
      const double len = std::hypot(mx, my);
      if (len <= 0.0) continue;
      bool all_out = true;
      for (int k = 0; k < 4 && all_out; ++k) all_out = (mx * (cx[k] - a.x()) + my * (cy[k] - a.y())) / len > tol;
      if (all_out) return true;
    }
    return false;
  }

  static Hit recompute(const CamQuad& q, double x, double y) {
    const double t = q.h / (q.nx * x + q.ny * y + q.nz);
    return Hit{t, t * (q.aux * x + q.auy * y + q.auz) - q.s0, t * (q.avx * x + q.avy * y + q.avz) - q.r0};
  }

  // Pixels whose 8-neighbourhood shows another surface (not merely the next tile of the same plane).
  std::vector<uint8_t> edge_mask() const {
    const int W = rays_.width(), H = rays_.height();
    std::vector<uint8_t> m(qbuf_.size(), 0);
    auto differ = [&](int a, int b) {
      const int qa = qbuf_[a], qb = qbuf_[b];
      return qa != qb && !(qa >= 0 && qb >= 0 && coplanar(quads_[qa], quads_[qb]));
    };
    // Each unordered neighbour pair once: right, down-left, down, down-right; both pixels get marked.
    for (int v = 0; v < H; ++v) {
      for (int u = 0; u < W; ++u) {
        const int i = v * W + u;
        if (u + 1 < W && differ(i, i + 1)) m[i] = m[i + 1] = 1;
        if (v + 1 < H) {
          if (differ(i, i + W)) m[i] = m[i + W] = 1;
          if (u > 0 && differ(i, i + W - 1)) m[i] = m[i + W - 1] = 1;
          if (u + 1 < W && differ(i, i + W + 1)) m[i] = m[i + W + 1] = 1;
        }
      }
    }
    return m;
  }

  static bool coplanar(const CamQuad& a, const CamQuad& b) {
    return a.label == b.label && std::abs(a.nx * b.nx + a.ny * b.ny + a.nz * b.nz - 1.0) < 1e-9 &&
           std::abs(a.h - b.h) < 1e-6 * std::abs(a.h);
  }

  // Box filter of the pixel from 4 rotated-grid sub-samples, each hitting the nearest of the quads seen
  // in the 3x3 neighbourhood (or the sky).
  float supersample(int u, int v, double x, double y, float dxdu, float dydu, float dxdv, float dydv) const {
    static const double kOff[4][2] = {{-0.125, -0.375}, {0.375, -0.125}, {0.125, 0.375}, {-0.375, 0.125}};
    const int W = rays_.width(), H = rays_.height();
    int cand[9];
    int nc = 0;
    for (int dv = -1; dv <= 1; ++dv) {
      for (int du = -1; du <= 1; ++du) {
        const int uu = std::clamp(u + du, 0, W - 1), vv = std::clamp(v + dv, 0, H - 1);
        const int o = qbuf_[vv * W + uu];
        if (o >= 0 && std::find(cand, cand + nc, o) == cand + nc) cand[nc++] = o;
      }
    }
    float acc = 0.0f;
    for (const auto& off : kOff) {
      // First-order sub-pixel ray; the ray table is smooth at this scale.
      const double sx = x + dxdu * off[0] + dxdv * off[1];
      const double sy = y + dydu * off[0] + dydv * off[1];
      Hit best{std::numeric_limits<double>::infinity(), 0.0, 0.0};
      int bq = -1;
      for (int k = 0; k < nc; ++k) {
        Hit hit;
        if (intersect(quads_[cand[k]], sx, sy, opt_.near_m, &hit) && hit.t < best.t) {
          best = hit;
          bq = cand[k];
        }
      }
      acc += bq >= 0 ? shade(quads_[bq], best, sx, sy, dxdu, dydu, dxdv, dydv, 0.5f, opt_.max_anisotropy)
                     : sky(sx, sy);
    }
    return 0.25f * acc;
  }

  // Smooth featureless sky: brighter toward the horizon and around the sun.
  float sky(double x, double y) const {
    const Eigen::Vector3d d = (R_wc_ * Eigen::Vector3d(x, y, 1.0)).normalized();
    const double e = 1.0 - std::max(0.0, d.z());
    const double c1 = std::max(0.0, d.dot(opt_.sun_direction));
    const double c4 = c1 * c1 * c1 * c1;
    // Quadratic in elevation: a finite slope at the horizon keeps the gradient under a level per pixel.
    const double g = opt_.sky_horizon + (opt_.sky_zenith - opt_.sky_horizon) * (1.0 - e * e) + 14.0 * c4 * c4;
    return static_cast<float>(std::min(g, 235.0));
  }

  const RayTable& rays_;
  const RenderOptions& opt_;
  Eigen::Matrix3d R_wc_;
  std::vector<double> zbuf_;
  std::vector<int> qbuf_;
  std::vector<CamQuad> quads_;
  std::vector<Pending> pending_;
};

}  // namespace

Renderer::Renderer(const CameraIntrinsics& camera, const RenderOptions& options)
    : rays_(std::make_shared<const RayTable>(camera)), options_(options) {
  options_.sun_direction.normalize();
}

RenderedView Renderer::render(const World& world, double t, const Eigen::Isometry3d& T_world_cam) const {
  Frame frame(*rays_, options_, T_world_cam);
  const Eigen::Isometry3d T_cam_world = T_world_cam.inverse();
  for (const WorldObject& obj : world.objects()) {
    const Eigen::Isometry3d T_world_obj = obj.pose_at(t);
    const Eigen::Isometry3d T_cam_obj = T_cam_world * T_world_obj;
    for (const Quad& q : obj.quads) frame.add(q, T_cam_obj, T_world_obj.linear(), static_cast<uint8_t>(obj.id));
  }
  frame.rasterise();
  return frame.finish();
}

std::pair<RenderedView, RenderedView> Renderer::render_stereo(const World& world, double t,
                                                              const Eigen::Isometry3d& T_world_left,
                                                              const Eigen::Isometry3d& T_left_right) const {
  auto right = std::async(std::launch::async, [&] { return render(world, t, T_world_left * T_left_right); });
  RenderedView left = render(world, t, T_world_left);
  return {std::move(left), right.get()};
}

}  // namespace dynavins::sim
