#pragma once
// Small line plots rendered to RGB8 images (PNG via core/io/png.h): axes with numeric tick
// labels, optional log-scaled y axis, several coloured series (lines, dashed lines or markers),
// a legend and a title, all drawn with the built-in 5x7 font (core/io/font.h).
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace femto {

struct Rgb8 {
  uint8_t r = 0, g = 0, b = 0;
};

struct PlotSeries {
  enum class Style { Line, Dashed, Markers };
  std::string label;  ///< legend entry; empty keeps the series out of the legend
  std::vector<double> x,
      y;  ///< same length; a non-finite point (or y <= 0 on a log axis) breaks the line
  Rgb8 color;
  Style style = Style::Line;
};

struct Plot {
  enum class Legend { TopRight, TopLeft, BottomRight, BottomLeft };
  std::string title, x_label, y_label;
  bool log_y = false;
  /// Axis ranges; NaN = from the data (a log axis is widened to whole decades).
  double x_min = NAN, x_max = NAN, y_min = NAN, y_max = NAN;
  std::vector<PlotSeries> series;
  Legend legend = Legend::TopRight;
};

/// An RGB8 image, row-major, top row first, initially white.
struct Canvas {
  int width, height;
  std::vector<uint8_t> rgb;
  Canvas(int w, int h);
  void set(int x, int y, Rgb8 c);  ///< ignores pixels outside the image
};

/// Draws `plot` into the rectangle [x0, x0 + w) x [y0, y0 + h) of the canvas; text is drawn at
/// `text_scale` times the 5x7 font. Series are clipped to the axes.
void draw_plot(Canvas& canvas, int x0, int y0, int w, int h, const Plot& plot, int text_scale = 2);

/// Writes the canvas as an sRGB PNG (atomic replace). Throws RuntimeError naming path.
void write_canvas_png(const std::string& path, const Canvas& canvas);

/// Tick positions and labels of an axis over [lo, hi] (decades when log, then lo/hi are log10).
struct AxisTicks {
  std::vector<double> at;
  std::vector<std::string> labels;
};
AxisTicks axis_ticks(double lo, double hi, bool log, int target = 6);

}  // namespace femto
