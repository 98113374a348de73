// The OBJ reader: polygon faces as fans, every face-corner form, negative indices, and its
// refusals of bad input.
#include <array>
#include <catch2/catch.hpp>
#include <string>
#include <vector>

#include "core/obj_loader.h"
#include "scene_loader_helpers.h"

using namespace femto::test::loader;

TEST_CASE("obj loader: faces, indices and errors", "[obj_loader]") {
  std::vector<Vec3> v;
  std::vector<std::array<uint32_t, 3>> t;

  femto::load_obj(write_temp_file("pent.obj",
                                  "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0.5 1.5 0\nv +0 1 -0e0\n"
                                  "g poly\nf 1 2 3 4 5\nl 1 2\n"),
                  v, t);
  REQUIRE(v.size() == 5);
  CHECK(v[3].x == 0.5);
  REQUIRE(t.size() == 3);  // fan around the first corner
  CHECK(t[0] == std::array<uint32_t, 3>{0, 1, 2});
  CHECK(t[2] == std::array<uint32_t, 3>{0, 3, 4});

  femto::load_obj(write_temp_file("tet.obj", kTetObj), v, t);
  REQUIRE(t.size() == 4);
  CHECK(t[2] == std::array<uint32_t, 3>{0, 3, 2});  // from negative indices

  // Forward references are allowed as long as the vertex exists by the end of the file.
  femto::load_obj(write_temp_file("fwd.obj", "f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"), v, t);
  CHECK(t.size() == 1);

  auto error = [&](const std::string& name, const std::string& text) -> std::string {
    const std::string path = write_temp_file(name, text);
    try {
      femto::load_obj(path, v, t);
    } catch (const InputError& e) {
      return e.what();
    }
    FAIL("expected an InputError for " << name);
    return "";
  };
  CHECK_THAT(error("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 9\n"),
             Contains("range.obj:5:") && Contains("9") && Contains("3 vertices"));
  CHECK_THAT(error("neg.obj", "v 0 0 0\nf -1 -2 -3\n"), Contains("neg.obj:2:") && Contains("-2"));
  CHECK_THAT(error("zero.obj", "v 0 0 0\nf 0 1 1\n"), Contains("zero.obj:2:") && Contains("'0'"));
  CHECK_THAT(error("num.obj", "# x\nv 0 0 nan\n"), Contains("num.obj:2:") && Contains("'nan'"));
  CHECK_THAT(error("short.obj", "v 0 0\n"), Contains("short.obj:1:"));
  CHECK_THAT(error("two.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n"), Contains("two.obj:3:"));
  CHECK_THAT(error("slash.obj", "v 0 0 0\nf 1/x 1 1\n"),
             Contains("slash.obj:2:") && Contains("1/x"));
  CHECK_THAT(error("curve.obj", "v 0 0 0\ncurv 0 1 1\n"),
             Contains("curve.obj:2:") && Contains("curv"));
  CHECK_THAT(error("empty.obj", "# nothing\nv 0 0 0\n"),
             Contains("empty.obj") && Contains("no faces"));
  CHECK_THROWS_AS(femto::load_obj((temp_dir() / "missing.obj").string(), v, t), InputError);
}
