#include "core/io/tone_mapping.h"

#include <algorithm>
#include <cmath>

#include "core/io/tonemap.h"

namespace femto {

const char* tone_map_name(ToneMapMode mode) {
  switch (mode) {
    case ToneMapMode::PerFrame:
      return "per-frame";
    case ToneMapMode::Log:
      return "log";
    default:
      return "global";
  }
}

bool parse_tone_map(const std::string& name, ToneMapMode& mode) {
  if (name == "global")
    mode = ToneMapMode::Global;
  else if (name == "per-frame")
    mode = ToneMapMode::PerFrame;
  else if (name == "log")
    mode = ToneMapMode::Log;
  else
    return false;
  return true;
}

double auto_scale(const float* rgb, size_t pixels, double exposure_stops) {
  return auto_exposure(rgb, pixels) * std::exp2(exposure_stops);  // exp2(0) == 1: today's bits
}

double log_display_luminance(double L, double scale, double decades) {
  if (!(L > 0)) return 0;  // also NaN
  const double d = 1 + std::log10(L * scale) / decades;
  return std::clamp(d, 0.0, 1.0);
}

std::vector<uint8_t> tone_map_rgb8(const float* rgb, size_t pixels, const ToneCurve& curve) {
  if (!curve.log) return tonemap_srgb8(rgb, pixels, curve.scale);
  // The pixel's colour scaled to its display luminance: hue kept, channels clamped by the encoder.
  std::vector<float> display(pixels * 3);
  for (size_t i = 0; i < pixels; ++i) {
    const float* p = rgb + 3 * i;
    const double L = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
    const double d = log_display_luminance(L, curve.scale, curve.decades);
    const double k = d > 0 ? d / L : 0;
    for (int c = 0; c < 3; ++c)
      display[3 * i + static_cast<size_t>(c)] = static_cast<float>(p[c] * k);
  }
  return tonemap_srgb8(display.data(), pixels, 1.0);
}

}  // namespace femto
