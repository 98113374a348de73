#include "core/tissue/scene.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>

#include "core/constants.h"
#include "core/error.h"
#include "core/io/nifti.h"
#include "core/scene_json/shape_builders.h"
#include "media/label_grid_vdb.h"
#include "media/volume_data.h"

namespace femto::tissue {

namespace {
using Json = nlohmann::json;
using Keys = std::vector<std::string>;
constexpr double kMaxCells = 268435456.0;  // 2^28 label voxels (512 MiB of labels)
constexpr double kMaxTallyCells =
    68719476736.0;  // 2^36 fluence cells x gates: bounds every size computation
constexpr int kMaxLabel = 65535;
constexpr int kMaxNesting = 64;  // JSON depth, as for camera scenes

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string show(const Json& v) {
  if (v.is_string()) return clip(Json(clip(v.get<std::string>(), 200)).dump());
  return clip(v.dump());
}

// Reads one JSON object strictly: every key must be used, every value checked.
class Reader {
 public:
  Reader(std::string source, std::string base)
      : source_(std::move(source)), base_(std::move(base)) {}

  std::string where(const std::string& path) const { return clip(source_, 200) + ": " + path; }
  [[noreturn]] void fail(const std::string& path, const std::string& problem) const {
    throw InputError(clip(source_, 200) + ": " + path + ": " + problem);
  }
  [[noreturn]] void fail(const std::string& path, const std::string& problem,
                         const Json& got) const {
    fail(path, problem + " (got " + show(got) + ")");
  }

  const Json& object(const Json& j, const std::string& path, const Keys& allowed) const {
    if (!j.is_object()) fail(path, "must be an object", j);
    for (auto it = j.begin(); it != j.end(); ++it) {
      bool ok = false;
      for (const auto& k : allowed) ok = ok || k == it.key();
      if (!ok) {
        std::string list;
        for (const auto& k : allowed) list += (list.empty() ? "'" : ", '") + k + "'";
        fail(path + "/" + clip(it.key(), 40), "unknown key (expected one of " + list + ")");
      }
    }
    return j;
  }
  double number(const Json& j, const std::string& path, double lo, double hi, bool lo_open = false,
                bool hi_open = false) const {
    if (!j.is_number()) fail(path, "must be a number", j);
    const double x = j.get<double>();
    const bool ok =
        std::isfinite(x) && (lo_open ? x > lo : x >= lo) && (hi_open ? x < hi : x <= hi);
    if (!ok) {
      std::string range = hi == kInf ? std::string(lo_open ? "must be > " : "must be >= ") + fmt(lo)
                                     : std::string("must be in ") + (lo_open ? "(" : "[") +
                                           fmt(lo) + ", " + fmt(hi) + (hi_open ? ")" : "]");
      fail(path, range, j);
    }
    return x;
  }
  int64_t integer(const Json& j, const std::string& path, double lo, double hi) const {
    const double x = number(j, path, lo, hi);
    if (x != std::floor(x)) fail(path, "must be a whole number", j);
    return static_cast<int64_t>(x);
  }
  Vec3 vec3(const Json& j, const std::string& path, bool nonzero = false) const {
    if (!j.is_array() || j.size() != 3) fail(path, "must be [x, y, z]", j);
    Vec3 v;
    for (int i = 0; i < 3; ++i)
      v[i] = number(j[static_cast<size_t>(i)], path + "/" + std::to_string(i), -1e9, 1e9);
    if (nonzero && !(length(v) > 0)) fail(path, "must not be the zero vector", j);
    return v;
  }
  std::array<int, 3> ints3(const Json& j, const std::string& path, int lo, int hi) const {
    if (!j.is_array() || j.size() != 3) fail(path, "must be [nx, ny, nz]", j);
    std::array<int, 3> v{};
    for (size_t i = 0; i < 3; ++i)
      v[i] = static_cast<int>(integer(j[i], path + "/" + std::to_string(i), lo, hi));
    return v;
  }
  std::string string(const Json& j, const std::string& path, const Keys& options = {}) const {
    if (!j.is_string()) fail(path, "must be a string", j);
    const std::string s = j.get<std::string>();
    if (options.empty()) return s;
    for (const auto& o : options)
      if (o == s) return s;
    std::string list;
    for (const auto& o : options) list += (list.empty() ? "\"" : ", \"") + o + "\"";
    fail(path, "must be one of " + list, j);
  }
  bool boolean(const Json& j, const std::string& path) const {
    if (!j.is_boolean()) fail(path, "must be true or false", j);
    return j.get<bool>();
  }
  std::string file(const Json& j, const std::string& path) const {
    const std::string f = string(j, path);
    if (f.empty()) fail(path, "must name a file", j);
    const std::filesystem::path p(f);
    return p.is_absolute() || base_.empty() ? f : (std::filesystem::path(base_) / p).string();
  }

 private:
  std::string source_, base_;
};

Json parse_strict(const std::string& text, const std::string& source) {
  // Duplicate keys are errors (nlohmann keeps the last one silently).
  std::vector<std::set<std::string>> keys;
  const Json::parser_callback_t cb = [&](int depth, Json::parse_event_t ev, Json& parsed) {
    if ((ev == Json::parse_event_t::object_start || ev == Json::parse_event_t::array_start) &&
        depth >= kMaxNesting)
      throw InputError(clip(source, 200) + ": values are nested more than " +
                       std::to_string(kMaxNesting) +
                       " levels deep; a tissue scene needs far fewer");
    if (ev == Json::parse_event_t::object_start) keys.emplace_back();
    if (ev == Json::parse_event_t::object_end) keys.pop_back();
    if (ev == Json::parse_event_t::key && !keys.back().insert(parsed.get<std::string>()).second)
      throw InputError(clip(source, 200) + ": duplicate key '" + clip(parsed.get<std::string>()) +
                       "'");
    return true;
  };
  try {
    return Json::parse(text, cb, true, true);
  } catch (const InputError&) {
    throw;
  } catch (const nlohmann::json::exception& e) {
    throw InputError(clip(source, 200) + ": not valid JSON (" + clip(e.what(), 200) + ")");
  }
}

void read_volume(const Reader& rd, const Json& j, const std::string& P, Setup& s) {
  rd.object(j, P, {"shape", "fill", "voxel", "origin", "nifti", "vdb", "grid"});
  const int sources =
      (j.contains("fill") ? 1 : 0) + (j.contains("nifti") ? 1 : 0) + (j.contains("vdb") ? 1 : 0);
  if (sources != 1)
    rd.fail(P, "needs exactly one of \"fill\" (with \"shape\"), \"nifti\" or \"vdb\"", j);
  LabelVolume& v = s.volume;
  std::vector<uint16_t>& labels = v.labels;
  if (j.contains("fill")) {
    if (!j.contains("shape")) rd.fail(P + "/shape", "required with \"fill\"");
    if (!j.contains("voxel")) rd.fail(P + "/voxel", "required with \"fill\"");
    const auto n = rd.ints3(j["shape"], P + "/shape", 1, 100000);
    const int label = static_cast<int>(rd.integer(j["fill"], P + "/fill", 1, kMaxLabel));
    double cells = 1;
    for (int a = 0; a < 3; ++a)
      v.n[a] = n[static_cast<size_t>(a)], cells *= n[static_cast<size_t>(a)];
    if (cells > kMaxCells) rd.fail(P + "/shape", "more than 2^28 voxels", j["shape"]);
    labels.assign(static_cast<size_t>(cells), static_cast<uint16_t>(label));
  } else if (j.contains("nifti")) {
    for (const char* k : {"shape", "grid"})
      if (j.contains(k)) rd.fail(P + "/" + k, "applies to \"fill\" / \"vdb\" volumes only");
    const std::string path = rd.file(j["nifti"], P + "/nifti");
    NiftiVolume nv;
    try {
      nv = read_nifti(path);
    } catch (const InputError& e) {
      rd.fail(P + "/nifti", e.what());
    }
    if (nv.dim[3] != 1)
      rd.fail(P + "/nifti", path + ": a label volume has 3 dimensions (dim[4] = " +
                                std::to_string(nv.dim[3]) + ")");
    double cells = 1;
    for (int a = 0; a < 3; ++a) v.n[a] = nv.dim[static_cast<size_t>(a)], cells *= v.n[a];
    if (cells > kMaxCells) rd.fail(P + "/nifti", path + ": more than 2^28 voxels");
    if (!j.contains("voxel")) {
      const auto& pd = nv.pixdim;
      if (!(pd[0] > 0) || std::abs(pd[0] - pd[1]) > 1e-6 * pd[0] ||
          std::abs(pd[0] - pd[2]) > 1e-6 * pd[0])
        rd.fail(P + "/nifti", path + ": voxels are " + fmt(pd[0]) + " x " + fmt(pd[1]) + " x " +
                                  fmt(pd[2]) + " mm; cubic voxels are needed (or give \"voxel\")");
      v.voxel = pd[0];
    }
    // NIfTI is x fastest; the label grid is z fastest.
    labels.resize(static_cast<size_t>(cells));
    for (int i = 0; i < v.n[0]; ++i)
      for (int jj = 0; jj < v.n[1]; ++jj)
        for (int k = 0; k < v.n[2]; ++k) {
          const double x = nv.data[(static_cast<size_t>(k) * v.n[1] + jj) * v.n[0] + i];
          if (x != std::floor(x) || x < 0 || x > kMaxLabel)
            rd.fail(P + "/nifti", path + ": voxel (" + std::to_string(i) + ", " +
                                      std::to_string(jj) + ", " + std::to_string(k) + ") holds " +
                                      fmt(x) + "; labels are whole numbers 0 to 65535");
          labels[v.index(i, jj, k)] = static_cast<uint16_t>(x);
        }
  } else {
    if (j.contains("shape")) rd.fail(P + "/shape", "applies to \"fill\" volumes only");
    const std::string path = rd.file(j["vdb"], P + "/vdb");
    const std::string grid = j.contains("grid") ? rd.string(j["grid"], P + "/grid") : "labels";
    const LabelGridData d = read_vdb_labels(path, grid, rd.where(P + "/vdb"));
    for (int a = 0; a < 3; ++a) v.n[a] = d.n[static_cast<size_t>(a)];
    v.voxel = d.voxel;
    v.origin = d.origin;
    labels.resize(d.labels.size());
    for (size_t i = 0; i < labels.size(); ++i) {
      if (d.labels[i] < 0 || d.labels[i] > kMaxLabel)
        rd.fail(P + "/vdb",
                path + ": label " + std::to_string(d.labels[i]) + " is outside 0 to 65535");
      labels[i] = static_cast<uint16_t>(d.labels[i]);
    }
  }
  if (j.contains("voxel")) v.voxel = rd.number(j["voxel"], P + "/voxel", 1e-6, 1e6);
  if (j.contains("origin")) v.origin = rd.vec3(j["origin"], P + "/origin");
}

void read_labels(const Reader& rd, const Json& j, const std::string& P, double outside_n,
                 Setup& s) {
  if (!j.is_array() || j.empty())
    rd.fail(P, "must be a non-empty array of {\"label\", \"mu_a\", \"mu_s\", \"g\", \"n\"}", j);
  std::vector<bool> given;
  std::vector<TissueOptics>& optics = s.volume.optics;
  for (size_t i = 0; i < j.size(); ++i) {
    const std::string Q = P + "/" + std::to_string(i);
    const Json& e = rd.object(j[i], Q, {"label", "mu_a", "mu_s", "g", "n"});
    for (const char* k : {"label", "mu_a", "mu_s", "g", "n"})
      if (!e.contains(k)) rd.fail(Q + "/" + k, "required");
    const size_t label = static_cast<size_t>(rd.integer(e["label"], Q + "/label", 1, kMaxLabel));
    if (label >= optics.size()) optics.resize(label + 1), given.resize(label + 1, false);
    if (given[label]) rd.fail(Q + "/label", "label given twice", e["label"]);
    given[label] = true;
    TissueOptics& o = optics[label];
    o.mu_a = rd.number(e["mu_a"], Q + "/mu_a", 0, 1e6);
    o.mu_s = rd.number(e["mu_s"], Q + "/mu_s", 0, 1e6);
    o.g = rd.number(e["g"], Q + "/g", -1, 1, true, true);
    o.n = rd.number(e["n"], Q + "/n", 1, 10);
  }
  optics[0] = TissueOptics{0, 0, 0, outside_n};
  // Every label in the volume needs its optics.
  std::vector<bool> seen(65536, false);
  for (uint16_t l : s.volume.labels) seen[l] = true;
  for (size_t l = 1; l < seen.size(); ++l)
    if (seen[l] && (l >= given.size() || !given[l]))
      rd.fail(P, "label " + std::to_string(l) +
                     " occurs in the volume but has no optical properties here");
}

// A voxel medium (OpenVDB density/albedo/eta grids, the keys of a camera scene's "vdb" medium)
// as the tissue: each voxel gets its own mu_a, mu_s and n; every voxel has label 1.
void read_medium(const Reader& rd, const Json& j, const std::string& P, double outside_n,
                 const std::string& source, Setup& s) {
  rd.object(j, P,
            {"type", "file", "density_grid", "sigma_t_scale", "albedo", "albedo_grid", "eta",
             "eta_grid", "g", "interpolation"});
  if (j.contains("type")) rd.string(j["type"], P + "/type", {"vdb"});
  for (const char* k : {"file", "sigma_t_scale"})
    if (!j.contains(k)) rd.fail(P + "/" + k, "required");
  VdbMediumDesc d;
  d.file = rd.file(j["file"], P + "/file");
  if (j.contains("density_grid")) d.density_grid = rd.string(j["density_grid"], P + "/density_grid");
  d.sigma_t_scale = rd.number(j["sigma_t_scale"], P + "/sigma_t_scale", 0, 1e6, true);
  if (j.contains("albedo") && j.contains("albedo_grid"))
    rd.fail(P + "/albedo", "give \"albedo\" or \"albedo_grid\", not both");
  if (j.contains("albedo")) d.albedo = rd.number(j["albedo"], P + "/albedo", 0, 1);
  if (j.contains("albedo_grid")) d.albedo_grid = rd.string(j["albedo_grid"], P + "/albedo_grid");
  if (j.contains("eta")) d.eta = rd.number(j["eta"], P + "/eta", 1, 10);
  if (j.contains("eta_grid")) d.eta_grid = rd.string(j["eta_grid"], P + "/eta_grid");
  const double g = j.contains("g") ? rd.number(j["g"], P + "/g", -1, 1, true, true) : 0.0;
  if (j.contains("interpolation") &&
      rd.string(j["interpolation"], P + "/interpolation", {"nearest", "trilinear"}) != "nearest")
    rd.fail(P + "/interpolation",
            "tissue volumes are voxel-constant: only \"nearest\" applies here", j["interpolation"]);
  d.interpolation = VdbMediumDesc::Interpolation::Nearest;
  d.storage = VdbMediumDesc::Storage::Dense;  // the walk reads every voxel's optics
  d.max_dense_bytes = static_cast<uint64_t>(kMaxCells) * 3 * sizeof(float);
  const VolumeData data = load_volume(d, source, P);
  // The walk's voxels are cubes along the world axes.
  const double* M = data.grid_to_world;
  const double h = M[0];
  const bool diagonal = M[1] == 0 && M[2] == 0 && M[4] == 0 && M[6] == 0 && M[8] == 0 && M[9] == 0;
  if (!diagonal || !(h > 0) || std::abs(M[5] - h) > 1e-9 * h || std::abs(M[10] - h) > 1e-9 * h)
    rd.fail(P + "/file", d.file + ": voxels of " + fmt(data.voxel_size[0]) + " x " +
                             fmt(data.voxel_size[1]) + " x " + fmt(data.voxel_size[2]) +
                             " mm" + (diagonal ? "" : ", rotated or sheared,") +
                             " in the file's transform; a tissue needs cubic voxels along the "
                             "world axes");
  LabelVolume& v = s.volume;
  v.n[0] = data.density.nx, v.n[1] = data.density.ny, v.n[2] = data.density.nz;
  if (static_cast<double>(v.n[0]) * v.n[1] * v.n[2] > kMaxCells)
    rd.fail(P + "/file", d.file + ": more than 2^28 voxels");
  v.voxel = h;
  v.origin = Vec3(M[3], M[7], M[11]);
  v.labels.assign(v.cells(), 1);
  v.voxel_optics.resize(v.cells());
  double mu_a_sum = 0, mu_s_sum = 0;
  for (int i = 0; i < v.n[0]; ++i)
    for (int jj = 0; jj < v.n[1]; ++jj)
      for (int k = 0; k < v.n[2]; ++k) {
        const size_t src = data.density.index(i, jj, k);  // x fastest; the labels: z fastest
        const double mu_t = d.sigma_t_scale * data.density.v[src];
        const double a = data.albedo.empty() ? d.albedo : data.albedo.v[src];
        const double n = data.eta.empty() ? d.eta : data.eta.v[src];
        VoxelOptics& o = v.voxel_optics[v.index(i, jj, k)];
        o.mu_s = static_cast<float>(a * mu_t);
        o.mu_a = static_cast<float>(mu_t - a * mu_t);
        o.n = static_cast<float>(n);
        mu_a_sum += o.mu_a, mu_s_sum += o.mu_s;
      }
  // Label 1 names the whole medium; its table entry carries g and the mean coefficients.
  const double cells = static_cast<double>(v.cells());
  v.optics = {TissueOptics{0, 0, 0, outside_n},
              TissueOptics{mu_a_sum / cells, mu_s_sum / cells, g, d.eta}};
}

// The keys of box and mesh sources (the camera scenes' box and mesh shapes, without transforms).
void read_surface_source(const Reader& rd, const Json& j, const std::string& P,
                         const std::string& type, Source& src) {
  const bool box = src.type == Source::Type::Box, mesh = src.type == Source::Type::Mesh;
  for (const char* k : {"min", "max"}) {
    if (box && !j.contains(k)) rd.fail(P + "/" + k, "required for a box source (mm)");
    if (!box && j.contains(k)) rd.fail(P + "/" + k, "applies to box sources only");
  }
  if (box) {
    src.box_min = rd.vec3(j["min"], P + "/min");
    src.box_max = rd.vec3(j["max"], P + "/max");
    const Vec3 lo = src.box_min, hi = src.box_max;
    if (!(hi.x > lo.x && hi.y > lo.y && hi.z > lo.z))
      rd.fail(P + "/max", "must exceed 'min' on every axis", j["max"]);
  }
  if (mesh != j.contains("file"))
    rd.fail(P + "/file", mesh ? "required for a mesh source (an OBJ or PLY file, mm)"
                              : "applies to mesh sources only");
  if (!mesh) return;
  const std::string path = rd.file(j["file"], P + "/file");
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    rd.fail(P + "/file", "mesh file not found: " + clip(path, 200), j["file"]);
  ShapeDesc mesh_shape;
  try {
    scene_json::load_mesh_file(path, mesh_shape);
  } catch (const InputError& e) {
    rd.fail(P + "/file", e.what());
  }
  src.mesh_vertices = std::move(mesh_shape.vertices);
  src.mesh_triangles = std::move(mesh_shape.triangles);
  double area = 0;
  for (const auto& t : src.mesh_triangles)
    area += length(cross(src.mesh_vertices[t[1]] - src.mesh_vertices[t[0]],
                         src.mesh_vertices[t[2]] - src.mesh_vertices[t[0]]));
  if (!(area > 0)) rd.fail(P + "/file", "the " + type + " has no area", j["file"]);
}

void read_source(const Reader& rd, const Json& j, const std::string& P, Source& src) {
  rd.object(j, P,
            {"type", "position", "direction", "waist", "radius", "cone_angle", "falloff_start",
             "edge1", "edge2", "min", "max", "file", "pulse", "specular"});
  if (!j.contains("type")) rd.fail(P + "/type", "required");
  const std::string type = rd.string(
      j["type"], P + "/type",
      {"pencil", "gaussian", "disk", "isotropic", "spot", "sphere", "quad", "box", "mesh"});
  src.type = type == "pencil"     ? Source::Type::Pencil
             : type == "gaussian" ? Source::Type::Gaussian
             : type == "disk"     ? Source::Type::Disk
             : type == "spot"     ? Source::Type::Spot
             : type == "sphere"   ? Source::Type::Sphere
             : type == "quad"     ? Source::Type::Quad
             : type == "box"      ? Source::Type::Box
             : type == "mesh"     ? Source::Type::Mesh
                                  : Source::Type::Isotropic;
  const bool placed = src.type != Source::Type::Box && src.type != Source::Type::Mesh;
  if (placed) {
    if (!j.contains("position")) rd.fail(P + "/position", "required");
    src.position = rd.vec3(j["position"], P + "/position");
  } else if (j.contains("position")) {
    rd.fail(P + "/position",
            "a " + type + " source has no position (" +
                (src.type == Source::Type::Box ? "'min' and 'max'" : "its 'file'") + " place it)");
  }
  read_surface_source(rd, j, P, type, src);
  const bool surface = is_surface(src.type);
  if (src.type == Source::Type::Isotropic || surface) {
    if (j.contains("direction"))
      rd.fail(P + "/direction",
              surface ? "a " + type + " source has no direction (it emits from its surface)"
                      : std::string("an isotropic source has no direction"));
  } else {
    if (!j.contains("direction")) rd.fail(P + "/direction", "required for a " + type + " source");
    src.direction = normalize(rd.vec3(j["direction"], P + "/direction", true));
  }
  if (src.type == Source::Type::Gaussian) {
    if (!j.contains("waist"))
      rd.fail(P + "/waist", "required for a gaussian source (1/e^2 radius, mm)");
    src.waist = rd.number(j["waist"], P + "/waist", 0, 1e6, true);
  } else if (j.contains("waist")) {
    rd.fail(P + "/waist", "applies to gaussian sources only");
  }
  if (src.type == Source::Type::Disk || src.type == Source::Type::Sphere) {
    if (!j.contains("radius")) rd.fail(P + "/radius", "required for a " + type + " source (mm)");
    src.radius = rd.number(j["radius"], P + "/radius", 0, 1e6, true);
  } else if (j.contains("radius")) {
    rd.fail(P + "/radius", "applies to disk and sphere sources only");
  }
  if (src.type == Source::Type::Quad) {  // the keys of the camera scenes' quad
    for (const char* k : {"edge1", "edge2"})
      if (!j.contains(k)) rd.fail(P + "/" + k, "required for a quad source (mm)");
    src.edge1 = rd.vec3(j["edge1"], P + "/edge1", true);
    src.edge2 = rd.vec3(j["edge2"], P + "/edge2", true);
    if (!(length(cross(src.edge1, src.edge2)) > 1e-12 * length(src.edge1) * length(src.edge2)))
      rd.fail(P + "/edge2", "parallel to edge1: the quad has no area", j["edge2"]);
  } else {
    for (const char* k : {"edge1", "edge2"})
      if (j.contains(k)) rd.fail(P + "/" + k, "applies to quad sources only");
  }
  if (src.type == Source::Type::Spot) {  // the keys and defaults of the camera scenes' spot light
    if (!j.contains("cone_angle"))
      rd.fail(P + "/cone_angle", "required for a spot source (degrees)");
    src.cone_angle_deg = rd.number(j["cone_angle"], P + "/cone_angle", 0, 90, true);
    src.falloff_start_deg = 0.8 * src.cone_angle_deg;
    if (j.contains("falloff_start"))
      src.falloff_start_deg =
          rd.number(j["falloff_start"], P + "/falloff_start", 0, src.cone_angle_deg);
  } else {
    for (const char* k : {"cone_angle", "falloff_start"})
      if (j.contains(k)) rd.fail(P + "/" + k, "applies to spot sources only");
  }
  if (j.contains("pulse")) {
    const Json& pl = rd.object(j["pulse"], P + "/pulse", {"fwhm", "offset"});
    if (pl.contains("fwhm")) src.fwhm_ps = rd.number(pl["fwhm"], P + "/pulse/fwhm", 0, 1e9);
    if (pl.contains("offset"))
      src.offset_ps = rd.number(pl["offset"], P + "/pulse/offset", -1e9, 1e9);
  }
  if (j.contains("specular")) src.specular = rd.boolean(j["specular"], P + "/specular");
}
}  // namespace

bool is_tissue_scene(const std::string& text) {
  // Deeply nested values would make freeing the parsed value recurse past the stack.
  struct TooDeep {};
  const Json::parser_callback_t cb = [](int depth, Json::parse_event_t ev, Json&) {
    if ((ev == Json::parse_event_t::object_start || ev == Json::parse_event_t::array_start) &&
        depth >= kMaxNesting)
      throw TooDeep{};
    return true;
  };
  try {
    const Json j = Json::parse(text, cb, false, true);
    return j.is_object() && j.contains("tissue");
  } catch (const TooDeep&) {
    return false;  // the scene loader reports it
  }
}

Setup load_tissue_scene(const std::string& text, const std::string& source,
                        const std::string& base_dir) {
  const Reader rd(source, base_dir);
  const Json root = parse_strict(text, source);
  rd.object(root, "", {"tissue"});
  const std::string P = "/tissue";
  const Json& t = rd.object(
      root["tissue"], P,
      {"volume", "labels", "medium", "outside_n", "boundary", "absorption", "source", "time", "fluence",
       "faces", "detectors", "detected_photons", "photons", "seed", "batches"});
  for (const char* k : {"source", "time"})
    if (!t.contains(k)) rd.fail(P + "/" + k, "required");
  const double outside_n =
      t.contains("outside_n") ? rd.number(t["outside_n"], P + "/outside_n", 1, 10) : 1.0;
  Setup s;
  if (t.contains("medium")) {  // a voxel medium instead of a labelled volume
    for (const char* k : {"volume", "labels"})
      if (t.contains(k))
        rd.fail(P + "/" + k, "a tissue is either \"medium\" or \"volume\" with \"labels\"");
    read_medium(rd, t["medium"], P + "/medium", outside_n, source, s);
  } else {
    for (const char* k : {"volume", "labels"})
      if (!t.contains(k)) rd.fail(P + "/" + k, "required (or a voxel \"medium\")");
    read_volume(rd, t["volume"], P + "/volume", s);
    s.volume.optics.assign(1, TissueOptics{});
    read_labels(rd, t["labels"], P + "/labels", outside_n, s);
  }
  if (t.contains("boundary"))
    s.fresnel = rd.string(t["boundary"], P + "/boundary", {"fresnel", "matched"}) == "fresnel";
  if (t.contains("absorption"))
    s.absorption =
        rd.string(t["absorption"], P + "/absorption", {"weighted", "analog"}) == "weighted"
            ? Absorption::Weighted
            : Absorption::Analog;
  read_source(rd, t["source"], P + "/source", s.source);

  const Json& tm = rd.object(t["time"], P + "/time", {"t_start", "bin_width", "bins"});
  for (const char* k : {"bin_width", "bins"})
    if (!tm.contains(k)) rd.fail(P + "/time/" + k, "required");
  if (tm.contains("t_start"))
    s.time.t_start_ps = rd.number(tm["t_start"], P + "/time/t_start", -1e9, 1e9);
  s.time.bin_width_ps = rd.number(tm["bin_width"], P + "/time/bin_width", 1e-6, 1e9);
  s.time.bins = static_cast<int>(rd.integer(tm["bins"], P + "/time/bins", 1, 100000));

  // Fluence volume: over the label grid unless given its own grid.
  s.fluence_grid.origin = s.volume.origin;
  for (int a = 0; a < 3; ++a) {
    s.fluence_grid.n[a] = s.volume.n[a];
    s.fluence_grid.size[a] = s.volume.n[a] * s.volume.voxel;
  }
  if (t.contains("fluence")) {
    const Json& f = t["fluence"];
    if (f.is_boolean()) {
      s.fluence = f.get<bool>();
    } else {
      rd.object(f, P + "/fluence", {"resolution", "origin", "size", "stderr"});
      if (f.contains("resolution")) {
        const auto n = rd.ints3(f["resolution"], P + "/fluence/resolution", 1, 100000);
        for (int a = 0; a < 3; ++a) s.fluence_grid.n[a] = n[static_cast<size_t>(a)];
      }
      if (f.contains("origin")) s.fluence_grid.origin = rd.vec3(f["origin"], P + "/fluence/origin");
      if (f.contains("size")) {
        s.fluence_grid.size = rd.vec3(f["size"], P + "/fluence/size");
        for (int a = 0; a < 3; ++a)
          if (!(s.fluence_grid.size[a] > 0))
            rd.fail(P + "/fluence/size", "every extent must be > 0", f["size"]);
      }
      if (f.contains("stderr")) s.fluence_stderr = rd.boolean(f["stderr"], P + "/fluence/stderr");
    }
  }
  if (s.fluence) {
    const double cells =
        static_cast<double>(s.fluence_grid.n[0]) * s.fluence_grid.n[1] * s.fluence_grid.n[2];
    if (cells * s.time.bins > kMaxTallyCells)
      rd.fail(P + "/fluence",
              "a fluence volume of " + fmt(cells) + " voxels x " + std::to_string(s.time.bins) +
                  " gates is above the limit of 2^36 values; lower its resolution or the gates");
  }
  if (t.contains("faces")) s.faces = rd.boolean(t["faces"], P + "/faces");
  if (t.contains("detectors")) {
    const Json& d = t["detectors"];
    if (!d.is_array()) rd.fail(P + "/detectors", "must be an array", d);
    for (size_t i = 0; i < d.size(); ++i) {
      const std::string Q = P + "/detectors/" + std::to_string(i);
      const Json& e = rd.object(d[i], Q, {"position", "radius", "na"});
      for (const char* k : {"position", "radius"})
        if (!e.contains(k)) rd.fail(Q + "/" + k, "required");
      Detector det;
      det.center = rd.vec3(e["position"], Q + "/position");
      det.radius = rd.number(e["radius"], Q + "/radius", 0, 1e6, true);
      if (e.contains("na")) det.na = rd.number(e["na"], Q + "/na", 0, 10, true);
      s.detectors.push_back(det);
    }
  }
  if (t.contains("detected_photons")) {
    const Json& d = rd.object(t["detected_photons"], P + "/detected_photons", {"save", "max"});
    if (d.contains("save")) s.save_detected = rd.boolean(d["save"], P + "/detected_photons/save");
    if (d.contains("max"))
      s.max_detected =
          static_cast<uint64_t>(rd.integer(d["max"], P + "/detected_photons/max", 0, 1e9));
  }
  if (t.contains("photons"))
    s.photons = static_cast<uint64_t>(rd.integer(t["photons"], P + "/photons", 1, 1e12));
  if (t.contains("seed"))
    s.seed = static_cast<uint64_t>(rd.integer(t["seed"], P + "/seed", 0, 9007199254740992.0));
  if (t.contains("batches"))
    s.batches = static_cast<int>(rd.integer(t["batches"], P + "/batches", 1, 1000));
  if (s.fluence_stderr && s.batches < 2)
    rd.fail(P + "/batches", "standard errors (/tissue/fluence/stderr) need at least 2 batches",
            t["batches"]);
  return s;
}

}  // namespace femto::tissue
