// <transform>: translate, rotate, scale, matrix and lookat composed into one affine map in mm.
#include <cmath>

#include "core/error.h"
#include "core/mitsuba/importer.h"

namespace femto::mitsuba {

Importer::Placement Importer::get_transform(Props& p, const std::string& name) const {
  Placement out;
  const Node n = take(p, name);
  Affine m;
  int ops = 0;
  if (n) {
    expect_tag(n, {"transform"});
    check_attributes(n, {"name"});
    check_text(n);
    for (Node c : n.children()) {
      if (c.type() != pugi::node_element) continue;
      const std::string op = c.name();
      check_text(c);
      ++ops;
      if (op == "translate") {
        check_attributes(c, {"value", "x", "y", "z"});
        m = Affine::translate(xyz(c, 0.0)) * m;
      } else if (op == "scale") {
        check_attributes(c, {"value", "x", "y", "z"});
        m = Affine::scale(xyz(c, 1.0)) * m;
      } else if (op == "rotate") {
        check_attributes(c, {"value", "x", "y", "z", "angle"});
        const Vec3 axis = xyz(c, 0.0);
        if (!(length(axis) > 0)) fail(c, "the rotation axis must be non-zero");
        const double angle = c.attribute("angle") ? number(c, "angle", attr(c, "angle")) : 0.0;
        m = Affine::rotate(normalize(axis), angle) * m;
      } else if (op == "matrix") {
        check_attributes(c, {"value"});
        const std::vector<double> v = numbers(c, "value", attr(c, "value"));
        Affine a;
        if (v.size() == 16) {
          if (v[12] != 0 || v[13] != 0 || v[14] != 0 || v[15] != 1)
            fail(c, "the last row must be 0 0 0 1 (projective matrices are not supported)");
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 4; ++j) a.m[i][j] = v[static_cast<std::size_t>(4 * i + j)];
        } else if (v.size() == 9) {
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) a.m[i][j] = v[static_cast<std::size_t>(3 * i + j)];
        } else {
          fail(c, "attribute 'value': expected 16 (or 9) numbers, row by row");
        }
        m = a * m;
      } else if (op == "lookat") {
        check_attributes(c, {"origin", "target", "up"});
        const Vec3 o = triple(c, "origin"), t = triple(c, "target");
        Vec3 up = c.attribute("up") ? triple(c, "up") : Vec3(0, 0, 0);
        if (up.x == 0 && up.y == 0 && up.z == 0 && length(t - o) > 0)
          up = mitsuba::any_perpendicular(normalize(t - o));  // what Mitsuba does
        if (!(length(t - o) > 0)) fail(c, "'target' must differ from 'origin'");
        if (!(length(cross(normalize(up), normalize(t - o))) > 1e-9))
          fail(c, "'up' must be non-zero and not parallel to target - origin");
        m = Affine::lookat(o, t, up) * m;
        if (ops == 1) {
          out.single_lookat = true;
          out.origin = o * unit_mm_;
          out.target = t * unit_mm_;
          out.up = up;
        }
      } else {
        fail(c, "unsupported transform operation <" + clip(op) +
                    "> (translate, rotate, scale, matrix and lookat are)");
      }
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 4; ++j)
          if (!std::isfinite(m.m[i][j])) fail(c, "the transform is not finite");
    }
  }
  if (ops != 1) out.single_lookat = false;
  out.m = unit_mm_ == 1.0 ? m : Affine::scale(Vec3(unit_mm_)) * m;
  return out;
}

}  // namespace femto::mitsuba
