#include "core/geometry.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "core/error.h"

namespace femto {

/// A sphere as Embree's user geometry holds it (outside the anonymous namespace: Geometry::Impl
/// keeps one, and a unity build would see that as a member of internal linkage).
struct SphereData {
  Vec3 center;
  double radius;
};

namespace {

// Nearest root of |o + s d - c|^2 = r^2 in (s_min, s_max), computed in double precision.
bool intersect_sphere(const SphereData& sp, const Vec3& o, const Vec3& d, double s_min,
                      double s_max, double& s_hit) {
  const Vec3 oc = o - sp.center;
  const double b = dot(oc, d);
  // Stable discriminant: |oc - b d|^2 avoids cancellation for far-away origins.
  const Vec3 perp = oc - d * b;
  const double disc = sp.radius * sp.radius - dot(perp, perp);
  if (disc < 0.0) return false;
  const double q = std::sqrt(disc);
  const double s0 = -b - q, s1 = -b + q;
  if (s0 > s_min && s0 < s_max) { s_hit = s0; return true; }
  if (s1 > s_min && s1 < s_max) { s_hit = s1; return true; }
  return false;
}

void sphere_bounds(const RTCBoundsFunctionArguments* args) {
  const auto* sp = static_cast<const SphereData*>(args->geometryUserPtr);
  const float pad = 1e-4f * static_cast<float>(sp->radius);
  args->bounds_o->lower_x = static_cast<float>(sp->center.x - sp->radius) - pad;
  args->bounds_o->lower_y = static_cast<float>(sp->center.y - sp->radius) - pad;
  args->bounds_o->lower_z = static_cast<float>(sp->center.z - sp->radius) - pad;
  args->bounds_o->upper_x = static_cast<float>(sp->center.x + sp->radius) + pad;
  args->bounds_o->upper_y = static_cast<float>(sp->center.y + sp->radius) + pad;
  args->bounds_o->upper_z = static_cast<float>(sp->center.z + sp->radius) + pad;
}

// Ray context carrying the double-precision ray, so sphere hits are exact to double precision.
struct FemtoContext {
  RTCIntersectContext rtc;
  Vec3 o, d;
};

void sphere_occluded(const RTCOccludedFunctionNArguments* args) {
  if (!args->valid[0]) return;
  const auto* sp = static_cast<const SphereData*>(args->geometryUserPtr);
  const auto* ctx = reinterpret_cast<const FemtoContext*>(args->context);
  RTCRay* ray = reinterpret_cast<RTCRay*>(args->ray);
  double s;
  if (intersect_sphere(*sp, ctx->o, ctx->d, ray->tnear, ray->tfar, s))
    ray->tfar = -std::numeric_limits<float>::infinity();  // Embree's "occluded" mark
}

void sphere_intersect(const RTCIntersectFunctionNArguments* args) {
  if (!args->valid[0]) return;
  const auto* sp = static_cast<const SphereData*>(args->geometryUserPtr);
  const auto* ctx = reinterpret_cast<const FemtoContext*>(args->context);
  RTCRayHit* rh = reinterpret_cast<RTCRayHit*>(args->rayhit);
  double s;
  if (!intersect_sphere(*sp, ctx->o, ctx->d, rh->ray.tnear, rh->ray.tfar, s)) return;
  const Vec3 n = (ctx->o + ctx->d * s - sp->center) / sp->radius;
  rh->ray.tfar = static_cast<float>(s);
  rh->hit.Ng_x = static_cast<float>(n.x);
  rh->hit.Ng_y = static_cast<float>(n.y);
  rh->hit.Ng_z = static_cast<float>(n.z);
  rh->hit.u = 0.0f;
  rh->hit.v = 0.0f;
  rh->hit.primID = args->primID;
  rh->hit.geomID = args->geomID;
  rh->hit.instID[0] = args->context->instID[0];
}

}  // namespace

/// A box or sphere that no other shape's bounds touch: a ray starting strictly inside it leaves
/// through its own surface before meeting anything else, so that hit is found in closed form
/// (most rays of a medium held by a box or sphere start inside it). Boxes are axis-aligned (the
/// loader's make_box); prim[axis][side] is the triangle of that face (side 1: the max face).
struct EmptyCell {
  int shape = -1;
  bool sphere = false;
  Vec3 lo, hi;  ///< box
  SphereData sp{};
  int prim[3][2] = {{-1, -1}, {-1, -1}, {-1, -1}};
};

constexpr size_t kMaxEmptyCells = 16;  // beyond this the per-ray test would cost more than it saves

struct Geometry::Impl {
  std::vector<EmptyCell> cells;
  /// Closed-form closest hit for a ray starting inside an empty cell: 1 hit, 0 no hit in
  /// (s_min, s_max), -1 not applicable (Embree decides).
  int inside_hit(const Ray& ray, double s_min, double s_max, SurfaceHit* hit) const;
  /// Bounds of every shape, when all are empty cells: a ray that misses them all meets nothing,
  /// so Embree need not be asked (a shadow ray's leg from a medium's face to a light outside it).
  std::vector<Vec3> box_lo, box_hi;
  double extent = 0.0;  ///< largest coordinate magnitude of the shapes' bounds
  bool misses_bounds(const Ray& ray, double s_min, double s_max) const;
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::vector<SphereData> spheres;            // indexed by shape (unused for triangle shapes)
  std::vector<const ShapeDesc*> shapes;       // geomID == shape index
  std::vector<std::vector<Vec3>> tri_normals;  // double-precision normals per shape
  Vec3 lo{std::numeric_limits<double>::infinity()}, hi{-std::numeric_limits<double>::infinity()};
};

Geometry::Geometry(const SceneDesc& desc, bool closed_form_cells)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.device = rtcNewDevice(nullptr);  // no "threads=N": Embree would cap all of TBB with it
  if (!m.device) throw RuntimeError("Embree: cannot create a device");
  m.scene = rtcNewScene(m.device);
  rtcSetSceneFlags(m.scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(m.scene, RTC_BUILD_QUALITY_HIGH);
  m.spheres.resize(desc.shapes.size());
  m.tri_normals.resize(desc.shapes.size());
  for (size_t i = 0; i < desc.shapes.size(); ++i) {
    const ShapeDesc& sh = desc.shapes[i];
    m.shapes.push_back(&sh);
    RTCGeometry g;
    if (sh.type == ShapeDesc::Type::Sphere) {
      m.spheres[i] = {sh.center, sh.radius};
      g = rtcNewGeometry(m.device, RTC_GEOMETRY_TYPE_USER);
      rtcSetGeometryUserPrimitiveCount(g, 1);
      rtcSetGeometryUserData(g, &m.spheres[i]);
      rtcSetGeometryBoundsFunction(g, sphere_bounds, nullptr);
      rtcSetGeometryIntersectFunction(g, sphere_intersect);
      rtcSetGeometryOccludedFunction(g, sphere_occluded);
      m.lo = vmin(m.lo, sh.center - Vec3(sh.radius));
      m.hi = vmax(m.hi, sh.center + Vec3(sh.radius));
    } else {
      g = rtcNewGeometry(m.device, RTC_GEOMETRY_TYPE_TRIANGLE);
      auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
          g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), sh.vertices.size()));
      for (size_t k = 0; k < sh.vertices.size(); ++k) {
        v[3 * k + 0] = static_cast<float>(sh.vertices[k].x);
        v[3 * k + 1] = static_cast<float>(sh.vertices[k].y);
        v[3 * k + 2] = static_cast<float>(sh.vertices[k].z);
        m.lo = vmin(m.lo, sh.vertices[k]);
        m.hi = vmax(m.hi, sh.vertices[k]);
      }
      auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
          g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), sh.triangles.size()));
      auto& normals = m.tri_normals[i];
      normals.reserve(sh.triangles.size());
      for (size_t k = 0; k < sh.triangles.size(); ++k) {
        const auto& t = sh.triangles[k];
        for (int c = 0; c < 3; ++c) idx[3 * k + c] = t[c];
        const Vec3 n = cross(sh.vertices[t[1]] - sh.vertices[t[0]], sh.vertices[t[2]] - sh.vertices[t[0]]);
        const double len = length(n);
        normals.push_back(len > 0 ? n / len : Vec3(0, 0, 1));
      }
    }
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(m.scene, g, static_cast<unsigned>(i));
    rtcReleaseGeometry(g);
  }
  rtcCommitScene(m.scene);
  if (rtcGetDeviceError(m.device) != RTC_ERROR_NONE)
    throw RuntimeError("Embree failed to build the scene's acceleration structure");
  if (desc.shapes.empty()) {
    m.lo = Vec3(-0.5);
    m.hi = Vec3(0.5);
  }
  if (closed_form_cells) find_empty_cells(desc);
}

void Geometry::find_empty_cells(const SceneDesc& desc) {
  Impl& m = *impl_;
  const size_t n = desc.shapes.size();
  std::vector<Vec3> lo(n), hi(n);
  for (size_t i = 0; i < n; ++i) {
    const ShapeDesc& sh = desc.shapes[i];
    if (sh.type == ShapeDesc::Type::Sphere) {
      lo[i] = sh.center - Vec3(sh.radius);
      hi[i] = sh.center + Vec3(sh.radius);
    } else {
      lo[i] = Vec3(std::numeric_limits<double>::infinity());
      hi[i] = Vec3(-std::numeric_limits<double>::infinity());
      for (const Vec3& v : sh.vertices) lo[i] = vmin(lo[i], v), hi[i] = vmax(hi[i], v);
    }
  }
  for (size_t i = 0; i < n && m.cells.size() < kMaxEmptyCells; ++i) {
    const ShapeDesc& sh = desc.shapes[i];
    EmptyCell c;
    c.shape = static_cast<int>(i);
    if (sh.type == ShapeDesc::Type::Sphere) {
      c.sphere = true;
      c.sp = {sh.center, sh.radius};
    } else if (sh.type == ShapeDesc::Type::Box && sh.vertices.size() == 8 &&
               sh.triangles.size() == 12) {
      c.lo = lo[i];
      c.hi = hi[i];
      bool aligned = true;  // every corner on the bounds: an axis-aligned box
      for (const Vec3& v : sh.vertices)
        aligned = aligned && (v.x == c.lo.x || v.x == c.hi.x) && (v.y == c.lo.y || v.y == c.hi.y) &&
                  (v.z == c.lo.z || v.z == c.hi.z);
      const auto& normals = m.tri_normals[i];
      for (size_t k = 0; k < normals.size() && aligned; ++k) {
        const Vec3& nk = normals[k];
        const int axis = std::abs(nk.x) == 1.0 ? 0 : (std::abs(nk.y) == 1.0 ? 1 : 2);
        const double comp = axis == 0 ? nk.x : (axis == 1 ? nk.y : nk.z);
        if (std::abs(comp) != 1.0) aligned = false;
        int& slot = c.prim[axis][comp > 0 ? 1 : 0];
        if (slot < 0) slot = static_cast<int>(k);
      }
      for (int a = 0; a < 3 && aligned; ++a) aligned = c.prim[a][0] >= 0 && c.prim[a][1] >= 0;
      if (!aligned) continue;
    } else {
      continue;
    }
    // Empty: no other shape's bounds touch this one's (padded against rounding).
    const Vec3 clo = lo[i], chi = hi[i];
    const Vec3 far = vmax(Vec3(std::abs(clo.x), std::abs(clo.y), std::abs(clo.z)),
                         Vec3(std::abs(chi.x), std::abs(chi.y), std::abs(chi.z)));
    const double pad = 1e-6 * (length(chi - clo) + length(far));
    bool empty = true;
    for (size_t j = 0; j < n && empty; ++j) {
      if (j == i) continue;
      const bool apart = lo[j].x > chi.x + pad || hi[j].x < clo.x - pad || lo[j].y > chi.y + pad ||
                         hi[j].y < clo.y - pad || lo[j].z > chi.z + pad || hi[j].z < clo.z - pad;
      empty = apart;
    }
    if (empty) m.cells.push_back(c);
  }
  // Only where every shape is such a cell (separate boxes and spheres: fog banks, blocks of
  // tissue, lamps): there a ray outside them often meets nothing; in a room of walls a ray always
  // meets one, and the test would only add its cost.
  if (n > 0 && m.cells.size() == n) {
    m.box_lo = lo;
    m.box_hi = hi;
    for (size_t i = 0; i < n; ++i)
      m.extent = std::max({m.extent, std::abs(lo[i].x), std::abs(lo[i].y), std::abs(lo[i].z),
                           std::abs(hi[i].x), std::abs(hi[i].y), std::abs(hi[i].z)});
  }
}

bool Geometry::Impl::misses_bounds(const Ray& ray, double s_min, double s_max) const {
  if (box_lo.empty()) return false;
  // Embree intersects in float: vertices, origin and direction rounded (about 6e-8 of the
  // coordinates each, and of the distance travelled); 1e-6 of the largest coordinate covers that
  // with room, and stays below the tracer's ray epsilon (2e-6 of the scene's extent).
  const Vec3& o = ray.o;
  const double far = std::max({extent, std::abs(o.x), std::abs(o.y), std::abs(o.z)});
  const double pad = 1e-6 * far;
  const double oa[3] = {o.x, o.y, o.z}, da[3] = {ray.d.x, ray.d.y, ray.d.z};
  for (size_t i = 0; i < box_lo.size(); ++i) {
    const double la[3] = {box_lo[i].x, box_lo[i].y, box_lo[i].z};
    const double ha[3] = {box_hi[i].x, box_hi[i].y, box_hi[i].z};
    double t0 = s_min, t1 = s_max;
    for (int a = 0; a < 3 && t0 <= t1; ++a) {
      const double s_lo = la[a] - pad, s_hi = ha[a] + pad;
      if (da[a] == 0.0) {
        if (oa[a] < s_lo || oa[a] > s_hi) t1 = -1.0, t0 = 0.0;  // parallel and outside the slab
        continue;
      }
      const double inv = 1.0 / da[a];
      double ta = (s_lo - oa[a]) * inv, tb = (s_hi - oa[a]) * inv;
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
    }
    if (t0 <= t1) return false;  // this shape's bounds are crossed: Embree decides
  }
  return true;
}

int Geometry::Impl::inside_hit(const Ray& ray, double s_min, double s_max,
                               SurfaceHit* hit) const {
  for (const EmptyCell& c : cells) {
    double s;
    int prim = 0;
    if (c.sphere) {
      const Vec3 oc = ray.o - c.sp.center;
      if (!(dot(oc, oc) < c.sp.radius * c.sp.radius)) continue;
      const double b = dot(oc, ray.d);
      const Vec3 perp = oc - ray.d * b;
      const double disc = c.sp.radius * c.sp.radius - dot(perp, perp);
      if (!(disc >= 0)) return -1;
      s = -b + std::sqrt(disc);  // the far root: the origin is inside
    } else {
      const Vec3& o = ray.o;
      if (!(o.x > c.lo.x && o.x < c.hi.x && o.y > c.lo.y && o.y < c.hi.y && o.z > c.lo.z &&
            o.z < c.hi.z))
        continue;
      s = std::numeric_limits<double>::infinity();
      int axis = -1, side = 0;
      const double oa[3] = {o.x, o.y, o.z}, da[3] = {ray.d.x, ray.d.y, ray.d.z};
      const double la[3] = {c.lo.x, c.lo.y, c.lo.z}, ha[3] = {c.hi.x, c.hi.y, c.hi.z};
      for (int a = 0; a < 3; ++a) {
        if (da[a] == 0.0) continue;
        const int sd = da[a] > 0 ? 1 : 0;
        const double t = ((sd ? ha[a] : la[a]) - oa[a]) / da[a];
        if (t < s) s = t, axis = a, side = sd;
      }
      if (axis < 0) return -1;
      prim = c.prim[axis][side];
    }
    // Inside a cell only its own surface can be met; an exit at or before s_min would need
    // what lies beyond it.
    if (!(s > s_min)) return -1;
    if (!(s < s_max)) return 0;
    if (hit) {
      hit->shape = c.shape;
      hit->prim = prim;
      hit->s = s;
      hit->p = ray.at(s);
      hit->ng = c.sphere ? normalize(hit->p - c.sp.center)
                         : tri_normals[static_cast<size_t>(c.shape)][static_cast<size_t>(prim)];
    }
    return 1;
  }
  return -1;
}

Geometry::~Geometry() {
  if (impl_) {
    if (impl_->scene) rtcReleaseScene(impl_->scene);
    if (impl_->device) rtcReleaseDevice(impl_->device);
  }
}

Vec3 Geometry::bounds_min() const { return impl_->lo; }
Vec3 Geometry::bounds_max() const { return impl_->hi; }

bool Geometry::occluded(const Ray& ray, double s_min, double s_max) const {
  const int fast = impl_->inside_hit(ray, s_min, s_max, nullptr);
  if (fast >= 0) return fast == 1;
  if (impl_->misses_bounds(ray, s_min, s_max)) return false;
  FemtoContext ctx;
  rtcInitIntersectContext(&ctx.rtc);
  ctx.o = ray.o;
  ctx.d = ray.d;
  RTCRay r;
  r.org_x = static_cast<float>(ray.o.x);
  r.org_y = static_cast<float>(ray.o.y);
  r.org_z = static_cast<float>(ray.o.z);
  r.dir_x = static_cast<float>(ray.d.x);
  r.dir_y = static_cast<float>(ray.d.y);
  r.dir_z = static_cast<float>(ray.d.z);
  r.tnear = static_cast<float>(s_min);
  r.tfar = s_max < 3e38 ? static_cast<float>(s_max) : std::numeric_limits<float>::infinity();
  r.time = 0.0f;
  r.mask = 0xFFFFFFFFu;
  r.id = 0;
  r.flags = 0;
  rtcOccluded1(impl_->scene, &ctx.rtc, &r);
  return r.tfar < 0.0f;
}

bool Geometry::intersect(const Ray& ray, double s_min, double s_max, SurfaceHit& hit) const {
  const int fast = impl_->inside_hit(ray, s_min, s_max, &hit);
  if (fast >= 0) return fast == 1;
  if (impl_->misses_bounds(ray, s_min, s_max)) return false;
  FemtoContext ctx;
  rtcInitIntersectContext(&ctx.rtc);
  ctx.o = ray.o;
  ctx.d = ray.d;
  RTCRayHit rh;
  rh.ray.org_x = static_cast<float>(ray.o.x);
  rh.ray.org_y = static_cast<float>(ray.o.y);
  rh.ray.org_z = static_cast<float>(ray.o.z);
  rh.ray.dir_x = static_cast<float>(ray.d.x);
  rh.ray.dir_y = static_cast<float>(ray.d.y);
  rh.ray.dir_z = static_cast<float>(ray.d.z);
  rh.ray.tnear = static_cast<float>(s_min);
  rh.ray.tfar = s_max < 3e38 ? static_cast<float>(s_max) : std::numeric_limits<float>::infinity();
  rh.ray.time = 0.0f;
  rh.ray.mask = 0xFFFFFFFFu;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &ctx.rtc, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  const int shape = static_cast<int>(rh.hit.geomID);
  const ShapeDesc& sh = *impl_->shapes[static_cast<size_t>(shape)];
  hit.shape = shape;
  hit.prim = static_cast<int>(rh.hit.primID);
  if (sh.type == ShapeDesc::Type::Sphere) {
    // Re-solve in double precision: Embree's tfar is float.
    const SphereData& sp = impl_->spheres[static_cast<size_t>(shape)];
    double s = rh.ray.tfar;
    if (!intersect_sphere(sp, ray.o, ray.d, s_min, s_max, s)) s = rh.ray.tfar;
    hit.s = s;
    hit.p = ray.at(s);
    hit.ng = normalize(hit.p - sp.center);
  } else {
    hit.s = rh.ray.tfar;
    hit.p = ray.at(hit.s);
    hit.ng = impl_->tri_normals[static_cast<size_t>(shape)][static_cast<size_t>(hit.prim)];
  }
  return true;
}

}  // namespace femto
