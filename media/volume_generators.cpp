#include "media/volume_generators.h"

#include <algorithm>
#include <cmath>

#include "core/rng.h"

namespace femto {
namespace {

// Lattice value in [0, 1) from integer hashing, so noise is identical on every platform.
double lattice(uint64_t key, int64_t x, int64_t y, int64_t z) {
  const uint64_t h = mix64(mix64(mix64(key + uint64_t(x)) + uint64_t(y)) + uint64_t(z));
  return double(h >> 11) * 0x1.0p-53;
}

double fade(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }  // C2-smooth blend

// Trilinear value noise with quintic fading, in [0, 1].
double value_noise(uint64_t key, const Vec3& p) {
  const double fx = std::floor(p.x), fy = std::floor(p.y), fz = std::floor(p.z);
  const auto x = int64_t(fx), y = int64_t(fy), z = int64_t(fz);
  const double u = fade(p.x - fx), v = fade(p.y - fy), w = fade(p.z - fz);
  double sum = 0;
  for (int c = 0; c < 8; ++c) {
    const int a = c & 1, b = (c >> 1) & 1, d = (c >> 2) & 1;
    sum += (a ? u : 1 - u) * (b ? v : 1 - v) * (d ? w : 1 - w) * lattice(key, x + a, y + b, z + d);
  }
  return sum;
}

// Fractal sum of 5 octaves (lacunarity 2, gain 0.5), normalised to [0, 1], mean ~0.5.
double fbm(uint64_t key, const Vec3& p) {
  double sum = 0, amp = 1, norm = 0, freq = 1;
  for (int o = 0; o < 5; ++o) {
    // A per-octave shift keeps lattice points of different octaves from lining up.
    sum += amp * value_noise(mix64(key + uint64_t(o)), p * freq + Vec3(17.3 * o, 31.7 * o, 5.9 * o));
    norm += amp;
    amp *= 0.5;
    freq *= 2;
  }
  return sum / norm;
}

double smoothstep(double e0, double e1, double x) {
  const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

// Calls f(i, j, k, p) for every cell with p its centre in [-1, 1]^3.
template <class F>
void for_cells(int n, F f) {
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        f(i, j, k, Vec3((i + 0.5) / n * 2 - 1, (j + 0.5) / n * 2 - 1, (k + 0.5) / n * 2 - 1));
}

uint64_t stream(uint64_t seed, uint64_t field) { return mix64(seed * 0x9e3779b97f4a7c15ULL + field); }

}  // namespace

GeneratedVolume make_cloud(int n, uint64_t seed) {
  GeneratedVolume vol;
  vol.kind = "cloud";
  vol.density = DenseGrid(n, n, n);
  const uint64_t shape_key = stream(seed, 1), detail_key = stream(seed, 2);
  for_cells(n, [&](int i, int j, int k, const Vec3& p) {
    // Noise-displaced radius (+-0.1) gives billowy edges; zero beyond radius 0.95.
    const double r = length(p) + 0.2 * (fbm(shape_key, p * 1.5) - 0.5);
    const double falloff = 1 - smoothstep(0.5, 0.85, r);
    const double d = 1.8 * falloff * fbm(detail_key, p * 3 + Vec3(4.1)) - 0.2;
    vol.density.at(i, j, k) = static_cast<float>(std::clamp(d, 0.0, 1.0));
  });
  vol.density.update_range();
  return vol;
}

GeneratedVolume make_tissue(int n, uint64_t seed) {
  constexpr float kEtaTissue = 1.37f, kEtaInclusion = 1.45f;
  GeneratedVolume vol;
  vol.kind = "tissue";
  vol.density = DenseGrid(n, n, n);
  vol.albedo = DenseGrid(n, n, n);
  vol.eta = DenseGrid(n, n, n);
  vol.eta_background = kEtaTissue;
  const uint64_t dkey = stream(seed, 3), akey = stream(seed, 4);
  const Vec3 centre(0, 0.25, 0);
  for_cells(n, [&](int i, int j, int k, const Vec3& p) {
    const bool inclusion = length(p - centre) < 0.35;
    const double d = 1 + 0.2 * (fbm(dkey, p * 4) - 0.5);
    vol.density.at(i, j, k) = static_cast<float>(inclusion ? 3 * d : d);
    vol.albedo.at(i, j, k) = static_cast<float>(0.9 + 0.06 * (fbm(akey, p * 4) - 0.5));
    vol.eta.at(i, j, k) = inclusion ? kEtaInclusion : kEtaTissue;
  });
  vol.density.update_range();
  vol.albedo.update_range();
  vol.eta.update_range();
  return vol;
}

void write_generated(const std::string& path, const GeneratedVolume& vol, double voxel_mm) {
  const Vec3 origin(-0.5 * voxel_mm * vol.density.nx, -0.5 * voxel_mm * vol.density.ny,
                    -0.5 * voxel_mm * vol.density.nz);
  const auto spec = [&](const char* name, const DenseGrid& g, float background,
                        VdbGridSpec::Class cls) {
    VdbGridSpec s;
    s.name = name;
    s.values = &g;
    s.background = background;
    s.grid_class = cls;
    s.voxel_mm = Vec3(voxel_mm);
    s.origin_mm = origin;
    return s;
  };
  std::vector<VdbGridSpec> grids{spec("density", vol.density, 0.0f, VdbGridSpec::Class::FogVolume)};
  if (!vol.albedo.empty())
    grids.push_back(spec("albedo", vol.albedo, 0.0f, VdbGridSpec::Class::Unknown));
  if (!vol.eta.empty())
    grids.push_back(spec("eta", vol.eta, vol.eta_background, VdbGridSpec::Class::Unknown));
  write_vdb(path, grids);
}

}  // namespace femto
