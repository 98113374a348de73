// Media: homogeneous and VDB media, their sampling choices, and references to them by name.
#include <filesystem>

#include "core/error.h"
#include "core/scene_json/loader.h"

namespace femto::scene_json {

namespace fs = std::filesystem;

void Loader::media(const Json& v, SceneDesc& scene) const {
  const std::string p = "/media";
  object(v, p);
  const Keys common = {"type",
                       "g",
                       "eta",
                       "distance_sampling",
                       "time_uniform_rate",
                       "mis_heuristic",
                       "connection_sampling",
                       "direction_sampling"};
  const Keys homogeneous = {"sigma_a", "sigma_s"};
  const Keys vdb = {"file",     "density_grid",  "sigma_t_scale", "albedo", "albedo_grid",
                    "eta_grid", "interpolation", "transform",     "storage"};
  for (const auto& item : v.items()) {
    const std::string& name = item.key();
    const std::string mp = at(p, name);
    if (name.empty()) fail(mp, "a medium name must not be empty");
    const Json& o = object(item.value(), mp);
    const std::string type =
        type_of(o, mp, {"homogeneous", "vdb"}, join(common, join(homogeneous, vdb)));
    MediumDesc m;
    m.name = name;
    if (type == "homogeneous") {
      check_keys(o, mp, join(common, homogeneous), "a homogeneous medium", vdb);
      m.medium.sigma_a = number(require(o, mp, "sigma_a"), at(mp, "sigma_a"), at_least(0));
      m.medium.sigma_s = number(require(o, mp, "sigma_s"), at(mp, "sigma_s"), at_least(0));
    } else {
      check_keys(o, mp, join(common, vdb), "a vdb medium", homogeneous);
      m.type = MediumDesc::Type::Vdb;
      vdb_medium(o, mp, m.vdb);
    }
    if (const Json* g = find(o, "g"))
      m.medium.g = number(*g, at(mp, "g"), within(-1, 1, true, true));
    if (const Json* e = find(o, "eta")) m.medium.eta = number(*e, at(mp, "eta"), at_least(1));
    // A VDB medium's constant eta also serves the dielectric-interface check on shapes.
    m.vdb.eta = m.medium.eta;
    distance_sampling(o, mp, m);
    connection_sampling(o, mp, m);
    scene.media.push_back(m);
  }
}

// Keys of a "vdb" medium except the common ones; loading the file happens in load_volume.
void Loader::vdb_medium(const Json& o, const std::string& mp, VdbMediumDesc& d) const {
  const std::string fp = at(mp, "file");
  const Json& jf = require(o, mp, "file");
  const std::string file = string(jf, fp);
  if (file.empty()) fail(fp, "must name a VDB file", jf);
  d.file = resolve(file);
  std::error_code ec;
  if (!fs::is_regular_file(d.file, ec)) fail(fp, "VDB file not found: " + clip(d.file, 200), jf);
  const auto grid_name = [&](const std::string& key) {
    const std::string s = string(o.at(key), at(mp, key));
    if (s.empty()) fail(at(mp, key), "must name a grid", o.at(key));
    return s;
  };
  if (find(o, "density_grid")) d.density_grid = grid_name("density_grid");
  d.sigma_t_scale = number(require(o, mp, "sigma_t_scale"), at(mp, "sigma_t_scale"), above(0));
  const Json* a = find(o, "albedo");
  if (a && find(o, "albedo_grid"))
    fail(at(mp, "albedo_grid"), "give either 'albedo' (a constant) or 'albedo_grid', not both",
         o.at("albedo_grid"));
  if (a) d.albedo = number(*a, at(mp, "albedo"), within(0, 1));
  if (find(o, "albedo_grid")) d.albedo_grid = grid_name("albedo_grid");
  if (find(o, "eta_grid")) d.eta_grid = grid_name("eta_grid");
  if (const Json* i = find(o, "interpolation"))
    d.interpolation = choice(*i, at(mp, "interpolation"), {"nearest", "trilinear"}) == "nearest"
                          ? VdbMediumDesc::Interpolation::Nearest
                          : VdbMediumDesc::Interpolation::Trilinear;
  if (const Json* st = find(o, "storage")) {
    const std::string c = choice(*st, at(mp, "storage"), {"auto", "dense", "sparse"});
    d.storage = c == "dense"    ? VdbMediumDesc::Storage::Dense
                : c == "sparse" ? VdbMediumDesc::Storage::Sparse
                                : VdbMediumDesc::Storage::Auto;
  }
  if (const Json* t = find(o, "transform")) {
    const Transform tf = transform(*t, at(mp, "transform"));
    d.transform = {tf.translate, tf.rotate_deg, tf.scale};
  }
}

// Distance-sampling keys, valid for every medium type.
void Loader::connection_sampling(const Json& o, const std::string& mp, MediumDesc& m) const {
  if (const Json* c = find(o, "connection_sampling")) {
    const std::string v = choice(*c, at(mp, "connection_sampling"),
                                 {"collision", "equiangular", "line_to_point", "mis", "auto"});
    m.connection = v == "collision"       ? ConnectionSampling::Collision
                   : v == "equiangular"   ? ConnectionSampling::Equiangular
                   : v == "line_to_point" ? ConnectionSampling::LineToPoint
                   : v == "mis"           ? ConnectionSampling::Mis
                                          : ConnectionSampling::Auto;
  } else {
    m.connection = ConnectionSampling::Auto;  // the default for scene files (docs/scene-format.md)
  }
  if (const Json* d = find(o, "direction_sampling"))
    m.direction = choice(*d, at(mp, "direction_sampling"), {"phase", "angular"}) == "phase"
                      ? DirectionSampling::Phase
                      : DirectionSampling::Angular;
}

void Loader::distance_sampling(const Json& o, const std::string& mp, MediumDesc& m) const {
  const Json* s = find(o, "distance_sampling");
  if (s) {
    const std::string v =
        choice(*s, at(mp, "distance_sampling"), {"mfp", "time_uniform", "mis", "mixture"});
    m.sampling = v == "mfp"            ? DistanceSampling::Mfp
                 : v == "time_uniform" ? DistanceSampling::TimeUniform
                 : v == "mis"          ? DistanceSampling::Mis
                                       : DistanceSampling::Mixture;
  } else {
    m.sampling = DistanceSampling::Mfp;  // the default for scene files (docs/scene-format.md)
  }
  const std::string uses = std::string("; this medium uses \"") +
                           (m.sampling == DistanceSampling::Mfp           ? "mfp"
                            : m.sampling == DistanceSampling::TimeUniform ? "time_uniform"
                            : m.sampling == DistanceSampling::Mis         ? "mis"
                                                                          : "mixture") +
                           "\"" + (s ? "" : " (the default)");
  if (const Json* r = find(o, "time_uniform_rate")) {
    if (m.sampling == DistanceSampling::Mfp)
      fail(at(mp, "time_uniform_rate"),
           "only applies with \"distance_sampling\": \"time_uniform\", \"mis\" or \"mixture\"" +
               uses,
           *r);
    m.time_uniform_rate = not_tiny(number(*r, at(mp, "time_uniform_rate"), above(0)), kMinRate,
                                   at(mp, "time_uniform_rate"), *r);
  }
  if (const Json* h = find(o, "mis_heuristic")) {
    if (m.sampling != DistanceSampling::Mis)
      fail(at(mp, "mis_heuristic"), "only applies with \"distance_sampling\": \"mis\"" + uses, *h);
    m.mis_heuristic = choice(*h, at(mp, "mis_heuristic"), {"balance", "power"}) == "balance"
                          ? MisHeuristic::Balance
                          : MisHeuristic::Power;
  }
}

int Loader::medium_ref(const Json& v, const std::string& path, const SceneDesc& scene) const {
  const std::string name = string(v, path);
  Keys names;
  for (std::size_t i = 0; i < scene.media.size(); ++i) {
    if (scene.media[i].name == name) return static_cast<int>(i);
    names.push_back(scene.media[i].name);
  }
  if (names.empty()) fail(path, "unknown medium '" + clip(name) + "' (\"media\" defines none)", v);
  fail(path,
       "unknown medium '" + clip(name) + "'" + suggest(name, names) +
           "; defined: " + quoted_list(names),
       v);
}

}  // namespace femto::scene_json
