// Tests for core/io: NPY, EXR, PNG writers, atomic replacement and tone mapping.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/io/atomic_file.h"
#include "core/io/exr.h"
#include "core/io/npy.h"
#include "core/io/png.h"
#include "core/io/tonemap.h"
#include "temp_dir.h"

namespace fs = std::filesystem;
using namespace femto;

namespace {

// A fresh directory per test case, removed afterwards, with path and leftover helpers.
struct IoDir : test::TempDir {
  IoDir() : test::TempDir("femto_test_io") {}
  std::string operator/(const std::string& name) const { return (dir / name).string(); }
  // Names of the leftover temporaries (".tmp.") in the directory.
  std::vector<std::string> temporaries() const {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(dir))
      if (e.path().filename().string().find(".tmp.") != std::string::npos)
        out.push_back(e.path().string());
    return out;
  }
};

std::string slurp_io_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

uint32_t be32(const std::string& s, size_t at) {
  uint32_t v = 0;
  for (size_t i = 0; i < 4; ++i) v = (v << 8) | static_cast<unsigned char>(s[at + i]);
  return v;
}

// Expects fn to throw RuntimeError whose message contains needle.
template <class Fn>
void require_runtime_error_naming(Fn&& fn, const std::string& needle) {
  try {
    fn();
    FAIL("no exception thrown");
  } catch (const RuntimeError& e) {
    INFO(e.what());
    REQUIRE(std::string(e.what()).find(needle) != std::string::npos);
  }
}

std::vector<float> ramp(size_t n, float scale) {
  std::vector<float> v(n);
  for (size_t i = 0; i < n; ++i) v[i] = scale * static_cast<float>(i) - 1.5f;
  return v;
}

}  // namespace

TEST_CASE("NPY float32 round trip and header layout", "[io][npy]") {
  IoDir tmp;
  const std::string path = tmp / "a.npy";
  const std::vector<size_t> shape{2, 3, 4};
  std::vector<float> data = ramp(24, 0.25f);
  data[5] = 1e-30f;
  data[7] = -3.4e38f;
  write_npy_float32(path, shape, data.data());

  const std::string bytes = slurp_io_file(path);
  REQUIRE(bytes.compare(0, 6, "\x93NUMPY") == 0);
  REQUIRE(bytes[6] == 1);
  REQUIRE(bytes[7] == 0);
  const size_t hlen = static_cast<unsigned char>(bytes[8]) | (static_cast<unsigned char>(bytes[9]) << 8);
  REQUIRE((10 + hlen) % 64 == 0);
  REQUIRE(bytes[10 + hlen - 1] == '\n');
  REQUIRE(bytes.find("'descr': '<f4'") != std::string::npos);
  REQUIRE(bytes.find("'shape': (2, 3, 4)") != std::string::npos);
  REQUIRE(bytes.size() == 10 + hlen + 24 * sizeof(float));
  REQUIRE(tmp.temporaries().empty());

  std::vector<size_t> shape2;
  std::vector<float> data2;
  read_npy_float32(path, shape2, data2);
  REQUIRE(shape2 == shape);
  REQUIRE(data2 == data);

  SECTION("1-d and 0-d shapes") {
    const float v[3] = {1, 2, 3};
    write_npy_float32(path, {3}, v);
    REQUIRE(slurp_io_file(path).find("'shape': (3,)") != std::string::npos);
    read_npy_float32(path, shape2, data2);
    REQUIRE(shape2 == std::vector<size_t>{3});
    REQUIRE(data2 == std::vector<float>{1, 2, 3});
    write_npy_float32(path, {}, v);
    read_npy_float32(path, shape2, data2);
    REQUIRE(shape2.empty());
    REQUIRE(data2 == std::vector<float>{1});
  }
  SECTION("a header over 64 KiB switches to version 2.0") {
    const std::vector<size_t> many(30000, 1);  // more dims than numpy allows, but valid NPY 2.0
    const float one = 42;
    write_npy_float32(path, many, &one);
    const std::string b = slurp_io_file(path);
    REQUIRE(b[6] == 2);
    const size_t len = be32(std::string{b[11], b[10], b[9], b[8]}, 0);  // little-endian uint32
    REQUIRE((12 + len) % 64 == 0);
    read_npy_float32(path, shape2, data2);
    REQUIRE(shape2 == many);
    REQUIRE(data2 == std::vector<float>{42});
  }
}

TEST_CASE("NPY reader rejects foreign files", "[io][npy]") {
  IoDir tmp;
  std::vector<size_t> shape;
  std::vector<float> data;
  const float v[2] = {1, 2};
  // Rewrites one header field of a valid file, keeping the header length.
  auto patched = [&](const std::string& from, const std::string& to) {
    write_npy_float32(tmp / "x.npy", {2}, v);
    std::string b = slurp_io_file(tmp / "x.npy");
    b.replace(b.find(from), from.size(), to);
    std::ofstream(tmp / "bad.npy", std::ios::binary) << b;
    return tmp / "bad.npy";
  };
  require_runtime_error_naming([&] { read_npy_float32(patched("'<f4'", "'<f8'"), shape, data); }, "bad.npy");
  require_runtime_error_naming([&] { read_npy_float32(patched("False", "True "), shape, data); }, "Fortran");
  require_runtime_error_naming([&] { read_npy_float32(patched("NUMPY", "NUMPX"), shape, data); }, "magic");
  require_runtime_error_naming([&] { read_npy_float32(patched("(2,)", "(3,)"), shape, data); }, "shape");
  require_runtime_error_naming([&] { read_npy_float32(tmp / "missing.npy", shape, data); }, "missing.npy");
}

TEST_CASE("NPY files load in numpy", "[io][npy][python]") {
  if (std::system("/usr/bin/python3 -c 'import numpy' >/dev/null 2>&1") != 0) {
    WARN("numpy not importable by /usr/bin/python3; skipping");
    return;
  }
  IoDir tmp;
  const std::string path = tmp / "n.npy", out = tmp / "n.txt";
  const std::vector<float> data = ramp(2 * 3 * 5, 0.5f);
  write_npy_float32(path, {2, 3, 5}, data.data());
  const std::string cmd = "/usr/bin/python3 -c \"import numpy,sys; a=numpy.load(sys.argv[1]); "
                          "print(a.shape, a.dtype, a.flags['C_CONTIGUOUS'], float(a[1,2,4]))\" '" +
                          path + "' > '" + out + "'";
  REQUIRE(std::system(cmd.c_str()) == 0);
  const std::string expected = "(2, 3, 5) float32 True " + std::to_string(data.back()).substr(0, 4);
  REQUIRE(slurp_io_file(out).substr(0, expected.size()) == expected);
}

TEST_CASE("EXR RGB round trip is exact and keeps attributes", "[io][exr]") {
  IoDir tmp;
  const std::string path = tmp / "img.exr";
  const int w = 5, h = 3;
  std::vector<float> rgb = ramp(size_t(w) * h * 3, 0.1f);
  rgb[0] = 1e-20f;
  rgb[4] = 6.5e37f;
  rgb[8] = std::numeric_limits<float>::denorm_min();
  write_exr_rgb(path, w, h, rgb.data(), {{"femto:scene", "cornell.json"}, {"femto:spp", "64"}});
  REQUIRE(tmp.temporaries().empty());

  int w2 = 0, h2 = 0;
  std::vector<float> back;
  read_exr_rgb(path, w2, h2, back);
  REQUIRE(w2 == w);
  REQUIRE(h2 == h);
  REQUIRE(back == rgb);
  REQUIRE(read_exr_string_attribute(path, "femto:scene") == std::optional<std::string>("cornell.json"));
  REQUIRE(read_exr_string_attribute(path, "femto:spp") == std::optional<std::string>("64"));
  REQUIRE_FALSE(read_exr_string_attribute(path, "femto:nothing").has_value());
  REQUIRE(exr_part_names(path).size() == 1);
}

TEST_CASE("EXR arbitrary channels", "[io][exr]") {
  IoDir tmp;
  const std::string path = tmp / "peak_time.exr";
  const int w = 4, h = 2;
  const std::vector<float> y = ramp(8, 12.5f), a = ramp(8, -1.0f);
  write_exr_channels(path, w, h, {"Y", "A"}, {y.data(), a.data()}, {{"units", "ps"}});
  int w2 = 0, h2 = 0;
  std::vector<float> plane;
  read_exr_channel(path, 0, "Y", w2, h2, plane);
  REQUIRE((w2 == w && h2 == h));
  REQUIRE(plane == y);
  read_exr_channel(path, 0, "A", w2, h2, plane);
  REQUIRE(plane == a);
  require_runtime_error_naming([&] { read_exr_channel(path, 0, "Z", w2, h2, plane); }, "Z");
  require_runtime_error_naming(
      [&] { write_exr_channels(path, w, h, {"Y"}, {y.data(), a.data()}); }, path);
}

TEST_CASE("multi-part EXR holds one part per time bin", "[io][exr]") {
  IoDir tmp;
  const std::string path = tmp / "frames.exr";
  const int w = 3, h = 2, t_bins = 4;
  const std::vector<float> hwtc = ramp(size_t(w) * h * t_bins * 3, 0.125f);
  const std::vector<std::string> names{"t=0ps", "t=10ps", "t=20ps", "t=30ps"};
  write_exr_multipart_rgb(path, w, h, t_bins, names, hwtc.data(), {{"femto:bin_width_ps", "10"}});
  REQUIRE(exr_part_names(path) == names);
  REQUIRE(read_exr_string_attribute(path, "femto:bin_width_ps", 3) == std::optional<std::string>("10"));
  const char* channels[3] = {"R", "G", "B"};
  for (int t = 0; t < t_bins; ++t)
    for (int c = 0; c < 3; ++c) {
      int w2 = 0, h2 = 0;
      std::vector<float> plane;
      read_exr_channel(path, t, channels[c], w2, h2, plane);
      REQUIRE((w2 == w && h2 == h));
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
          REQUIRE(plane[size_t(y) * w + x] == hwtc[((size_t(y) * w + x) * t_bins + t) * 3 + c]);
    }

  SECTION("default part names, and bad names are refused") {
    write_exr_multipart_rgb(path, w, h, t_bins, {}, hwtc.data());
    REQUIRE(exr_part_names(path) == std::vector<std::string>{"t00000", "t00001", "t00002", "t00003"});
    require_runtime_error_naming(
        [&] { write_exr_multipart_rgb(path, w, h, t_bins, {"a", "a", "b", "c"}, hwtc.data()); }, path);
    require_runtime_error_naming(
        [&] { write_exr_multipart_rgb(path, w, h, t_bins, {"a"}, hwtc.data()); }, path);
  }
}

TEST_CASE("PNG has the signature and IHDR size", "[io][png]") {
  IoDir tmp;
  const std::string path = tmp / "img.png";
  const int w = 7, h = 5;
  std::vector<uint8_t> rgb(size_t(w) * h * 3);
  for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<uint8_t>(i * 7);
  write_png_rgb8(path, w, h, rgb.data());
  const std::string b = slurp_io_file(path);
  REQUIRE(b.size() > 33);
  REQUIRE(b.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0);
  REQUIRE(be32(b, 8) == 13);  // IHDR data length
  REQUIRE(b.compare(12, 4, "IHDR") == 0);
  REQUIRE(be32(b, 16) == uint32_t(w));
  REQUIRE(be32(b, 20) == uint32_t(h));
  REQUIRE(b[24] == 8);  // bit depth
  REQUIRE(b[25] == 2);  // colour type RGB
  REQUIRE(b.compare(b.size() - 8, 4, "IEND") == 0);
  REQUIRE(tmp.temporaries().empty());
}

TEST_CASE("atomic writes replace the target and clean up", "[io][atomic]") {
  IoDir tmp;
  const std::string path = tmp / "out.txt";
  write_text_atomically(path, "first");
  write_text_atomically(path, "second\n");
  REQUIRE(slurp_io_file(path) == "second\n");
  REQUIRE(tmp.temporaries().empty());

  SECTION("the temporary sits next to the target and carries the pid") {
    std::string seen;
    write_atomically(path, [&](const std::string& t) {
      seen = t;
      std::ofstream(t) << "third";
    });
    REQUIRE(seen == path + ".tmp." + std::to_string(::getpid()));
    REQUIRE(slurp_io_file(path) == "third");
  }
  SECTION("a throwing writer leaves no temporary and the target unchanged") {
    REQUIRE_THROWS_WITH(write_atomically(path,
                                         [&](const std::string& t) {
                                           std::ofstream(t) << "partial";
                                           throw std::runtime_error("boom");
                                         }),
                        "boom");
    REQUIRE(slurp_io_file(path) == "second\n");
    REQUIRE(tmp.temporaries().empty());
  }
  SECTION("a failing encoder (here a bad size) does not touch the target") {
    REQUIRE_THROWS_AS(write_png_rgb8(path, 0, 3, reinterpret_cast<const uint8_t*>("x")), RuntimeError);
    REQUIRE(slurp_io_file(path) == "second\n");
    REQUIRE(tmp.temporaries().empty());
  }
}

TEST_CASE("writing into a missing directory throws RuntimeError naming the path", "[io][atomic]") {
  IoDir tmp;
  const std::string dir = tmp / "no/such/dir";
  const float f[12] = {};
  const uint8_t b[12] = {};
  require_runtime_error_naming([&] { write_text_atomically(dir + "/a.txt", "x"); }, dir + "/a.txt");
  require_runtime_error_naming([&] { write_npy_float32(dir + "/a.npy", {4}, f); }, dir + "/a.npy");
  require_runtime_error_naming([&] { write_exr_rgb(dir + "/a.exr", 2, 2, f); }, dir + "/a.exr");
  require_runtime_error_naming([&] { write_exr_channels(dir + "/y.exr", 2, 2, {"Y"}, {f}); },
                               dir + "/y.exr");
  require_runtime_error_naming([&] { write_exr_multipart_rgb(dir + "/m.exr", 1, 1, 2, {}, f); },
                               dir + "/m.exr");
  require_runtime_error_naming([&] { write_png_rgb8(dir + "/a.png", 2, 2, b); }, dir + "/a.png");
  REQUIRE_FALSE(fs::exists(tmp / "no"));
}

TEST_CASE("sRGB tone mapping and auto exposure", "[io][tonemap]") {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const float rgb[9] = {0.0f, 1.0f, 0.5f, nan, -1.0f, inf, 0.002f, 2.0f, 0.25f};
  const std::vector<uint8_t> out = tonemap_srgb8(rgb, 3, 1.0);
  REQUIRE(out == std::vector<uint8_t>{0, 255, 188, 0, 0, 255, 7, 255, 137});
  REQUIRE(tonemap_srgb8(rgb, 3, 2.0)[2] == 255);  // exposure scales before clamping

  const float zeros[6] = {};
  REQUIRE(auto_exposure(zeros, 2) == 1.0);
  std::vector<float> grey(300, 2.0f);
  grey[0] = grey[1] = grey[2] = 0.0f;  // zero pixels are ignored
  REQUIRE(auto_exposure(grey.data(), 100) == Approx(0.45));
  // One very bright outlier in 1000 pixels stays above the 99th percentile.
  std::vector<float> mostly(3000, 1.0f);
  mostly[0] = mostly[1] = mostly[2] = 1e6f;
  REQUIRE(auto_exposure(mostly.data(), 1000) == Approx(0.9));
}

TEST_CASE("contact sheet tiles frames with gaps and labels", "[io][tonemap]") {
  const int w = 40, h = 20, bins = 5;
  // Bin t is a uniform grey of value t/4, so tiles differ only by brightness.
  std::vector<float> hwtc(size_t(w) * h * bins * 3);
  for (size_t i = 0; i < hwtc.size(); ++i) hwtc[i] = static_cast<float>((i / 3) % bins) / 4.0f;
  int sw = 0, sh = 0;
  const std::vector<uint8_t> sheet =
      contact_sheet_rgb8(w, h, bins, hwtc.data(), {1, 2, 4}, {"t=1.5ps", "", "t=-2.0ps"}, 2, 1.0, sw, sh);
  const int gap = 4;
  REQUIRE(sw == 2 * w + 3 * gap);
  REQUIRE(sh == 2 * h + 3 * gap);
  REQUIRE(sheet.size() == size_t(sw) * sh * 3);
  auto px = [&](int x, int y) { return sheet[(size_t(y) * sw + x) * 3]; };
  auto grey8 = [](float v) { return tonemap_srgb8(std::vector<float>{v, v, v}.data(), 1, 1.0)[0]; };
  REQUIRE(px(0, 0) < 64);                                  // gap is dark
  REQUIRE(px(gap + w, gap) < 64);                          // gap between tiles
  REQUIRE(px(gap + w - 1, gap + h - 1) == grey8(0.25f));   // tile 0 = bin 1, away from its label
  REQUIRE(px(2 * gap + w + 5, gap + 5) == grey8(0.5f));    // tile 1 = bin 2, unlabelled
  REQUIRE(px(gap + w - 1, 2 * gap + 2 * h - 1) == 255);    // tile 2 = bin 4 = 1.0
  // The labelled tiles have white glyph pixels on a black box in their top-left corner.
  int white = 0, black = 0;
  for (int y = gap; y < gap + 10; ++y)
    for (int x = gap; x < gap + w; ++x) {
      white += px(x, y) == 255;
      black += px(x, y) == 0;
    }
  REQUIRE(white > 10);
  REQUIRE(black > 10);

  int sw2 = 0, sh2 = 0;
  const auto auto_sheet = contact_sheet_rgb8(w, h, bins, hwtc.data(), {1, 2}, {}, 0, 0.0, sw2, sh2);
  REQUIRE(sw2 == 2 * w + 3 * gap);
  REQUIRE(sh2 == h + 2 * gap);
  // Auto exposure over both frames maps the brighter one (bin 2, 0.5) to 0.9.
  REQUIRE(auto_sheet[(size_t(gap + 5) * sw2 + 2 * gap + w + 5) * 3] == grey8(0.9f));
  REQUIRE_THROWS_AS(contact_sheet_rgb8(w, h, bins, hwtc.data(), {5}, {}, 1, 1.0, sw2, sh2), RuntimeError);
}
