#pragma once
// Which closed shape encloses which: media may nest (glass inside a fog box, a tumour inside
// tissue), so the medium outside a shape is the inside of the innermost shape around it.
#include <vector>

#include "core/scene_desc.h"

namespace femto {

/// Distance from p to the surface of a triangle shape (quad, box, mesh).
double distance_to_triangles(const ShapeDesc& s, const Vec3& p);

/// Whether shape s bounds a region of its own medium (a `medium`, or a refracting material).
bool bounds_a_medium(const ShapeDesc& s);

/// The axis-aligned bounding box [lo, hi] of shape s.
void shape_bounds(const ShapeDesc& s, Vec3& lo, Vec3& hi);

/// For every shape, the index of the innermost medium-bounding shape that strictly encloses it,
/// or -1 when the global medium surrounds it. Throws InputError, naming both shapes, when the
/// surfaces of two medium-bounding shapes cross or touch (nesting must be strict).
/// Shapes that bound no medium and cross a medium boundary get -1: paths keep their medium
/// across them, and a light path's first medium is found past them (medium_at_origin).
std::vector<int> enclosing_shapes(const SceneDesc& scene);

/// The innermost medium-bounding shape that contains point p (strictly inside), or -1.
/// `enclosing` is the result of enclosing_shapes().
int innermost_shape_at(const SceneDesc& scene, const std::vector<int>& enclosing, const Vec3& p);

}  // namespace femto
