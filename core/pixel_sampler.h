#pragma once
// Where in its pixel sample j of a pixel looks: the R2 low-discrepancy sequence (generalised
// golden ratio) with a random shift per (seed, pixel) (Cranley–Patterson rotation). Every sample
// is uniform over the pixel, so estimates stay unbiased, while a pixel's samples cover it evenly,
// which removes most of the noise from detail inside a pixel (a sharp caustic, an edge).
#include <cmath>
#include <cstdint>

#include "core/rng.h"

namespace femto {

inline void pixel_offset(uint64_t seed, uint64_t pixel, uint64_t sample, double& dx, double& dy) {
  constexpr double a1 = 0.7548776662466927;  // 1 / g, g = 1.32471795724474602596 (x^3 = x + 1)
  constexpr double a2 = 0.5698402909980532;  // 1 / g^2
  Rng shift = Rng::for_sample(seed ^ 0x9e3779b97f4a7c15ULL, pixel, 0x5049584c);  // "PIXL"
  const double s1 = shift.uniform(), s2 = shift.uniform();
  const auto j = static_cast<double>(sample);
  dx = s1 + j * a1;
  dy = s2 + j * a2;
  dx -= std::floor(dx);
  dy -= std::floor(dy);
}

}  // namespace femto
