// Render speed of the simulator on the example street (a measurement, not a test: machines are noisy).
// Usage: build/bin/bench_render
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>

#include "sim/render/renderer.hpp"
#include "sim/render/street_scene.hpp"

using namespace dynavins::sim;

int main() {
  StreetSceneOptions o;
  o.truck_start_x = 5.0;
  const auto build0 = std::chrono::steady_clock::now();
  const World w = make_street_scene(o);
  std::printf("street scene built in %.1f s\n",
              std::chrono::duration<double>(std::chrono::steady_clock::now() - build0).count());

  // Thread CPU time next to wall time: the machine is shared, CPU time is the steadier figure.
  auto cpu_ms = [] {
    timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
  };
  const Renderer renderer;
  std::printf("street scene: %zu quads, %.1f MB of textures\n", w.num_quads(), w.texture_bytes() / 1e6);
  const int n = 20;
  double wall = 0.0, cpu = 0.0, worst = 0.0;
  for (int k = 0; k < n; ++k) {
    const double t = 0.05 * k;
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = cpu_ms();
    const RenderedView v = renderer.render(w, t, street_camera_pose(3.0 * t, -1.75, 1.5, 0.02 * std::sin(t)));
    cpu += cpu_ms() - c0;
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    wall += ms;
    worst = std::max(worst, ms);
    if (v.gray.empty()) return 1;
  }
  std::printf("render 752x480 street view: %.1f ms CPU, %.1f ms wall (worst %.1f), one thread\n", cpu / n,
              wall / n, worst);
  Eigen::Isometry3d T_lr = Eigen::Isometry3d::Identity();
  T_lr.translation().x() = 0.11;
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < n; ++k) renderer.render_stereo(w, 0.05 * k, street_camera_pose(0.15 * k, -1.75, 1.5), T_lr);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() / n;
  std::printf("render_stereo: %.1f ms wall per stereo pair (two threads)\n", ms);
  return 0;
}
