#include "core/io/plot.h"

#include <algorithm>
#include <cstdio>

#include "core/io/font.h"
#include "core/io/png.h"

namespace femto {

Canvas::Canvas(int w, int h)
    : width(w),
      height(h),
      rgb(static_cast<size_t>(std::max(w, 0)) * static_cast<size_t>(std::max(h, 0)) * 3, 255) {}

void Canvas::set(int x, int y, Rgb8 c) {
  if (x < 0 || y < 0 || x >= width || y >= height) return;
  uint8_t* p =
      &rgb[(static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)) * 3];
  p[0] = c.r, p[1] = c.g, p[2] = c.b;
}

void write_canvas_png(const std::string& path, const Canvas& canvas) {
  write_png_rgb8(path, canvas.width, canvas.height, canvas.rgb.data());
}

namespace {

// Shortest decimal for a tick value on a grid of spacing `step` ("0.25", "40", "1e-5").
std::string format_tick(double v, double step) {
  char buf[32];
  if (std::abs(v) < 1e-9 * step) v = 0;  // -0 and rounding residue at zero
  const double mag = std::abs(v);
  if (mag != 0 && (mag >= 1e5 || mag < 1e-3)) {
    const int e = static_cast<int>(std::floor(std::log10(mag)));
    const double m = v / std::pow(10.0, e);
    std::snprintf(buf, sizeof buf, std::abs(m - std::round(m)) < 1e-6 ? "%.0fe%d" : "%.1fe%d", m,
                  e);
    return buf;
  }
  const int decimals = std::max(0, -static_cast<int>(std::floor(std::log10(step) + 1e-9)));
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

std::string format_decade(int e) {
  if (e >= -2 && e <= 3) return format_tick(std::pow(10.0, e), std::pow(10.0, e));
  return "1e" + std::to_string(e);
}

}  // namespace

AxisTicks axis_ticks(double lo, double hi, bool log, int target) {
  AxisTicks t;
  if (!(hi > lo)) return t;
  if (log) {
    const int first = static_cast<int>(std::ceil(lo - 1e-9)),
              last = static_cast<int>(std::floor(hi + 1e-9));
    const int every =
        std::max(1, (last - first + target) / std::max(target, 1));  // thin out many decades
    for (int e = first; e <= last; ++e)
      if ((e - first) % every == 0) {
        t.at.push_back(e);
        t.labels.push_back(format_decade(e));
      }
    return t;
  }
  const double raw = (hi - lo) / std::max(target, 1);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double norm = raw / mag;
  const double step = (norm < 1.5 ? 1 : norm < 3 ? 2 : norm < 7 ? 5 : 10) * mag;
  for (double k = std::ceil(lo / step - 1e-9); k * step <= hi + 1e-9 * step; k += 1) {
    t.at.push_back(k * step);
    t.labels.push_back(format_tick(k * step, step));
  }
  return t;
}

namespace {

constexpr Rgb8 kAxis{60, 60, 60}, kGrid{225, 225, 225}, kText{20, 20, 20};

void fill_rect(Canvas& c, int x0, int y0, int x1, int y1, Rgb8 col) {
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) c.set(x, y, col);
}

void text(Canvas& c, int x, int y, const std::string& s, int scale, Rgb8 col,
          bool vertical = false) {
  const uint8_t rgb[3] = {col.r, col.g, col.b};
  font::draw_text(c.rgb.data(), c.width, c.height, x, y, s, scale, rgb, vertical);
}

struct Rect {
  int x0, y0, x1, y1;  // half-open pixel rectangle
};

// Liang–Barsky: clips the segment (a, b) to the box; false when nothing is left.
bool clip_segment(double& ax, double& ay, double& bx, double& by, double x0, double y0, double x1,
                  double y1) {
  double t0 = 0, t1 = 1;
  const double dx = bx - ax, dy = by - ay;
  const double p[4] = {-dx, dx, -dy, dy}, q[4] = {ax - x0, x1 - ax, ay - y0, y1 - ay};
  for (int i = 0; i < 4; ++i) {
    if (p[i] == 0) {
      if (q[i] < 0) return false;
      continue;
    }
    const double r = q[i] / p[i];
    if (p[i] < 0)
      t0 = std::max(t0, r);
    else
      t1 = std::min(t1, r);
  }
  if (t0 > t1) return false;
  bx = ax + t1 * dx, by = ay + t1 * dy;
  ax = ax + t0 * dx, ay = ay + t0 * dy;
  return true;
}

// A square brush of `width` pixels stepped along the segment; `dash` (pixels on, then off)
// continues across segments through `run`, the length drawn so far.
void draw_segment(Canvas& c, const Rect& box, double ax, double ay, double bx, double by, int width,
                  Rgb8 col, int dash, double& run) {
  const double len = std::hypot(bx - ax, by - ay);
  if (!clip_segment(ax, ay, bx, by, box.x0, box.y0, box.x1 - 1, box.y1 - 1)) {
    run += len;
    return;
  }
  const int steps =
      std::max(1, static_cast<int>(std::ceil(std::max(std::abs(bx - ax), std::abs(by - ay)))));
  const double seg = std::hypot(bx - ax, by - ay);
  for (int i = 0; i <= steps; ++i) {
    const double f = static_cast<double>(i) / steps;
    if (dash > 0 && std::fmod(run + f * seg, 2.0 * dash) >= dash) continue;
    const int px = static_cast<int>(std::lround(ax + f * (bx - ax))) - width / 2;
    const int py = static_cast<int>(std::lround(ay + f * (by - ay))) - width / 2;
    for (int y = py; y < py + width; ++y)
      for (int x = px; x < px + width; ++x)
        if (x >= box.x0 && x < box.x1 && y >= box.y0 && y < box.y1) c.set(x, y, col);
  }
  run += len;
}

void draw_marker(Canvas& c, const Rect& box, double x, double y, int r, Rgb8 col) {
  const int cx = static_cast<int>(std::lround(x)), cy = static_cast<int>(std::lround(y));
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx)
      if (dx * dx + dy * dy <= r * r + r && cx + dx >= box.x0 && cx + dx < box.x1 &&
          cy + dy >= box.y0 && cy + dy < box.y1)
        c.set(cx + dx, cy + dy, col);
}

bool usable(double x, double y, bool log_y) {
  return std::isfinite(x) && std::isfinite(y) && (!log_y || y > 0);
}

}  // namespace

void draw_plot(Canvas& canvas, int x0, int y0, int w, int h, const Plot& plot, int s) {
  s = std::max(1, s);
  fill_rect(canvas, x0, y0, x0 + w, y0 + h, Rgb8{255, 255, 255});

  // Data ranges (log axis in decades).
  double xmin = plot.x_min, xmax = plot.x_max, ymin = plot.y_min, ymax = plot.y_max;
  double dxmin = INFINITY, dxmax = -INFINITY, dymin = INFINITY, dymax = -INFINITY;
  for (const auto& se : plot.series)
    for (size_t i = 0; i < std::min(se.x.size(), se.y.size()); ++i)
      if (usable(se.x[i], se.y[i], plot.log_y)) {
        dxmin = std::min(dxmin, se.x[i]), dxmax = std::max(dxmax, se.x[i]);
        dymin = std::min(dymin, se.y[i]), dymax = std::max(dymax, se.y[i]);
      }
  if (!std::isfinite(xmin)) xmin = std::isfinite(dxmin) ? dxmin : 0;
  if (!std::isfinite(xmax)) xmax = std::isfinite(dxmax) ? dxmax : 1;
  if (!(xmax > xmin)) xmax = xmin + 1;
  double fy0, fy1;  // axis range in plotted units
  if (plot.log_y) {
    fy0 = std::isfinite(ymin) && ymin > 0
              ? std::log10(ymin)
              : std::floor(std::isfinite(dymin) ? std::log10(dymin) : -1);
    fy1 = std::isfinite(ymax) && ymax > 0 ? std::log10(ymax)
                                          : std::ceil(std::isfinite(dymax) ? std::log10(dymax) : 0);
  } else {
    const double pad = 0.05 * (dymax - dymin);
    fy0 = std::isfinite(ymin) ? ymin : (std::isfinite(dymin) ? dymin - pad : 0);
    fy1 = std::isfinite(ymax) ? ymax : (std::isfinite(dymax) ? dymax + pad : 1);
  }
  if (!(fy1 > fy0)) fy1 = fy0 + 1;

  const AxisTicks xt = axis_ticks(xmin, xmax, false), yt = axis_ticks(fy0, fy1, plot.log_y);
  const int gh = font::kGlyphH * s, gap = 3 * s;
  int ylab_w = 0;
  for (const auto& l : yt.labels) ylab_w = std::max(ylab_w, font::text_width(l, s));
  const Rect box{x0 + gap + (plot.y_label.empty() ? 0 : gh + 2 * gap) + ylab_w + gap + 2 * s,
                 y0 + (plot.title.empty() ? gap : gh + 3 * gap), x0 + w - 4 * gap,
                 y0 + h - (gh + 2 * gap) - (plot.x_label.empty() ? 0 : gh + gap) - gap};
  if (box.x1 - box.x0 < 10 || box.y1 - box.y0 < 10) return;
  const double bw = box.x1 - 1 - box.x0, bh = box.y1 - 1 - box.y0;
  auto X = [&](double x) { return box.x0 + (x - xmin) / (xmax - xmin) * bw; };
  auto Y = [&](double fy) { return box.y1 - 1 - (fy - fy0) / (fy1 - fy0) * bh; };

  // Grid, ticks and labels.
  for (size_t i = 0; i < xt.at.size(); ++i) {
    const int px = static_cast<int>(std::lround(X(xt.at[i])));
    fill_rect(canvas, px, box.y0, px + 1, box.y1, kGrid);
    fill_rect(canvas, px, box.y1, px + 1, box.y1 + 2 * s, kAxis);
    text(canvas, px - font::text_width(xt.labels[i], s) / 2, box.y1 + 2 * s + gap, xt.labels[i], s,
         kText);
  }
  for (size_t i = 0; i < yt.at.size(); ++i) {
    const int py = static_cast<int>(std::lround(Y(yt.at[i])));
    fill_rect(canvas, box.x0, py, box.x1, py + 1, kGrid);
    fill_rect(canvas, box.x0 - 2 * s, py, box.x0, py + 1, kAxis);
    text(canvas, box.x0 - 2 * s - gap - font::text_width(yt.labels[i], s), py - gh / 2,
         yt.labels[i], s, kText);
  }
  fill_rect(canvas, box.x0, box.y0, box.x1, box.y0 + 1, kAxis);
  fill_rect(canvas, box.x0, box.y1 - 1, box.x1, box.y1, kAxis);
  fill_rect(canvas, box.x0, box.y0, box.x0 + 1, box.y1, kAxis);
  fill_rect(canvas, box.x1 - 1, box.y0, box.x1, box.y1, kAxis);
  if (!plot.title.empty())
    text(canvas, (box.x0 + box.x1 - font::text_width(plot.title, s)) / 2, y0 + gap, plot.title, s,
         kText);
  if (!plot.x_label.empty())
    text(canvas, (box.x0 + box.x1 - font::text_width(plot.x_label, s)) / 2,
         box.y1 + 2 * s + 2 * gap + gh, plot.x_label, s, kText);
  if (!plot.y_label.empty())
    text(canvas, x0 + gap, (box.y0 + box.y1 + font::text_width(plot.y_label, s)) / 2, plot.y_label,
         s, kText, true);

  // Series, in order (later ones on top).
  const int line_w = std::max(1, s), marker_r = s + 1;
  for (const auto& se : plot.series) {
    const size_t n = std::min(se.x.size(), se.y.size());
    double run = 0;
    bool have_prev = false;
    double px = 0, py = 0;
    for (size_t i = 0; i < n; ++i) {
      if (!usable(se.x[i], se.y[i], plot.log_y)) {
        have_prev = false;
        continue;
      }
      const double cx = X(se.x[i]), cy = Y(plot.log_y ? std::log10(se.y[i]) : se.y[i]);
      if (se.style == PlotSeries::Style::Markers)
        draw_marker(canvas, box, cx, cy, marker_r, se.color);
      else if (have_prev)
        draw_segment(canvas, box, px, py, cx, cy, line_w, se.color,
                     se.style == PlotSeries::Style::Dashed ? 5 * s : 0, run);
      px = cx, py = cy, have_prev = true;
    }
  }

  // Legend box in the chosen corner.
  std::vector<const PlotSeries*> entries;
  int label_w = 0;
  for (const auto& se : plot.series)
    if (!se.label.empty()) {
      entries.push_back(&se);
      label_w = std::max(label_w, font::text_width(se.label, s));
    }
  if (entries.empty()) return;
  const int sample_w = 8 * gap, row_h = gh + gap;
  const int lw = gap + sample_w + gap + label_w + gap,
            lh = gap + static_cast<int>(entries.size()) * row_h;
  const bool right =
      plot.legend == Plot::Legend::TopRight || plot.legend == Plot::Legend::BottomRight;
  const bool top = plot.legend == Plot::Legend::TopRight || plot.legend == Plot::Legend::TopLeft;
  const int lx = right ? box.x1 - 2 * gap - lw : box.x0 + 2 * gap;
  const int ly = top ? box.y0 + 2 * gap : box.y1 - 2 * gap - lh;
  fill_rect(canvas, lx, ly, lx + lw, ly + lh, Rgb8{255, 255, 255});
  fill_rect(canvas, lx, ly, lx + lw, ly + 1, kAxis);
  fill_rect(canvas, lx, ly + lh - 1, lx + lw, ly + lh, kAxis);
  fill_rect(canvas, lx, ly, lx + 1, ly + lh, kAxis);
  fill_rect(canvas, lx + lw - 1, ly, lx + lw, ly + lh, kAxis);
  const Rect all{0, 0, canvas.width, canvas.height};
  for (size_t i = 0; i < entries.size(); ++i) {
    const PlotSeries& se = *entries[i];
    const int ry = ly + gap + static_cast<int>(i) * row_h, cy = ry + gh / 2;
    if (se.style == PlotSeries::Style::Markers) {
      draw_marker(canvas, all, lx + gap + sample_w / 2, cy, marker_r, se.color);
    } else {
      double run = 0;
      draw_segment(canvas, all, lx + gap, cy, lx + gap + sample_w, cy, line_w, se.color,
                   se.style == PlotSeries::Style::Dashed ? 5 * s : 0, run);
    }
    text(canvas, lx + 2 * gap + sample_w, ry, se.label, s, kText);
  }
}

}  // namespace femto
