// Regression tests for hostile scene input (docs/RELIABILITY.md): every case once crashed,
// hung or produced non-finite output; now each is one short InputError naming file, key, value.
#include <catch2/catch.hpp>

#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/film.h"
#include "core/scene_loader.h"
#include "media/grid_medium.h"

using femto::InputError;
using Catch::Matchers::Contains;
using Json = nlohmann::ordered_json;

namespace {

Json bad_input_scene() {
  return Json::parse(R"({
    "camera": {"position": [0, 0, 100], "look_at": [0, 0, 0], "resolution": [8, 8]},
    "time": {"bin_width": 10, "bins": 10},
    "media": {"fog": {"type": "homogeneous", "sigma_a": 0.001, "sigma_s": 0.01}},
    "medium": "fog",
    "shapes": [{"type": "quad", "corner": [-10, -10, 0], "edge1": [20, 0, 0], "edge2": [0, 20, 0],
                "material": {"type": "diffuse", "albedo": 0.5}}],
    "lights": [{"type": "point", "position": [0, 0, 50], "intensity": 10}]
  })");
}

// The loader's message for `text`, checked to be one bounded line naming the file.
std::string bad_scene_error(const std::string& text) {
  try {
    femto::load_scene_string(text, "bad.json", ".");
  } catch (const InputError& e) {
    const std::string msg = e.what();
    CHECK(msg.find('\n') == std::string::npos);
    CHECK(msg.size() < 1000);
    CHECK_THAT(msg, Contains("bad.json: "));
    return msg;
  }
  FAIL("expected an InputError");
  return "";
}

std::string error_with(const std::function<void(Json&)>& edit) {
  Json j = bad_input_scene();
  edit(j);
  return bad_scene_error(j.dump());
}

}  // namespace

// Was: stack overflow (SIGSEGV) printing a 100,000-deep value in the error message.
TEST_CASE("deeply nested JSON is refused at depth 64 without recursion", "[robust]") {
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  CHECK_THAT(bad_scene_error(deep), Contains("nested more than 64 levels"));
  const std::string deep_in_key = R"({"camera": )" + std::string(100000, '[') + "1" +
                                  std::string(100000, ']') + "}";
  CHECK_THAT(bad_scene_error(deep_in_key), Contains("/camera") && Contains("nested"));
}

// Was: Embree assertion abort on coordinates beyond float range; the loader took any double.
TEST_CASE("magnitudes beyond the documented bounds are refused", "[robust]") {
  CHECK_THAT(error_with([](Json& j) { j["lights"][0]["position"] = {0, 0, 1e39}; }),
             Contains("/lights/0/position/2: must be within +-1e9") && Contains("1e+39"));
  CHECK_THAT(error_with([](Json& j) {
               j["shapes"].push_back({{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 1e40},
                                      {"material", {{"type", "mirror"}}}});
             }),
             Contains("/shapes/1/radius: must be within +-1e9"));
  CHECK_THAT(error_with([](Json& j) { j["shapes"][0]["transform"] = {{"scale", 1e39}}; }),
             Contains("/shapes/0/transform/scale: must be within +-1e9"));
  CHECK_THAT(error_with([](Json& j) { j["shapes"][0]["transform"] = {{"scale", 1e6}, {"translate", {9.95e8, 0, 0}}}; }),
             Contains("/shapes/0/transform: vertex 2 lands at") && Contains("outside the bound"));
  CHECK_THAT(error_with([](Json& j) {
               j["camera"]["type"] = "orthographic";
               j["camera"].erase("fov");
               j["camera"]["width"] = 1e200;
             }),
             Contains("/camera/width: must be within +-1e9"));
  CHECK_THAT(error_with([](Json& j) {
               j["media"]["fog"]["distance_sampling"] = "time_uniform";
               j["media"]["fog"]["time_uniform_rate"] = 5e-324;
             }),
             Contains("/media/fog/time_uniform_rate: must be >= 1e-09"));
  CHECK_THAT(error_with([](Json& j) { j["lights"][0]["pulse"] = {{"fwhm", 1e12}}; }),
             Contains("/lights/0/pulse/fwhm: must be within +-1e9"));
  CHECK_THAT(error_with([](Json& j) { j["time"]["bin_width"] = 1e9; j["time"]["bins"] = 100; }),
             Contains("/time/bins: the window ends at 1e+11 ps"));
}

// Was: exit 0 with inf in transient.npy from a finite emission of 1e308.
TEST_CASE("emission beyond the bound is refused; the film never keeps non-finite values", "[robust]") {
  CHECK_THAT(error_with([](Json& j) { j["shapes"][0]["emission"] = 1e308; }),
             Contains("/shapes/0/emission: must be within +-1e9") && Contains("1e+308"));
  femto::TimeAxis axis;
  axis.bins = 2;
  femto::TransientFilm film(1, 1, axis);
  const double bins[6] = {1e300, 1.0, 2.0, 3.0, std::nan(""), 4.0};  // overflows float32
  film.set_pixel(0, 0, bins, femto::RGB(0.0), femto::RGB(0.0), 1);
  CHECK(film.zero_nonfinite() == 4);  // two bins, and the steady red and green sums
  for (int i = 0; i < 6; ++i) CHECK(std::isfinite(film.transient()[i]));
  CHECK(film.zero_nonfinite() == 0);
}

// Was: 20 s of quadratic edit distance, and the whole name printed back.
TEST_CASE("a 100k-character medium name is refused fast with a clipped message", "[robust]") {
  const std::string longname(100000, 'x');
  const auto start = std::chrono::steady_clock::now();
  const std::string msg = error_with([&](Json& j) {
    j["media"][longname + "y"] = {{"type", "homogeneous"}, {"sigma_a", 0}, {"sigma_s", 0}};
    j["media"][longname] = j["media"]["fog"];
    j["medium"] = longname + "z";
  });
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  CHECK(seconds < 2.0);
  CHECK_THAT(msg, Contains("unknown medium 'xxx") && Contains("...'"));
  CHECK_THAT(error_with([&](Json& j) { j[longname] = 1; }), Contains("unknown key 'xxx"));
}

// Was: femto render /dev/zero read forever.
TEST_CASE("scene files are read up to 64 MiB", "[robust]") {
  CHECK_THROWS_WITH(femto::read_scene_text("/dev/zero"), Contains("larger than the 64 MiB limit"));
  CHECK_THROWS_AS(femto::load_scene_file("/dev/zero"), InputError);
}

// Was: signed overflow converting far grid coordinates (pulse fwhm 1e12 in cloud.json).
TEST_CASE("grid cell indices of far points are clamped, not overflowed", "[robust]") {
  CHECK(femto::clamped_floor(2.5) == 2);
  CHECK(femto::clamped_floor(-2.5) == -3);
  CHECK(femto::clamped_floor(1e12) == (1 << 30));
  CHECK(femto::clamped_floor(-1e300) == -(1 << 30));
  CHECK(femto::clamped_floor(std::nan("")) == -(1 << 30));
  CHECK(femto::clamped_floor(std::numeric_limits<double>::infinity()) == (1 << 30));
}
