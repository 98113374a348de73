#include "core/previews.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "core/io/colour_bar.h"
#include "core/io/png.h"
#include "core/io/tonemap.h"

namespace femto {

std::vector<int> contact_sheet_frames(int bins) {
  const int n = std::min(bins, 16);
  std::vector<int> idx;
  for (int k = 0; k < n; ++k)
    idx.push_back(
        n == 1 ? 0 : static_cast<int>(std::lround(static_cast<double>(k) * (bins - 1) / (n - 1))));
  return idx;
}

std::vector<ToneCurve> frame_tone_curves(const TransientFilm& film,
                                         const ToneMapSettings& settings) {
  const int T = film.bins();
  std::vector<ToneCurve> curves(static_cast<size_t>(T));
  const size_t pixels = static_cast<size_t>(film.width()) * static_cast<size_t>(film.height());
  if (settings.mode == ToneMapMode::PerFrame) {
    for (int t = 0; t < T; ++t) {
      const std::vector<float> f = film.frame(t);
      curves[static_cast<size_t>(t)].scale = auto_scale(f.data(), pixels, settings.exposure_stops);
    }
    return curves;
  }
  // One exposure from the contact sheet's frames together (as femto always chose it).
  std::vector<float> chosen;
  for (int t : contact_sheet_frames(T)) {
    const std::vector<float> f = film.frame(t);
    chosen.insert(chosen.end(), f.begin(), f.end());
  }
  const double scale = auto_scale(chosen.data(), chosen.size() / 3, settings.exposure_stops);
  double decades = settings.log_decades;
  if (settings.mode == ToneMapMode::Log && !(decades > 0)) {
    // Down to the dimmest lit bin's automatic white, so every frame with light shows.
    double dimmest_scale = scale;
    for (int t = 0; t < T; ++t) {
      const std::vector<float> f = film.frame(t);
      bool lit = false;
      for (size_t i = 0; i < pixels && !lit; ++i) {
        const double L = 0.2126 * f[3 * i] + 0.7152 * f[3 * i + 1] + 0.0722 * f[3 * i + 2];
        lit = L > 0 && std::isfinite(L);
      }
      if (lit)
        dimmest_scale =
            std::max(dimmest_scale, auto_scale(f.data(), pixels, settings.exposure_stops));
    }
    decades = std::clamp(std::log10(dimmest_scale / scale) + 1, 1.0, 12.0);
  }
  for (ToneCurve& c : curves) {
    c.scale = scale;
    c.log = settings.mode == ToneMapMode::Log;
    c.decades = decades;
  }
  return curves;
}

std::string frame_stamp(const TimeAxis& axis, int t, const ToneMapSettings& settings,
                        const ToneCurve& curve) {
  char buf[96];
  if (settings.mode == ToneMapMode::PerFrame)
    std::snprintf(buf, sizeof buf, "t=%.1fps\nwhite=%.2e", axis.bin_start_ps(t),
                  curve.white_radiance());
  else
    std::snprintf(buf, sizeof buf, "t=%.1fps", axis.bin_start_ps(t));
  return buf;
}

void write_contact_sheet(const std::string& path, const TransientFilm& film,
                         const ToneMapSettings& settings, const std::vector<ToneCurve>& curves) {
  const size_t pixels = static_cast<size_t>(film.width()) * static_cast<size_t>(film.height());
  std::vector<std::vector<uint8_t>> tiles;
  std::vector<std::string> labels;
  for (int t : contact_sheet_frames(film.bins())) {
    const ToneCurve& curve = curves[static_cast<size_t>(t)];
    const std::vector<float> f = film.frame(t);
    tiles.push_back(tone_map_rgb8(f.data(), pixels, curve));
    labels.push_back(frame_stamp(film.axis(), t, settings, curve));
  }
  int sw = 0, sh = 0;
  const std::vector<uint8_t> sheet =
      tile_sheet_rgb8(film.width(), film.height(), tiles, labels, 4, sw, sh);
  write_png_rgb8(path, sw, sh, sheet.data());
}

int video_upscale(int width, int height) {
  const int longer = std::max(width, height);
  return std::clamp((512 + longer - 1) / longer, 1, 8);
}

nlohmann::json write_transient_video(const std::string& path, const TransientFilm& film,
                                     const ToneMapSettings& settings,
                                     const std::vector<ToneCurve>& curves, const VideoSpec& spec_in,
                                     VideoBackend backend) {
  const int W = film.width(), H = film.height();
  const int k = video_upscale(W, H);
  VideoSpec spec = spec_in;
  spec.width = k * W;
  spec.height = k * H;
  const int stamp_scale = (spec.width >= 256 && spec.height >= 128) ? 2 : 1;
  const size_t pixels = static_cast<size_t>(W) * static_cast<size_t>(H);
  const std::string encoder = write_mp4_h264(
      path, spec, film.bins(),
      [&](int t, std::vector<uint8_t>& rgb) {
        const ToneCurve& curve = curves[static_cast<size_t>(t)];
        const std::vector<float> f = film.frame(t);
        const std::vector<uint8_t> small = tone_map_rgb8(f.data(), pixels, curve);
        for (int y = 0; y < spec.height; ++y)
          for (int x = 0; x < spec.width; ++x)
            std::copy_n(&small[(static_cast<size_t>(y / k) * W + static_cast<size_t>(x / k)) * 3],
                        3,
                        &rgb[(static_cast<size_t>(y) * spec.width + static_cast<size_t>(x)) * 3]);
        draw_stamp(rgb, spec.width, spec.height, frame_stamp(film.axis(), t, settings, curve),
                   stamp_scale);
      },
      backend);
  return {{"file", "transient.mp4"},
          {"codec", "h264"},
          {"encoder", encoder},
          {"backend", video_backend_name(backend)},
          {"pixel_format", "yuv420p"},
          {"fps", spec.fps},
          {"frames", film.bins()},
          {"frame", "one per time bin, stamped with the bin start time"},
          {"width", spec.width + (spec.width & 1)},
          {"height", spec.height + (spec.height & 1)},
          {"upscale", k}};
}

nlohmann::json write_peak_time_png(const std::string& path, const TransientFilm& film) {
  const std::vector<float> peak = film.peak_time();
  double lo = INFINITY, hi = -INFINITY;
  for (float v : peak)
    if (std::isfinite(v)) {
      lo = std::min(lo, static_cast<double>(v));
      hi = std::max(hi, static_cast<double>(v));
    }
  const TimeAxis& axis = film.axis();
  if (!(lo <= hi)) {  // no light anywhere
    lo = axis.t_start_ps;
    hi = axis.t_end_ps();
  } else if (!(lo < hi)) {  // one peak time everywhere: half a bin either side
    lo -= axis.bin_width_ps / 2;
    hi += axis.bin_width_ps / 2;
  }
  const ColourBarPicture p =
      false_colour_with_bar(peak.data(), film.width(), film.height(), lo, hi, "peak time (ps)");
  write_canvas_png(path, p.canvas);
  return {{"file", "peak_time.png"},
          {"colour_map", "viridis"},
          {"range_ps", {lo, hi}},
          {"no_light", "black"}};
}

nlohmann::json tone_mapping_json(const ToneMapSettings& settings,
                                 const std::vector<ToneCurve>& curves) {
  nlohmann::json j = {{"mode", tone_map_name(settings.mode)},
                      {"exposure_stops", settings.exposure_stops}};
  if (settings.mode == ToneMapMode::Log) {
    j["log_decades"] = curves.empty() ? settings.log_decades : curves.front().decades;
    j["log_decades_source"] = settings.log_decades > 0 ? "--log-decades" : "auto";
  }
  if (settings.mode == ToneMapMode::PerFrame) {
    nlohmann::json w = nlohmann::json::array();
    for (const ToneCurve& c : curves) w.push_back(c.white_radiance());
    j["white_radiance"] = w;
  } else if (!curves.empty()) {
    j["white_radiance"] = curves.front().white_radiance();
  }
  j["note"] =
      "white_radiance: the bin-integrated radiance shown at full scale (linear modes), or at "
      "the top of the log scale, which spans log_decades below it";
  return j;
}

}  // namespace femto
