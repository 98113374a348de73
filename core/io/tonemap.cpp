#include "core/io/tonemap.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/io/font.h"

namespace femto {
namespace {

uint8_t encode_srgb8(double linear) {
  if (!(linear > 0)) return 0;  // also catches NaN
  if (linear >= 1) return 255;
  const double v = linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1 / 2.4) - 0.055;
  return static_cast<uint8_t>(std::lround(v * 255));
}

double luminance(const float* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

// Collects finite, positive luminances (the pixels auto exposure looks at).
void add_luminance(std::vector<double>& lum, const float* p) {
  const double l = luminance(p);
  if (l > 0 && std::isfinite(l)) lum.push_back(l);
}

// Scale putting the 99th percentile at 0.9 (reorders lum).
double exposure_for(std::vector<double>& lum) {
  if (lum.empty()) return 1.0;
  const auto k = static_cast<size_t>(0.99 * static_cast<double>(lum.size() - 1));
  std::nth_element(lum.begin(), lum.begin() + static_cast<std::ptrdiff_t>(k), lum.end());
  return 0.9 / lum[k];
}

// Draws text (lines separated by '\n') at (x0,y0) on a dark box, clipped to the rectangle
// [0,clip_w) x [0,clip_h) offset by (ox,oy) in an image of row length `stride` pixels.
void draw_label(std::vector<uint8_t>& img, int stride, int ox, int oy, int clip_w, int clip_h,
                const std::string& text, int scale) {
  using font::kAdvance, font::kGlyphH, font::kGlyphW;
  std::vector<std::string> lines(1);
  for (char ch : text) {
    if (ch == '\n') lines.emplace_back();
    else lines.back() += ch;
  }
  size_t longest = 0;
  for (const auto& l : lines) longest = std::max(longest, l.size());
  const int line_h = (kGlyphH + 2) * scale;
  const int pad = scale, x0 = 2 * scale, y0 = 2 * scale;
  const int box_w = static_cast<int>(longest) * kAdvance * scale - scale + 2 * pad;
  const int box_h = kGlyphH * scale + 2 * pad + static_cast<int>(lines.size() - 1) * line_h;
  auto put = [&](int x, int y, uint8_t v) {
    if (x < 0 || y < 0 || x >= clip_w || y >= clip_h) return;
    uint8_t* p = &img[(static_cast<size_t>(oy + y) * stride + static_cast<size_t>(ox + x)) * 3];
    p[0] = p[1] = p[2] = v;
  };
  for (int y = 0; y < box_h; ++y)
    for (int x = 0; x < box_w; ++x) put(x0 - pad + x, y0 - pad + y, 0);
  for (size_t li = 0; li < lines.size(); ++li) {
    const std::string& line = lines[li];
    const int ly = y0 + static_cast<int>(li) * line_h;
    for (size_t i = 0; i < line.size(); ++i) {
      const uint8_t* rows = font::glyph_rows(line[i]);
      const int gx = x0 + static_cast<int>(i) * kAdvance * scale;
      for (int r = 0; r < kGlyphH; ++r)
        for (int c = 0; c < kGlyphW; ++c)
          if (rows[r] & (0x10 >> c))
            for (int sy = 0; sy < scale; ++sy)
              for (int sx = 0; sx < scale; ++sx) put(gx + c * scale + sx, ly + r * scale + sy, 255);
    }
  }
}

}  // namespace

std::vector<uint8_t> tonemap_srgb8(const float* rgb, size_t pixels, double exposure_scale) {
  std::vector<uint8_t> out(pixels * 3);
  for (size_t i = 0; i < pixels * 3; ++i) out[i] = encode_srgb8(rgb[i] * exposure_scale);
  return out;
}

double auto_exposure(const float* rgb, size_t pixels) {
  std::vector<double> lum;
  for (size_t i = 0; i < pixels; ++i) add_luminance(lum, rgb + 3 * i);
  return exposure_for(lum);
}

std::vector<uint8_t> contact_sheet_rgb8(int width, int height, int bins, const float* hwtc,
                                        const std::vector<int>& frame_indices,
                                        const std::vector<std::string>& labels, int columns,
                                        double exposure_scale, int& sheet_width, int& sheet_height) {
  const int n = static_cast<int>(frame_indices.size());
  if (width <= 0 || height <= 0 || bins <= 0 || !hwtc || n == 0)
    throw RuntimeError("contact sheet: empty film or no frames selected");
  for (int t : frame_indices)
    if (t < 0 || t >= bins)
      throw RuntimeError("contact sheet: frame " + std::to_string(t) + " outside [0, " +
                         std::to_string(bins) + ")");
  const size_t pixels = static_cast<size_t>(width) * static_cast<size_t>(height);
  const auto bins_z = static_cast<size_t>(bins);
  auto pixel = [&](size_t p, int t) { return hwtc + (p * bins_z + static_cast<size_t>(t)) * 3; };

  if (!(exposure_scale > 0)) {  // one exposure for all frames keeps their brightness comparable
    std::vector<double> lum;
    for (int t : frame_indices)
      for (size_t p = 0; p < pixels; ++p) add_luminance(lum, pixel(p, t));
    exposure_scale = exposure_for(lum);
  }

  std::vector<std::vector<uint8_t>> tiles;
  std::vector<float> frame(pixels * 3);
  for (int t : frame_indices) {
    for (size_t p = 0; p < pixels; ++p) std::copy_n(pixel(p, t), 3, &frame[3 * p]);
    tiles.push_back(tonemap_srgb8(frame.data(), pixels, exposure_scale));
  }
  return tile_sheet_rgb8(width, height, tiles, labels, columns, sheet_width, sheet_height);
}

std::vector<uint8_t> tile_sheet_rgb8(int width, int height,
                                     const std::vector<std::vector<uint8_t>>& tiles,
                                     const std::vector<std::string>& labels, int columns,
                                     int& sheet_width, int& sheet_height) {
  const int n = static_cast<int>(tiles.size());
  const size_t tile_bytes = static_cast<size_t>(width) * static_cast<size_t>(height) * 3;
  if (width <= 0 || height <= 0 || n == 0) throw RuntimeError("contact sheet: no frames to tile");
  for (const auto& tile : tiles)
    if (tile.size() != tile_bytes) throw RuntimeError("contact sheet: a tile has the wrong size");
  const int cols = columns > 0 ? std::min(columns, n)
                               : static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n))));
  const int rows = (n + cols - 1) / cols;
  const int gap = 4;
  sheet_width = cols * width + (cols + 1) * gap;
  sheet_height = rows * height + (rows + 1) * gap;
  // Dark grey (not black) gap, so tile edges stay visible against black renders.
  std::vector<uint8_t> sheet(static_cast<size_t>(sheet_width) * static_cast<size_t>(sheet_height) * 3,
                             40);
  const int scale = (width >= 256 && height >= 128) ? 2 : 1;

  for (int i = 0; i < n; ++i) {
    const int ox = gap + (i % cols) * (width + gap), oy = gap + (i / cols) * (height + gap);
    for (int y = 0; y < height; ++y)
      std::copy_n(&tiles[static_cast<size_t>(i)][static_cast<size_t>(y) * width * 3],
                  static_cast<size_t>(width) * 3,
                  &sheet[(static_cast<size_t>(oy + y) * sheet_width + static_cast<size_t>(ox)) * 3]);
    if (static_cast<size_t>(i) < labels.size() && !labels[i].empty())
      draw_label(sheet, sheet_width, ox, oy, width, height, labels[i], scale);
  }
  return sheet;
}

void draw_stamp(std::vector<uint8_t>& rgb8, int width, int height, const std::string& text, int scale) {
  draw_label(rgb8, width, 0, 0, width, height, text, scale);
}

}  // namespace femto
