// Light tracing's sensor connections along medium rays: one per ray against several per ray
// (stratified on the equiangular distribution, weighted against the collisions by the balance
// heuristic with the connections' count).
#include <catch2/catch.hpp>

#include <vector>

#include "agreement.h"
#include "core/integrators/light_tracer.h"
#include "core/rng.h"
#include "core/scene_loader.h"

using namespace femto;
using namespace femto::test;

namespace {

/// Sums of `batches` x `paths` light paths per block of 4 x 4 pixels and 125 ps (up to 4 ns):
/// cells[c][b]; and the number of splats.
std::vector<std::vector<double>> traced_cells(const Scene& scene, double streak_pixels,
                                              int batches, int paths, uint64_t seed,
                                              size_t& splats) {
  const Camera& cam = scene.camera();
  const int bx = (cam.width() + 3) / 4, by = (cam.height() + 3) / 4;
  constexpr int kGroups = 32;
  std::vector<std::vector<double>> out(static_cast<size_t>(bx * by * kGroups),
                                       std::vector<double>(static_cast<size_t>(batches), 0.0));
  LightTracer tracer(scene, 64, 1e6);
  tracer.set_streak_pixels(streak_pixels);
  std::vector<Splat> buf;
  PathStats stats;
  splats = 0;
  for (int b = 0; b < batches; ++b)
    for (int i = 0; i < paths; ++i) {
      Rng rng = Rng::for_sample(seed + static_cast<uint64_t>(b), 7, static_cast<uint64_t>(i));
      buf.clear();
      tracer.trace(rng, buf, stats);
      splats += buf.size();
      for (const Splat& s : buf) {
        const int x = static_cast<int>(s.pixel) % cam.width(),
                  y = static_cast<int>(s.pixel) / cam.width();
        const int g = static_cast<int>(s.t_ps / 125.0);
        if (g < 0 || g >= kGroups) continue;
        out[static_cast<size_t>(((y / 4) * bx + x / 4) * kGroups + g)][static_cast<size_t>(b)] +=
            (s.value.r + s.value.g + s.value.b) / paths;
      }
    }
  return out;
}

}  // namespace

// Catches: the connections' count missing from either side of the MIS with the collisions (the
// collisions' weight p_c / (p_c + K p_eq): max |z| 12.6; each connection's f / (K p_eq + p_c):
// 55), or a connection's time taken from another (87): one connection per ray and up to four
// must estimate the same bins (as built max |z| 2.3 over 49 cells). Thin fog (few collisions: the connections carry most of
// the light) and a film small enough that with 2 pixels per connection most rays get several.
TEST_CASE("light tracing: several sensor connections per medium ray agree with one",
          "[light-paths][statistical]") {
  const SceneDesc d = load_scene_string(R"({
    "camera": { "type": "perspective", "position": [0, 30, 140], "look_at": [0, 25, 0], "fov": 45,
                "resolution": [16, 12] },
    "time": { "t_start": 0, "bin_width": 100, "bins": 40 },
    "media": { "fog": { "type": "homogeneous", "sigma_a": 0.002, "sigma_s": 0.01, "g": 0.4, "eta": 1.33 } },
    "shapes": [
      { "type": "box", "min": [-59, 1, -59], "max": [59, 60, 59], "medium": "fog" },
      { "type": "quad", "corner": [-60, 0, 60], "edge1": [120, 0, 0], "edge2": [0, 0, -120],
        "material": { "type": "diffuse", "albedo": 0.7 } }
    ],
    "lights": [ { "type": "point", "position": [10, 75, -10], "intensity": 2000 } ]
  })",
                                        "thin fog box", ".");
  const Scene scene(d);
  size_t splats_one = 0, splats_many = 0;
  const auto one = traced_cells(scene, 1e9, 24, 20000, 500, splats_one);
  const auto many = traced_cells(scene, 2.0, 24, 20000, 600, splats_many);
  INFO("splats: " << splats_one << " with one connection per ray, " << splats_many
                  << " with several");
  CHECK(static_cast<double>(splats_many) > 1.5 * static_cast<double>(splats_one));
  require_agreement(many, one, 40, 0.02);
}
