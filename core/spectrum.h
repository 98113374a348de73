#pragma once
// RGB radiometric quantity (radiance, throughput, albedo).
#include <algorithm>
#include <cmath>

namespace femto {

struct RGB {
  double r = 0, g = 0, b = 0;
  constexpr RGB() = default;
  constexpr RGB(double r_, double g_, double b_) : r(r_), g(g_), b(b_) {}
  constexpr explicit RGB(double v) : r(v), g(v), b(v) {}
  constexpr double operator[](int i) const { return i == 0 ? r : (i == 1 ? g : b); }
  constexpr RGB operator+(const RGB& o) const { return {r + o.r, g + o.g, b + o.b}; }
  constexpr RGB operator-(const RGB& o) const { return {r - o.r, g - o.g, b - o.b}; }
  constexpr RGB operator*(const RGB& o) const { return {r * o.r, g * o.g, b * o.b}; }
  constexpr RGB operator*(double s) const { return {r * s, g * s, b * s}; }
  constexpr RGB operator/(double s) const { return {r / s, g / s, b / s}; }
  RGB& operator+=(const RGB& o) { r += o.r; g += o.g; b += o.b; return *this; }
  RGB& operator*=(const RGB& o) { r *= o.r; g *= o.g; b *= o.b; return *this; }
  RGB& operator*=(double s) { r *= s; g *= s; b *= s; return *this; }
  bool is_black() const { return r == 0 && g == 0 && b == 0; }
  double max_component() const { return std::max({r, g, b}); }
  double average() const { return (r + g + b) / 3.0; }
  bool is_finite() const { return std::isfinite(r) && std::isfinite(g) && std::isfinite(b); }
  /// Rec. 709 luminance.
  double luminance() const { return 0.2126 * r + 0.7152 * g + 0.0722 * b; }
};

constexpr RGB operator*(double s, const RGB& c) { return c * s; }

}  // namespace femto
