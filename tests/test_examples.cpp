// Every example scene in data/scenes loads, builds and renders (tiny resolution, 2 spp, with the
// integrator femto render would choose) to a finite, non-black film.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>

#include "core/render.h"
#include "core/scene_loader.h"
#include "core/tissue/scene.h"
#include "core/tissue/simulate.h"

using namespace femto;

// Catches: example scenes drifting out of sync with the scene format or the tracer (tissue
// scenes: with the tissue loader, a few photons, energy balanced).
TEST_CASE("example scenes load and render", "[examples]") {
  const std::filesystem::path dir = std::filesystem::path(FEMTO_SOURCE_DIR) / "data" / "scenes";
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".json") continue;
    INFO(entry.path().string());
    const std::string text = read_scene_text(entry.path().string());
    if (tissue::is_tissue_scene(text)) {
      tissue::Setup t = tissue::load_tissue_scene(text, entry.path().string(), dir.string());
      t.photons = 500;
      const tissue::Result r = tissue::simulate(t);
      CHECK(r.balance.absorbed > 0);
      CHECK(std::abs(r.balance.residual()) <= 1e-12 * r.balance.launched);
      ++count;
      continue;
    }
    SceneDesc desc = load_scene_file(entry.path().string());
    desc.camera.width = 24;
    desc.camera.height = 18;
    std::string why;
    RenderOptions opt;
    opt.integrator = resolve_integrator(desc, desc.integrator.kind, why);  // as femto render would
    opt.photons = desc.integrator.photons;
    opt.photons.per_pass = 2000;
    opt.light_paths = 20000;
    const Scene scene(std::move(desc));
    opt.spp = 2;
    opt.quiet = true;
    const RenderResult r = render(scene, opt);
    const TransientFilm& f = r.film;
    double sum = 0;
    const size_t n = static_cast<size_t>(f.width()) * f.height() * f.bins() * 3;
    for (size_t i = 0; i < n; ++i) {
      REQUIRE(std::isfinite(f.transient()[i]));
      sum += f.transient()[i];
    }
    CHECK(sum > 0);
    CHECK(r.stats.nonfinite_dropped == 0);
    ++count;
  }
  CHECK(count >= 1);
}
