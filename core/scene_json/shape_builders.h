#pragma once
// Triangles of the camera scenes' quad and box shapes, and a mesh file read by its extension:
// shared by the scene loader and the tissue mode's emissive-shape sources.
#include <string>

#include "core/scene_desc.h"

namespace femto::scene_json {

/// The quad corner, corner + e1, corner + e1 + e2, corner + e2: two triangles whose normals point
/// along e1 x e2.
void make_quad(const Vec3& corner, const Vec3& e1, const Vec3& e2, ShapeDesc& s);
/// The box from lo to hi: twelve triangles whose normals point outwards.
void make_box(const Vec3& lo, const Vec3& hi, ShapeDesc& s);
/// An OBJ or PLY file (by its extension) into s.vertices and s.triangles; InputError naming the
/// file (and line) on bad content.
void load_mesh_file(const std::string& path, ShapeDesc& s);

}  // namespace femto::scene_json
