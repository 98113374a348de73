// Tests of the transient video (core/io/video.h, femto render --video): the MP4 decodes (checked
// with ffprobe / ffmpeg, installed with FFmpeg) with the right codec, size, frame count and
// pictures, for both backends; failures are clear and leave nothing behind.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/io/sha256.h"
#include "core/io/video.h"
#include "run_femto.h"
#include "temp_dir.h"

namespace fs = std::filesystem;
using namespace femto;
using nlohmann::json;

namespace {

// stdout of a shell command (stderr discarded).
std::string capture(const std::string& cmd) {
  std::string out;
  if (FILE* p = ::popen((cmd + " 2>/dev/null").c_str(), "r")) {
    char buf[4096];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
    ::pclose(p);
  }
  return out;
}

// codec,width,height,pix_fmt,frame rate,decoded frame count of the first video stream.
std::string probe(const fs::path& mp4) {
  std::string s = capture(
      "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
      "stream=codec_name,width,height,pix_fmt,r_frame_rate,nb_read_frames -of csv=p=0 " +
      test::quote(mp4.string()));
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
  return s;
}

// All frames decoded to RGB24.
std::string decode_rgb(const fs::path& mp4) {
  return capture("ffmpeg -v error -i " + test::quote(mp4.string()) +
                 " -f rawvideo -pix_fmt rgb24 -");
}

// Frame i: a horizontal grey ramp on a colour that changes by 30 levels from frame to frame, so
// swapped, dropped or mis-converted frames show (constant chroma within a frame keeps 4:2:0
// subsampling exact).
void ramp_frame(int i, int w, int h, std::vector<uint8_t>& rgb) {
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t* p = &rgb[(static_cast<size_t>(y) * w + static_cast<size_t>(x)) * 3];
      p[0] = static_cast<uint8_t>(30 + 30 * i + x);
      p[1] = static_cast<uint8_t>(20 + x);
      p[2] = static_cast<uint8_t>(180 - 30 * i + x);
    }
}

std::vector<std::string> leftovers(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  return names;
}

std::vector<VideoBackend> backends() {
  std::vector<VideoBackend> b = {VideoBackend::Program};
  if (video_libraries_built_in()) b.insert(b.begin(), VideoBackend::Libraries);
  return b;
}

}  // namespace

// Catches: wrong codec or pixel format, odd sizes not padded, missing or extra frames, wrong
// frame rate, frames out of order or with wrong colours (RGB to YCbCr conversion), for both
// the FFmpeg libraries and the ffmpeg program.
TEST_CASE("write_mp4_h264 writes an H.264 MP4 that decodes to the frames given", "[video]") {
  REQUIRE_FALSE(capture("ffprobe -version").empty());  // CI installs ffmpeg (scripts/quickstart.sh)
  for (VideoBackend backend : backends()) {
    INFO(video_backend_name(backend));
    test::TempDir tmp("femto_test_video");
    const fs::path mp4 = tmp.dir / "clip.mp4";
    VideoSpec spec;
    spec.width = 33;  // odd: padded to 34 x 18
    spec.height = 17;
    spec.fps = 10;
    const int frames = 5;
    const std::string encoder = write_mp4_h264(
        mp4.string(), spec, frames,
        [&](int i, std::vector<uint8_t>& rgb) { ramp_frame(i, 33, 17, rgb); }, backend);
    CHECK(encoder == "libx264");
    CHECK(probe(mp4) == "h264,34,18,yuv420p,10/1,5");
    CHECK(leftovers(tmp.dir) == std::vector<std::string>{"clip.mp4"});

    const std::string raw = decode_rgb(mp4);
    REQUIRE(raw.size() == static_cast<size_t>(frames) * 34 * 18 * 3);
    std::vector<uint8_t> want(33 * 17 * 3);
    for (int i = 0; i < frames; ++i) {
      ramp_frame(i, 33, 17, want);
      // Mean absolute error over the frame (padding excluded): limited-range rounding and CRF 18
      // cost 0.7-1.5 levels here; a neighbouring frame differs by 20, and encoding with
      // swscale's default BT.601 matrix while tagging BT.709 gave 4.6-8.3 in an earlier version.
      double err = 0;
      for (int y = 0; y < 17; ++y)
        for (int x = 0; x < 33; ++x)
          for (int c = 0; c < 3; ++c) {
            const auto got = static_cast<unsigned char>(
                raw[((static_cast<size_t>(i) * 18 + y) * 34 + x) * 3 + c]);
            err += std::abs(got - want[(static_cast<size_t>(y) * 33 + x) * 3 + c]);
          }
      err /= 33 * 17 * 3;
      INFO("frame " << i);
      CHECK(err < 2.5);
    }
  }
}

// Catches: a missing encoder found only after a long render, a non-H.264 encoder accepted, and
// failed writes that leave a partial or temporary file behind.
TEST_CASE("video failures are clear and leave nothing behind", "[video]") {
  if (video_libraries_built_in()) {
    REQUIRE(check_h264_encoder("", VideoBackend::Libraries) == "libx264");
    try {
      check_h264_encoder("no-such-encoder", VideoBackend::Libraries);
      FAIL("accepted");
    } catch (const InputError& e) {
      CHECK(std::string(e.what()).find("--video-encoder no-such-encoder: no such FFmpeg encoder") !=
            std::string::npos);
    }
    try {
      check_h264_encoder("mpeg4", VideoBackend::Libraries);
      FAIL("accepted");
    } catch (const InputError& e) {
      CHECK(std::string(e.what()).find("not an H.264 encoder") != std::string::npos);
    }
  }
  {
    // No ffmpeg program (PATH without it): the program backend says so before anything is written.
    const std::string path = std::getenv("PATH") ? std::getenv("PATH") : "";
    ::setenv("PATH", "/nonexistent", 1);
    CHECK_THROWS_WITH(check_h264_encoder("", VideoBackend::Program),
                      Catch::Contains("no `ffmpeg` program on PATH; install ffmpeg"));
    ::setenv("PATH", path.c_str(), 1);
  }
  for (VideoBackend backend : backends()) {
    INFO(video_backend_name(backend));
    test::TempDir tmp("femto_test_video");
    VideoSpec spec;
    spec.width = 16;
    spec.height = 16;
    // A folder that does not exist: a RuntimeError naming the file.
    const std::string missing = (tmp.dir / "no" / "clip.mp4").string();
    try {
      write_mp4_h264(
          missing, spec, 3, [](int, std::vector<uint8_t>&) {}, backend);
      FAIL("no error");
    } catch (const RuntimeError& e) {
      CHECK(std::string(e.what()).find(missing) != std::string::npos);
    }
    // Failing half way through (the frame source throws at frame 3 of 6): nothing left.
    const std::string path = (tmp.dir / "clip.mp4").string();
    REQUIRE_THROWS_WITH(write_mp4_h264(
                            path, spec, 6,
                            [](int i, std::vector<uint8_t>& rgb) {
                              if (i == 3) throw RuntimeError("frame source failed");
                              std::fill(rgb.begin(), rgb.end(), uint8_t(90));
                            },
                            backend),
                        "frame source failed");
    CHECK(leftovers(tmp.dir).empty());
    // An encoder of another codec is refused, not used.
    CHECK(check_h264_encoder("", backend) == "libx264");
    spec.encoder = "mpeg4";
    CHECK_THROWS_WITH(write_mp4_h264(
                          path, spec, 2, [](int, std::vector<uint8_t>&) {}, backend),
                      Catch::Contains("--video-encoder mpeg4: not an H.264 encoder"));
    CHECK(leftovers(tmp.dir).empty());
    // An encoder the backend does not have.
    spec.encoder = "no-such-encoder";
    CHECK_THROWS(write_mp4_h264(
        path, spec, 2, [](int, std::vector<uint8_t>&) {}, backend));
    CHECK(leftovers(tmp.dir).empty());
  }
}

namespace {
// A tiny scene: 30 x 17 pixels (odd height), 14 bins.
const char* kScene = R"({
  "camera": { "type": "perspective", "position": [0, 0, 100], "look_at": [0, 0, 0],
              "fov": 40, "resolution": [30, 17] },
  "time": { "t_start": 250, "bin_width": 40, "bins": 14, "mode": "camera" },
  "media": { "fog": { "type": "homogeneous", "sigma_a": 0.001, "sigma_s": 0.01, "g": 0.3, "eta": 1.0 } },
  "medium": "fog",
  "shapes": [ { "type": "quad", "corner": [-60, -60, 0], "edge1": [120, 0, 0], "edge2": [0, 120, 0],
                "material": { "type": "diffuse", "albedo": 0.7 } } ],
  "lights": [ { "type": "point", "position": [10, 20, 50], "intensity": 1000 } ],
  "render": { "spp": 2, "max_depth": 20, "seed": 1 }
})";
}  // namespace

// Catches: --video not producing the file, one frame per bin, the enlargement and even padding,
// the listing with SHA-256 in render.json, and the tone-mapping record.
TEST_CASE("femto render --video writes transient.mp4 listed in render.json", "[video][cli]") {
  test::TempDir tmp("femto_test_video_cli");
  test::write_file(tmp.dir / "scene.json", kScene);
  const test::Run r =
      test::run_femto({"render", "scene.json", "--video", "--video-fps", "12", "--tonemap",
                       "per-frame", "--frames", "none", "--out", "out", "--quiet"},
                      tmp.dir);
  INFO(r.err);
  REQUIRE(r.code == 0);
  const fs::path out = tmp.dir / "out";
  // 30 x 17 enlarged 8x (longer side 240 -> >= 512 needs 18x, capped at 8) = 240 x 136.
  CHECK(probe(out / "transient.mp4") == "h264,240,136,yuv420p,12/1,14");
  const json info = json::parse(test::read_file(out / "render.json"));
  CHECK(info["video"]["frames"] == 14);
  CHECK(info["video"]["fps"] == 12);
  CHECK(info["video"]["upscale"] == 8);
  CHECK(info["tone_mapping"]["mode"] == "per-frame");
  CHECK(info["tone_mapping"]["white_radiance"].size() == 14);
  bool listed = false;
  for (const auto& f : info["files"])
    if (f["name"] == "transient.mp4") {
      listed = true;
      CHECK(f["sha256"] == sha256_file((out / "transient.mp4").string()));
    }
  CHECK(listed);
  CHECK(fs::exists(out / "peak_time.png"));

  // The same render again: the video has the same bytes (single-threaded encoding, fixed
  // settings), with another thread count for the render.
  const test::Run again = test::run_femto(
      {"render", "scene.json", "--video", "--video-fps", "12", "--tonemap", "per-frame", "--frames",
       "none", "--out", "out2", "--quiet", "--threads", "1"},
      tmp.dir);
  REQUIRE(again.code == 0);
  CHECK(test::read_file(tmp.dir / "out2" / "transient.mp4") ==
        test::read_file(out / "transient.mp4"));
}

// Catches: video and tone-mapping flag mistakes accepted, or found after rendering with the
// output folder already replaced.
TEST_CASE("bad video and tone-mapping flags are exit-2 errors before anything is written",
          "[video][cli]") {
  test::TempDir tmp("femto_test_video_cli");
  test::write_file(tmp.dir / "scene.json", kScene);
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const std::vector<Case> cases = {
      {{"--video", "--video-encoder", "no-such-encoder"},
       "--video-encoder no-such-encoder: no such FFmpeg encoder"},
      {{"--video-fps", "12"}, "--video-fps: applies to the video only; add --video"},
      {{"--video", "--video-fps", "0"}, "--video-fps"},
      {{"--tonemap", "loud"}, "--tonemap: expected global, per-frame or log (got 'loud')"},
      {{"--log-decades", "3"}, "--log-decades: applies to --tonemap log only"},
      {{"--tonemap", "log", "--log-decades", "50"},
       "--log-decades: expected 0.5..12 or auto (got '50')"},
      {{"--tonemap", "log", "--no-previews"}, "--no-previews is given without --video"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args = {"render", "scene.json", "--out", "out", "--quiet"};
    args.insert(args.end(), c.args.begin(), c.args.end());
    const test::Run r = test::run_femto(args, tmp.dir);
    INFO(r.err);
    CHECK(r.code == 2);
    CHECK(r.err.find(c.message) != std::string::npos);
    CHECK_FALSE(fs::exists(tmp.dir / "out"));
  }
}
