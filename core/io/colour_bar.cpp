#include "core/io/colour_bar.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/io/font.h"

namespace femto {

Rgb8 viridis(double f) {
  static const uint8_t kPoints[9][3] = {{68, 1, 84},    {72, 40, 120},  {62, 74, 137},
                                        {49, 104, 142}, {38, 130, 142}, {31, 158, 137},
                                        {53, 183, 121}, {109, 205, 89}, {253, 231, 37}};
  if (!(f > 0)) f = 0;  // also NaN
  if (f > 1) f = 1;
  const double s = f * 8;
  const int i = std::min(7, static_cast<int>(s));
  const double w = s - i;
  auto lerp = [&](int c) {
    return static_cast<uint8_t>(std::lround((1 - w) * kPoints[i][c] + w * kPoints[i + 1][c]));
  };
  return Rgb8{lerp(0), lerp(1), lerp(2)};
}

ColourBarPicture false_colour_with_bar(const float* values, int width, int height, double lo,
                                       double hi, const std::string& title) {
  if (width <= 0 || height <= 0 || !values || !std::isfinite(lo) || !std::isfinite(hi) ||
      !(lo < hi))
    throw RuntimeError("colour bar: empty image or bad range [" + std::to_string(lo) + ", " +
                       std::to_string(hi) + "]");
  const int k = std::clamp((256 + std::max(width, height) - 1) / std::max(width, height), 1, 8);
  const int text_scale = k * height >= 200 ? 2 : 1;
  const int margin = 10, gap = 12, bar_w = 20, tick = 4;
  const AxisTicks ticks = axis_ticks(lo, hi, false, 6);
  int label_w = 0;
  for (const auto& l : ticks.labels) label_w = std::max(label_w, font::text_width(l, text_scale));
  const int title_h = font::kGlyphH * text_scale;

  ColourBarPicture p;
  p.image_x = margin;
  p.image_y = margin;
  p.image_scale = k;
  p.bar_x0 = margin + k * width + gap;
  p.bar_x1 = p.bar_x0 + bar_w;
  p.bar_y0 = margin;
  p.bar_y1 = margin + k * height;
  const int label_x = p.bar_x1 + tick + 3;
  const int title_x = label_x + label_w + 8;
  p.canvas = Canvas(title_x + title_h + margin, k * height + 2 * margin);
  Canvas& c = p.canvas;

  const double range = hi - lo;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const float v = values[static_cast<size_t>(y) * width + static_cast<size_t>(x)];
      const Rgb8 col = std::isnan(v) ? Rgb8{0, 0, 0} : viridis((v - lo) / range);
      for (int sy = 0; sy < k; ++sy)
        for (int sx = 0; sx < k; ++sx) c.set(p.image_x + x * k + sx, p.image_y + y * k + sy, col);
    }
  const int bar_h = p.bar_y1 - p.bar_y0;
  for (int r = 0; r < bar_h; ++r) {
    const Rgb8 col = viridis(1 - (r + 0.5) / bar_h);
    for (int x = p.bar_x0; x < p.bar_x1; ++x) c.set(x, p.bar_y0 + r, col);
  }
  const Rgb8 ink{20, 20, 20};
  const uint8_t ink_rgb[3] = {ink.r, ink.g, ink.b};
  for (size_t i = 0; i < ticks.at.size(); ++i) {
    // Row of value v: the centre of the bar row whose fraction is nearest.
    const double f = (ticks.at[i] - lo) / range;
    const int y =
        p.bar_y0 + std::clamp(static_cast<int>(std::floor((1 - f) * bar_h)), 0, bar_h - 1);
    for (int x = p.bar_x1; x < p.bar_x1 + tick; ++x) c.set(x, y, ink);
    font::draw_text(c.rgb.data(), c.width, c.height, label_x, y - title_h / 2, ticks.labels[i],
                    text_scale, ink_rgb);
  }
  const int title_len = font::text_width(title, text_scale);
  font::draw_text(c.rgb.data(), c.width, c.height, title_x, p.bar_y0 + (bar_h + title_len) / 2,
                  title, text_scale, ink_rgb, true);
  return p;
}

}  // namespace femto
