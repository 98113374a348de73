#pragma once
// How transient frames become 8-bit pictures (contact sheet, video): one exposure for all frames,
// an exposure per frame, or a logarithmic curve, each described by the radiance shown as white.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace femto {

enum class ToneMapMode {
  Global,    ///< one exposure for every frame: brightness compares over time (the default)
  PerFrame,  ///< each frame exposed on its own: late, dim frames stay visible
  Log        ///< log10 of luminance over `log_decades` below white: all frames at once
};

struct ToneMapSettings {
  ToneMapMode mode = ToneMapMode::Global;
  double exposure_stops = 0;  ///< brightens by 2^stops from the automatic exposure
  /// Log: luminance range (decades) from white down to black; <= 0: automatic, one decade more
  /// than the frames' automatic exposures span (frame_tone_curves, core/previews.h)
  double log_decades = 0;
};

/// "global", "per-frame", "log".
const char* tone_map_name(ToneMapMode mode);
/// Parses a name of tone_map_name; false when unknown.
bool parse_tone_map(const std::string& name, ToneMapMode& mode);

/// The curve of one frame. `scale` multiplies bin-integrated radiance into display units, so
/// 1 / scale is the radiance shown as white. Linear (Global, PerFrame): radiance r shows as
/// sRGB(r * scale) per channel, clamped. Log: a pixel of luminance L keeps its colour, scaled to
/// display luminance clamp(1 + log10(L * scale) / decades, 0, 1).
struct ToneCurve {
  bool log = false;
  double scale = 1;
  double decades = 4;
  double white_radiance() const { return 1 / scale; }
};

/// The scale of the automatic exposure (core/io/tonemap.h, auto_exposure: the 99th percentile of
/// positive luminance shown at 0.9) of `pixels` RGB pixels, brightened by 2^exposure_stops.
double auto_scale(const float* rgb, size_t pixels, double exposure_stops);

/// Display luminance in [0, 1] of the log curve for luminance L (0 for L <= 0 or NaN).
double log_display_luminance(double L, double scale, double decades);

/// Maps `pixels` RGB pixels through `curve` to sRGB 8-bit. A linear curve gives the bytes of
/// tonemap_srgb8(rgb, pixels, curve.scale) (core/io/tonemap.h) bit for bit.
std::vector<uint8_t> tone_map_rgb8(const float* rgb, size_t pixels, const ToneCurve& curve);

}  // namespace femto
