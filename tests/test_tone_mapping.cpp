// Tests of the pictures' tone mapping (core/io/tone_mapping.h, core/previews.h) and of the
// false-colour peak-time picture with its colour bar (core/io/colour_bar.h).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/film.h"
#include "core/io/colour_bar.h"
#include "core/io/png.h"
#include "core/io/tone_mapping.h"
#include "core/io/tonemap.h"
#include "core/previews.h"
#include "temp_dir.h"

using namespace femto;

namespace {

std::string slurp_image_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// A film whose pixel (x, y) in bin t holds rgb * (x + 1) * (y + 2) * decay^t: every frame has a
// spread of values, and each bin is `decay` times the one before.
TransientFilm decaying_film(int W, int H, int T, double decay, RGB rgb = RGB(0.3, 0.5, 0.2)) {
  TimeAxis axis;
  axis.t_start_ps = 10;
  axis.bin_width_ps = 2.5;
  axis.bins = T;
  TransientFilm film(W, H, axis);
  std::vector<double> bins(static_cast<size_t>(T) * 3);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      for (int t = 0; t < T; ++t)
        for (int c = 0; c < 3; ++c)
          bins[static_cast<size_t>(t) * 3 + static_cast<size_t>(c)] =
              rgb[c] * (x + 1) * (y + 2) * std::pow(decay, t);
      film.set_pixel(x, y, bins.data(), RGB(0.0), RGB(0.0), 1);
    }
  return film;
}

double lum(const float* p) {
  return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
}

// The 99th percentile of positive luminance, computed here independently of core/io/tonemap.cpp.
double p99_luminance(const std::vector<float>& rgb) {
  std::vector<double> l;
  for (size_t i = 0; i < rgb.size() / 3; ++i)
    if (lum(&rgb[3 * i]) > 0) l.push_back(lum(&rgb[3 * i]));
  std::sort(l.begin(), l.end());
  return l[static_cast<size_t>(0.99 * static_cast<double>(l.size() - 1))];
}

}  // namespace

// Catches: any change of the default contact sheet. frames.png with the default settings must
// keep the bytes femto wrote before tone-mapping options existed; the reference here is that
// code (16 evenly spread bins, one auto exposure over them, "t=%.1fps" labels, contact_sheet_rgb8).
TEST_CASE("global tone mapping reproduces the previous contact sheet bit for bit", "[tonemap]") {
  test::TempDir tmp("femto_test_tonemap");
  const TransientFilm film = decaying_film(37, 21, 40, 0.8);
  const int T = film.bins(), n = std::min(T, 16);
  std::vector<int> idx;
  std::vector<std::string> labels;
  std::vector<float> chosen;
  for (int k = 0; k < n; ++k) {
    const int t = static_cast<int>(std::lround(static_cast<double>(k) * (T - 1) / (n - 1)));
    idx.push_back(t);
    char buf[48];
    std::snprintf(buf, sizeof buf, "t=%.1fps", film.axis().bin_start_ps(t));
    labels.emplace_back(buf);
    const std::vector<float> f = film.frame(t);
    chosen.insert(chosen.end(), f.begin(), f.end());
  }
  const double exposure = auto_exposure(chosen.data(), chosen.size() / 3);
  int sw = 0, sh = 0;
  const std::vector<uint8_t> sheet = contact_sheet_rgb8(
      film.width(), film.height(), T, film.transient(), idx, labels, 4, exposure, sw, sh);
  const std::string before = (tmp.dir / "before.png").string(),
                    now = (tmp.dir / "now.png").string();
  write_png_rgb8(before, sw, sh, sheet.data());

  const ToneMapSettings global;  // the default
  const std::vector<ToneCurve> curves = frame_tone_curves(film, global);
  write_contact_sheet(now, film, global, curves);
  REQUIRE(slurp_image_file(before) == slurp_image_file(now));
  // And one linear curve maps exactly like tonemap_srgb8 with its scale.
  const std::vector<float> f = film.frame(7);
  REQUIRE(tone_map_rgb8(f.data(), f.size() / 3, curves[7]) ==
          tonemap_srgb8(f.data(), f.size() / 3, exposure));
}

// Catches: a per-frame exposure that is not normalised to the frame itself (a shared scale, the
// wrong percentile, the exposure change applied the wrong way).
TEST_CASE("per-frame normalisation puts each frame's reference luminance at the white point",
          "[tonemap]") {
  const TransientFilm film = decaying_film(30, 20, 12, 0.1);  // ten decades over the window
  for (double stops : {0.0, 1.5, -2.0}) {
    ToneMapSettings s;
    s.mode = ToneMapMode::PerFrame;
    s.exposure_stops = stops;
    const std::vector<ToneCurve> curves = frame_tone_curves(film, s);
    REQUIRE(curves.size() == 12);
    for (int t = 0; t < 12; ++t) {
      const std::vector<float> f = film.frame(t);
      INFO("bin " << t << ", stops " << stops);
      CHECK_FALSE(curves[static_cast<size_t>(t)].log);
      // The 99th-percentile luminance of the frame is shown at 0.9 * 2^stops of white.
      CHECK(p99_luminance(f) * curves[static_cast<size_t>(t)].scale ==
            Approx(0.9 * std::exp2(stops)).epsilon(1e-9));
    }
  }
  // render.json lists the white of every bin, so the frames stay interpretable.
  ToneMapSettings s;
  s.mode = ToneMapMode::PerFrame;
  const auto curves = frame_tone_curves(film, s);
  const nlohmann::json j = tone_mapping_json(s, curves);
  REQUIRE(j["white_radiance"].size() == 12);
  CHECK(j["white_radiance"][5].get<double>() == Approx(1 / curves[5].scale));
  // ... and so does each frame's stamp.
  char expected[32];
  std::snprintf(expected, sizeof expected, "white=%.2e", 1 / curves[5].scale);
  CHECK(frame_stamp(film.axis(), 5, s, curves[5]).find(expected) != std::string::npos);
}

// Catches: a log curve that is not monotone, has the wrong end points or slope, or changes hue.
TEST_CASE("the log curve is monotone, spans its decades and keeps the colour", "[tonemap]") {
  const double scale = 250, decades = 5;  // white = 0.004
  CHECK(log_display_luminance(0.004, scale, decades) == Approx(1));
  CHECK(log_display_luminance(0.0004, scale, decades) == Approx(0.8));  // one decade of five lower
  CHECK(log_display_luminance(0.004e-5, scale, decades) == 0);
  CHECK(log_display_luminance(1.0, scale, decades) == 1);  // above white: clamped
  CHECK(log_display_luminance(0, scale, decades) == 0);
  CHECK(log_display_luminance(NAN, scale, decades) == 0);
  double previous = -1;
  for (double e = -12; e <= 2; e += 0.01) {
    const double d = log_display_luminance(std::pow(10.0, e) * 0.004, scale, decades);
    REQUIRE(d >= previous);
    previous = d;
  }
  // Grey pixels over eight decades: the 8-bit values never decrease; those within the range
  // are not black.
  std::vector<float> grey;
  for (int i = 0; i <= 80; ++i) {
    const float v = static_cast<float>(0.004 * std::pow(10.0, -i / 10.0));
    grey.insert(grey.end(), {v, v, v});
  }
  ToneCurve curve;
  curve.log = true;
  curve.scale = scale;
  curve.decades = decades;
  const std::vector<uint8_t> out = tone_map_rgb8(grey.data(), grey.size() / 3, curve);
  for (size_t i = 1; i < out.size() / 3; ++i) REQUIRE(out[3 * i] <= out[3 * (i - 1)]);
  CHECK(out[0] == 255);
  CHECK(out[3 * 45] > 0);   // 4.5 decades below white
  CHECK(out[3 * 55] == 0);  // 5.5 decades below
  // A coloured pixel keeps its channel ratios (below clipping, before the sRGB encoding).
  const float c[3] = {0.0004f, 0.0002f, 0.0001f};
  const std::vector<uint8_t> col = tone_map_rgb8(c, 1, curve);
  CHECK(col[0] > col[1]);
  CHECK(col[1] > col[2]);
}

// Catches: an automatic log range that leaves late frames black (the problem it solves).
TEST_CASE("automatic log decades reach the dimmest lit frame", "[tonemap]") {
  const TransientFilm film = decaying_film(24, 16, 10, 0.01);  // 18 decades: clamped to 12
  ToneMapSettings s;
  s.mode = ToneMapMode::Log;
  const std::vector<ToneCurve> clamped = frame_tone_curves(film, s);
  CHECK(clamped[0].decades == 12);
  const TransientFilm film2 = decaying_film(24, 16, 10, 0.3);
  const std::vector<ToneCurve> curves = frame_tone_curves(film2, s);
  const size_t pixels = 24 * 16;
  // From white down to the last frame's own automatic white, plus one decade.
  const std::vector<float> last = film2.frame(9);
  const double expected = std::log10(auto_scale(last.data(), pixels, 0) / curves[0].scale) + 1;
  CHECK(curves[9].decades == Approx(expected));
  CHECK(expected > 2);
  // The last frame's bright pixels are visible, not black.
  const std::vector<uint8_t> img = tone_map_rgb8(last.data(), pixels, curves[9]);
  CHECK(*std::max_element(img.begin(), img.end()) > 40);
  // The global curve of the same film shows the last frame black: the contrast to the log curve.
  const std::vector<ToneCurve> global = frame_tone_curves(film2, ToneMapSettings{});
  const std::vector<uint8_t> dark = tone_map_rgb8(last.data(), pixels, global[9]);
  CHECK(*std::max_element(dark.begin(), dark.end()) < 10);
}

TEST_CASE("tone map names parse and print", "[tonemap]") {
  for (ToneMapMode m : {ToneMapMode::Global, ToneMapMode::PerFrame, ToneMapMode::Log}) {
    ToneMapMode back = ToneMapMode::Global;
    REQUIRE(parse_tone_map(tone_map_name(m), back));
    CHECK(back == m);
  }
  ToneMapMode m = ToneMapMode::Log;
  CHECK_FALSE(parse_tone_map("perframe", m));
}

// Catches: a colour bar or image that does not follow the colour map, or a reversed bar.
TEST_CASE("the colour bar and the false-colour image follow viridis", "[tonemap][colour-bar]") {
  CHECK(viridis(0).r == 68);
  CHECK(viridis(0).b == 84);
  CHECK(viridis(1).r == 253);
  CHECK(viridis(1).g == 231);
  CHECK(viridis(-3).g == viridis(0).g);
  CHECK(viridis(NAN).g == viridis(0).g);
  // Half way between two control points: their average.
  const Rgb8 a = viridis(3.0 / 8), b = viridis(4.0 / 8), mid = viridis(3.5 / 8);
  CHECK(std::abs(mid.g - (a.g + b.g) / 2.0) <= 0.5);
  // Green rises over the map (a reversed or scrambled table would fail).
  for (int i = 1; i <= 100; ++i) REQUIRE(viridis(i / 100.0).g >= viridis((i - 1) / 100.0).g);

  const int W = 40, H = 12;
  std::vector<float> v(static_cast<size_t>(W * H));
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) v[static_cast<size_t>(y * W + x)] = static_cast<float>(100 + 5 * x);
  v[0] = NAN;
  const ColourBarPicture p = false_colour_with_bar(v.data(), W, H, 100, 295, "peak time (ps)");
  REQUIRE(p.image_scale == 7);  // 40 * 7 = 280 >= 256
  const Canvas& c = p.canvas;
  auto at = [&](int x, int y) {
    const uint8_t* q = &c.rgb[(static_cast<size_t>(y) * c.width + static_cast<size_t>(x)) * 3];
    return Rgb8{q[0], q[1], q[2]};
  };
  auto same = [](Rgb8 u, Rgb8 w) { return u.r == w.r && u.g == w.g && u.b == w.b; };
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const int k = p.image_scale;
      const Rgb8 want = (x == 0 && y == 0) ? Rgb8{0, 0, 0} : viridis((5.0 * x) / 195);
      REQUIRE(same(at(p.image_x + x * k + k / 2, p.image_y + y * k + k / 2), want));
    }
  const int bar_h = p.bar_y1 - p.bar_y0;
  REQUIRE(bar_h == H * p.image_scale);
  for (int r = 0; r < bar_h; ++r) {
    const Rgb8 want = viridis(1 - (r + 0.5) / bar_h);
    for (int x = p.bar_x0; x < p.bar_x1; ++x) REQUIRE(same(at(x, p.bar_y0 + r), want));
  }
  // Tick labels are drawn right of the bar (dark text on white).
  int ink = 0;
  for (int y = p.bar_y0; y < p.bar_y1; ++y)
    for (int x = p.bar_x1; x < c.width; ++x) ink += at(x, y).r < 100;
  CHECK(ink > 100);
  REQUIRE_THROWS_AS(false_colour_with_bar(v.data(), W, H, 5, 5, "t"), RuntimeError);
  REQUIRE_THROWS_AS(false_colour_with_bar(v.data(), W, H, 0, NAN, "t"), RuntimeError);
}
