#include "core/outputs.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/io/atomic_file.h"
#include "core/io/exr.h"
#include "core/io/npy.h"
#include "core/io/png.h"
#include "core/io/sha256.h"
#include "core/memory_usage.h"
#include "core/previews.h"
#include "core/io/tonemap.h"

namespace femto {

namespace fs = std::filesystem;

std::string frame_file_name(const TimeAxis& axis, int t) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "frames/frame_%04d_%.3fps.exr", t, axis.bin_start_ps(t));
  return buf;
}

std::vector<std::string> write_outputs(const TransientFilm& film, const OutputOptions& opt, nlohmann::json info,
                   const std::vector<float>& bandwidth_ps) {
  const fs::path dir(opt.dir);
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {  // normally the staging folder (core/output_folder.h), made before rendering
    fs::create_directories(dir, ec);
    if (ec) throw RuntimeError(opt.dir + ": cannot create the output folder: " + ec.message());
  }
  const int W = film.width(), H = film.height(), T = film.bins();
  const TimeAxis& axis = film.axis();
  const std::vector<std::pair<std::string, std::string>> attrs = {
      {"femto:units", "bin-integrated radiance (sum over bins = steady image)"},
      {"femto:time_axis", "t_start_ps=" + std::to_string(axis.t_start_ps) +
                              " bin_width_ps=" + std::to_string(axis.bin_width_ps) +
                              " bins=" + std::to_string(T)}};
  nlohmann::json files = nlohmann::json::array();
  auto path_of = [&](const std::string& name) { return (dir / name).string(); };
  // The render's threads write the frames and hash the files.
  tbb::task_arena arena(opt.threads > 0 ? opt.threads : tbb::task_arena::automatic);

  write_exr_rgb(path_of("steady.exr"), W, H, film.steady(), attrs);
  files.push_back("steady.exr");
  write_exr_rgb(path_of("before_window.exr"), W, H, film.before(), attrs);
  files.push_back("before_window.exr");
  write_exr_rgb(path_of("after_window.exr"), W, H, film.after(), attrs);
  files.push_back("after_window.exr");
  const std::vector<float> peak = film.peak_time();
  write_exr_channels(path_of("peak_time.exr"), W, H, {"Y"}, {peak.data()},
                     {{"femto:units", "ps (centre of the brightest bin; NaN where empty)"}});
  files.push_back("peak_time.exr");
  if (!bandwidth_ps.empty()) {
    write_exr_channels(path_of("kernel_bandwidth.exr"), W, H, {"Y"}, {bandwidth_ps.data()},
                       {{"femto:units", "ps (temporal kernel bandwidth of each pixel's last sample)"}});
    files.push_back("kernel_bandwidth.exr");
  }

  if (opt.frames == OutputOptions::Frames::Files) {
    fs::create_directory(dir / "frames", ec);  // not recursive: never recreates a removed staging folder
    if (ec) throw RuntimeError((dir / "frames").string() + ": cannot create folder: " + ec.message());
    // Frames are independent files: compressing them one after another took about a third of
    // the time spent writing a default render's outputs.
    arena.execute([&] {
      tbb::parallel_for(0, T, [&](int t) {
        const std::vector<float> f = film.frame(t);
        write_exr_rgb(path_of(frame_file_name(axis, t)), W, H, f.data(), attrs);
      });
    });
    files.push_back("frames/");
  } else if (opt.frames == OutputOptions::Frames::Multipart) {
    std::vector<std::string> names;
    for (int t = 0; t < T; ++t) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "t%04d_%.3fps", t, axis.bin_start_ps(t));
      names.emplace_back(buf);
    }
    write_exr_multipart_rgb(path_of("transient.exr"), W, H, T, names, film.transient(), attrs);
    files.push_back("transient.exr");
  }

  write_npy_float32(path_of("transient.npy"),
                    {static_cast<size_t>(H), static_cast<size_t>(W), static_cast<size_t>(T), 3},
                    film.transient());
  files.push_back("transient.npy");

  std::vector<ToneCurve> curves;
  if (opt.previews || opt.video) {
    curves = frame_tone_curves(film, opt.tonemap);
    info["tone_mapping"] = tone_mapping_json(opt.tonemap, curves);
  }
  if (opt.previews) {
    const size_t pixels = static_cast<size_t>(W) * static_cast<size_t>(H);
    const double exposure = auto_exposure(film.steady(), pixels);
    const std::vector<uint8_t> img = tonemap_srgb8(film.steady(), pixels, exposure);
    write_png_rgb8(path_of("steady.png"), W, H, img.data());
    files.push_back("steady.png");
    // Contact sheet: up to 16 frames evenly over the window (core/previews.h).
    write_contact_sheet(path_of("frames.png"), film, opt.tonemap, curves);
    files.push_back("frames.png");
    info["peak_time_png"] = write_peak_time_png(path_of("peak_time.png"), film);
    files.push_back("peak_time.png");
  }
  if (opt.video) {
    info["video"] = write_transient_video(path_of("transient.mp4"), film, opt.tonemap, curves, opt.video_spec,
                                          opt.video_backend);
    files.push_back("transient.mp4");
  }
  files.push_back("render.json");
  info["outputs"] = files;
  // Every file with its size and SHA-256 (render.json itself excepted), frames one by one. The
  // files are hashed in parallel: one thread hashing a default render's outputs took 6% of a
  // 16-pass hybrid render.
  std::vector<std::string> names;
  for (const auto& f : files) {
    const std::string name = f.get<std::string>();
    if (name == "render.json") continue;
    if (name == "frames/") {
      for (int t = 0; t < T; ++t) names.push_back(frame_file_name(axis, t));
    } else {
      names.push_back(name);
    }
  }
  std::vector<std::string> digests(names.size());
  arena.execute([&] {
    tbb::parallel_for(size_t{0}, names.size(),
                      [&](size_t i) { digests[i] = sha256_file(path_of(names[i])); });
  });
  nlohmann::json listing = nlohmann::json::array();
  for (size_t i = 0; i < names.size(); ++i)
    listing.push_back(
        {{"name", names[i]}, {"bytes", fs::file_size(path_of(names[i]))}, {"sha256", digests[i]}});
  info["files"] = listing;
  if (info.contains("memory") && info["memory"].is_object()) info["memory"]["peak_rss_bytes"] = peak_rss_bytes();
  write_text_atomically(path_of("render.json"), info.dump(2) + "\n");
  return files.get<std::vector<std::string>>();
}

}  // namespace femto
