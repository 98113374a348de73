#include "core/medium_nesting.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/error.h"

namespace femto {

namespace {

struct Box3 {
  Vec3 lo{std::numeric_limits<double>::infinity()};
  Vec3 hi{-std::numeric_limits<double>::infinity()};
  void add(const Vec3& p) { lo = vmin(lo, p), hi = vmax(hi, p); }
  bool overlaps(const Box3& b, double tol) const {
    return lo.x <= b.hi.x + tol && b.lo.x <= hi.x + tol && lo.y <= b.hi.y + tol &&
           b.lo.y <= hi.y + tol && lo.z <= b.hi.z + tol && b.lo.z <= hi.z + tol;
  }
  bool holds(const Vec3& p, double tol) const {
    return p.x >= lo.x - tol && p.x <= hi.x + tol && p.y >= lo.y - tol && p.y <= hi.y + tol &&
           p.z >= lo.z - tol && p.z <= hi.z + tol;
  }
  double volume() const { return (hi.x - lo.x) * (hi.y - lo.y) * (hi.z - lo.z); }
};

Box3 bounds_of(const ShapeDesc& s) {
  Box3 b;
  if (s.type == ShapeDesc::Type::Sphere) {
    b.add(s.center - Vec3(s.radius));
    b.add(s.center + Vec3(s.radius));
  } else {
    for (const Vec3& v : s.vertices) b.add(v);
  }
  return b;
}

}  // namespace

void shape_bounds(const ShapeDesc& s, Vec3& lo, Vec3& hi) {
  const Box3 b = bounds_of(s);
  lo = b.lo, hi = b.hi;
}

namespace {

bool is_sphere(const ShapeDesc& s) {
  return s.type == ShapeDesc::Type::Sphere;
}

struct Tri {
  Vec3 a, b, c;
};
Tri triangle(const ShapeDesc& s, size_t i) {
  const auto& t = s.triangles[i];
  return {s.vertices[t[0]], s.vertices[t[1]], s.vertices[t[2]]};
}
Box3 bounds_of(const Tri& t) {
  Box3 b;
  b.add(t.a), b.add(t.b), b.add(t.c);
  return b;
}

// Closest point to p on triangle abc, by the Voronoi regions of its vertices, edges and face.
Vec3 closest_on_triangle(const Vec3& p, const Tri& t) {
  const Vec3 ab = t.b - t.a, ac = t.c - t.a, ap = p - t.a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return t.a;
  const Vec3 bp = p - t.b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return t.b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return t.a + ab * (d1 / (d1 - d3));
  const Vec3 cp = p - t.c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return t.c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return t.a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return t.b + (t.c - t.b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = 1.0 / (va + vb + vc);
  return t.a + ab * (vb * denom) + ac * (vc * denom);
}

}  // namespace

double distance_to_triangles(const ShapeDesc& s, const Vec3& p) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < s.triangles.size(); ++i) {
    const Tri t = triangle(s, i);
    best = std::min(best, length(p - closest_on_triangle(p, t)));
  }
  return best;
}

namespace {

// Parameter s of the crossing of the line o + s d with triangle t, or NaN; crossings within
// rel_tol (barycentric) of the triangle's edges do not count.
double crossing(const Vec3& o, const Vec3& d, const Tri& t, double rel_tol) {
  const Vec3 e1 = t.b - t.a, e2 = t.c - t.a;
  const Vec3 q = cross(d, e2);
  const double det = dot(e1, q);
  const double scale = length(d) * length(e1) * length(e2);
  if (!(std::abs(det) > 1e-12 * scale)) return std::nan("");  // parallel or degenerate
  const Vec3 r = o - t.a;
  const double u = dot(r, q) / det;
  const Vec3 k = cross(r, e1);
  const double v = dot(d, k) / det;
  if (u <= rel_tol || v <= rel_tol || u + v >= 1 - rel_tol) return std::nan("");
  return dot(e2, k) / det;
}

// Whether p lies inside closed shape s (ray parity for triangle shapes).
bool inside(const ShapeDesc& s, const Vec3& p) {
  if (is_sphere(s)) return length(p - s.center) < s.radius;
  // A direction along no axis or diagonal, so the ray meets edges of boxes only by accident.
  const Vec3 d = normalize(Vec3(0.5377, 0.6289, 0.5615));
  int crossings = 0;
  for (size_t i = 0; i < s.triangles.size(); ++i) {
    const double t = crossing(p, d, triangle(s, i), 0.0);
    if (t > 0) ++crossings;
  }
  return crossings % 2 == 1;
}

enum class Relation { Disjoint, AInB, BInA, Cross, Touch };

Relation flip(Relation r) {
  return r == Relation::AInB ? Relation::BInA : r == Relation::BInA ? Relation::AInB : r;
}

Relation spheres(const ShapeDesc& a, const ShapeDesc& b, double tol) {
  const double d = length(a.center - b.center);
  if (d + a.radius < b.radius - tol) return Relation::AInB;
  if (d + b.radius < a.radius - tol) return Relation::BInA;
  if (d > a.radius + b.radius + tol) return Relation::Disjoint;
  const bool touch = std::abs(d - (a.radius + b.radius)) <= tol ||
                     std::abs(d + a.radius - b.radius) <= tol ||
                     std::abs(d + b.radius - a.radius) <= tol;
  return touch ? Relation::Touch : Relation::Cross;
}

// Sphere a against the triangle shape b: the sphere's surface meets b's surface exactly when
// the nearest point of b is inside the ball and the farthest (a vertex) outside it.
Relation sphere_triangles(const ShapeDesc& a, const ShapeDesc& b, bool b_closed, double tol) {
  const double d_min = distance_to_triangles(b, a.center);
  double d_max = 0;
  for (const Vec3& v : b.vertices) d_max = std::max(d_max, length(v - a.center));
  if (d_min > a.radius + tol)
    return b_closed && inside(b, a.center) ? Relation::AInB : Relation::Disjoint;
  if (d_max < a.radius - tol) return Relation::BInA;
  if (d_min < a.radius - tol && d_max > a.radius + tol) return Relation::Cross;
  return Relation::Touch;
}

// The triangles of a shape binned into a uniform grid over its bounds, so that the pair tests
// below look only at triangles near an edge or a vertex (large nested meshes stay fast).
class TriangleGrid {
 public:
  TriangleGrid(const ShapeDesc& s, double tol) : shape_(s), tol_(tol) {
    for (const Vec3& v : s.vertices) box_.add(v);
    const size_t T = s.triangles.size();
    r_ = std::clamp(static_cast<int>(std::cbrt(static_cast<double>(T))), 1, 64);
    for (int a = 0; a < 3; ++a) {
      const double extent = box_.hi[a] - box_.lo[a];
      inv_cell_[a] = extent > 0 ? r_ / extent : 0.0;  // a flat shape: one layer of cells
    }
    cells_.resize(static_cast<size_t>(r_) * r_ * r_);
    boxes_.resize(T);
    for (size_t j = 0; j < T; ++j) {
      boxes_[j] = bounds_of(triangle(s, j));
      for_cells(boxes_[j], [&](size_t c) { cells_[c].push_back(static_cast<uint32_t>(j)); });
    }
    stamp_.assign(T, 0);
  }
  double tolerance() const { return tol_; }
  /// Calls f(j, triangle j) once for every triangle whose box comes within tol of q.
  template <class F>
  bool any(const Box3& q, F f) {
    if (!q.overlaps(box_, tol_)) return false;
    ++visit_;
    bool hit = false;
    for_cells(q, [&](size_t c) {
      for (uint32_t j : cells_[c]) {
        if (hit || stamp_[j] == visit_) continue;
        stamp_[j] = visit_;
        if (q.overlaps(boxes_[j], tol_) && f(triangle(shape_, j))) hit = true;
      }
    });
    return hit;
  }

 private:
  int cell(double x, int a) const {  // clamped as a double: x may lie far outside the box
    const double c = std::floor((x - box_.lo[a]) * inv_cell_[a]);
    return static_cast<int>(std::clamp(c, 0.0, static_cast<double>(r_ - 1)));
  }
  template <class F>
  void for_cells(const Box3& q, F f) const {
    int lo[3], hi[3];
    for (int a = 0; a < 3; ++a) lo[a] = cell(q.lo[a] - tol_, a), hi[a] = cell(q.hi[a] + tol_, a);
    for (int z = lo[2]; z <= hi[2]; ++z)
      for (int y = lo[1]; y <= hi[1]; ++y)
        for (int x = lo[0]; x <= hi[0]; ++x)
          f((static_cast<size_t>(z) * r_ + static_cast<size_t>(y)) * r_ + static_cast<size_t>(x));
  }

  const ShapeDesc& shape_;
  double tol_;
  Box3 box_;
  int r_ = 1;
  double inv_cell_[3] = {1, 1, 1};
  std::vector<std::vector<uint32_t>> cells_;
  std::vector<Box3> boxes_;
  std::vector<uint32_t> stamp_;
  uint32_t visit_ = 0;
};

// Whether an edge of a crosses a triangle of b strictly inside both.
bool edges_cross(const ShapeDesc& a, TriangleGrid& b) {
  for (size_t i = 0; i < a.triangles.size(); ++i) {
    const Tri t = triangle(a, i);
    const Vec3 corners[3] = {t.a, t.b, t.c};
    for (int e = 0; e < 3; ++e) {
      const Vec3 p0 = corners[e], p1 = corners[(e + 1) % 3];
      Box3 eb;
      eb.add(p0), eb.add(p1);
      const double s_tol = b.tolerance() / std::max(length(p1 - p0), 1e-300);
      if (b.any(eb, [&](const Tri& tb) {
            const double s = crossing(p0, p1 - p0, tb, 1e-9);
            return s > s_tol && s < 1 - s_tol;
          }))
        return true;
    }
  }
  return false;
}

// Whether a vertex of a lies within tol of b's surface.
bool vertex_on_surface(const ShapeDesc& a, TriangleGrid& b) {
  const double tol = b.tolerance();
  for (const Vec3& v : a.vertices) {
    Box3 q;
    q.add(v);
    if (b.any(q, [&](const Tri& tb) { return length(v - closest_on_triangle(v, tb)) <= tol; }))
      return true;
  }
  return false;
}

// How shape a lies relative to shape b. `a_closed`/`b_closed`: whether each bounds a region
// (only then can the other lie inside it).
Relation relate(const ShapeDesc& a, bool a_closed, const ShapeDesc& b, bool b_closed, double tol) {
  if (is_sphere(a) && is_sphere(b)) return spheres(a, b, tol);
  if (is_sphere(a)) return sphere_triangles(a, b, b_closed, tol);
  if (is_sphere(b)) return flip(sphere_triangles(b, a, a_closed, tol));
  TriangleGrid a_grid(a, tol), b_grid(b, tol);
  if (edges_cross(a, b_grid) || edges_cross(b, a_grid)) return Relation::Cross;
  if (vertex_on_surface(a, b_grid) || vertex_on_surface(b, a_grid)) return Relation::Touch;
  if (b_closed && inside(b, a.vertices.front())) return Relation::AInB;
  if (a_closed && inside(a, b.vertices.front())) return Relation::BInA;
  return Relation::Disjoint;
}

}  // namespace

bool bounds_a_medium(const ShapeDesc& s) {
  return s.interior_medium >= 0 || s.material.is_transmissive();
}

std::vector<int> enclosing_shapes(const SceneDesc& scene) {
  const auto& shapes = scene.shapes;
  const size_t n = shapes.size();
  std::vector<Box3> boxes(n);
  for (size_t i = 0; i < n; ++i) boxes[i] = bounds_of(shapes[i]);
  std::vector<int> enclosing(n, -1);
  for (size_t i = 0; i < n; ++i) {
    const bool i_medium = bounds_a_medium(shapes[i]);
    for (size_t j = 0; j < n; ++j) {
      if (j == i || !bounds_a_medium(shapes[j])) continue;
      // Geometric tolerance: a few float ulps of the pair's extent (Embree's vertices are float).
      const double extent =
          std::max({max_abs_component(boxes[i].lo), max_abs_component(boxes[i].hi),
                    max_abs_component(boxes[j].lo), max_abs_component(boxes[j].hi), 1.0});
      const double tol = 1e-6 * extent;
      if (!boxes[i].overlaps(boxes[j], tol)) continue;
      const Relation r = relate(shapes[i], i_medium, shapes[j], true, tol);
      if (i_medium && (r == Relation::Cross || r == Relation::Touch)) {
        if (j < i) continue;  // reported for the pair (j, i) already
        throw InputError(
            clip(scene.source, 200) + ": " + shapes[i].where + " and " + shapes[j].where +
            ": the surfaces of two shapes with a medium or a refracting material " +
            (r == Relation::Cross ? "cross" : "touch") +
            "; such shapes may nest (one strictly inside the other) but not overlap or touch");
      }
      if (r != Relation::AInB) continue;
      const int best = enclosing[i];
      if (best < 0 || boxes[j].volume() < boxes[static_cast<size_t>(best)].volume())
        enclosing[i] = static_cast<int>(j);
    }
  }
  return enclosing;
}

int innermost_shape_at(const SceneDesc& scene, const std::vector<int>& enclosing, const Vec3& p) {
  int best = -1, best_depth = -1;
  for (size_t j = 0; j < scene.shapes.size(); ++j) {
    const ShapeDesc& s = scene.shapes[j];
    if (!bounds_a_medium(s) || !bounds_of(s).holds(p, 0.0) || !inside(s, p)) continue;
    int depth = 0;
    for (int k = enclosing[j]; k >= 0; k = enclosing[static_cast<size_t>(k)]) ++depth;
    if (depth > best_depth) best = static_cast<int>(j), best_depth = depth;
  }
  return best;
}

}  // namespace femto
