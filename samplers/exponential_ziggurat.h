#pragma once
// Unit-mean exponential variates by the ziggurat method (Marsaglia & Tsang 2000): the area under
// exp(-x) is covered by 256 layers of equal area, and a draw that lands inside a layer's part
// under the curve (about 99% of draws) costs a table lookup and a comparison: no logarithm. The
// rest take the exact wedge test or the exact tail, so the variates are exponential to the
// resolution of the uniforms (2^-53 of a layer's width). For the photon walks, where
// -log(1 - u) was about a twentieth of a step's instructions.
#include <cmath>
#include <cstdint>

#include "core/rng.h"

namespace femto {

class ExpZiggurat {
 public:
  static constexpr int kLayers = 256;

  /// The tables, computed once.
  static const ExpZiggurat& get() {
    static const ExpZiggurat z;
    return z;
  }

  /// One unit-mean exponential variate: 64 random bits in the common case (8 choose the layer,
  /// 53 the position in it).
  double sample(Rng& rng) const {
    while (true) {
      const uint64_t hi = rng.next_u32();  // the high half first (operands of | are unordered)
      const uint64_t bits = (hi << 32) | rng.next_u32();
      const int i = static_cast<int>(bits & 0xff);
      const double x = static_cast<double>(bits >> 11) * width_[i];  // u in [0, 1) times width
      if (x < x_[i + 1]) return x;  // under the curve: the rectangle left of the next edge
      if (i == 0) return r_ - std::log(1 - rng.uniform());  // the tail: memoryless beyond r
      // The wedge between the layer's rectangle and the curve: exact test.
      if (f_[i] + rng.uniform() * (f_[i + 1] - f_[i]) < std::exp(-x)) return x;
    }
  }

  /// Layer edges (tests): x(0) is the base layer's width A / exp(-r), x(1) = r, x(256) = 0.
  double edge(int i) const { return x_[i]; }
  /// exp(-edge(i)) for i >= 1 (tests).
  double height(int i) const { return f_[i]; }
  /// The area of each layer (tests).
  double area() const { return area_; }

 private:
  ExpZiggurat() {
    // r and the common area A for 256 layers (Marsaglia & Tsang 2000): with them the recursion
    // exp(-x_{i+1}) = exp(-x_i) + A / x_i ends at x_256 = 0 (the top of the curve).
    r_ = 7.69711747013104972;
    area_ = 3.949659822581572e-3;
    x_[0] = area_ / std::exp(-r_);  // r + 1: the base rectangle plus the tail's area beyond r
    x_[1] = r_;
    f_[0] = f_[1] = std::exp(-r_);
    for (int i = 1; i < kLayers - 1; ++i) {
      f_[i + 1] = f_[i] + area_ / x_[i];
      x_[i + 1] = -std::log(f_[i + 1]);
    }
    x_[kLayers] = 0;
    f_[kLayers] = 1;
    for (int i = 0; i < kLayers; ++i) width_[i] = x_[i] * 0x1p-53;
  }

  double r_ = 0, area_ = 0;
  double x_[kLayers + 1] = {};  // layer i spans [0, x_i] x [f_i, f_{i+1}]
  double f_[kLayers + 1] = {};  // exp(-x_i)
  double width_[kLayers] = {};  // x_i / 2^53: a 53-bit integer times it is u x_i
};

/// A unit-mean exponential variate (the optical depth to the next event of a photon walk).
inline double sample_unit_exponential(Rng& rng) {
  return ExpZiggurat::get().sample(rng);
}

}  // namespace femto
