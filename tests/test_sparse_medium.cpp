// Sparse voxel media (media/sparse_field.h): the same answers as the dense path, the automatic
// choice between them, the memory estimate made before the trees are read, and renders that
// agree bin by bin.
#include <catch2/catch.hpp>

#include <cmath>
#include <iomanip>
#include <vector>

#include "agreement.h"
#include "core/error.h"
#include "core/rng.h"
#include "media/grid_medium.h"
#include "media/volume_data.h"
#include "run_femto.h"
#include "samplers/medium_distance.h"
#include "scene_builders.h"
#include "temp_dir.h"

using namespace femto;
using namespace femto::test;

namespace {

// Random density (about a fifth of the voxels 0, i.e. inactive), albedo and eta over nx x ny x nz
// voxels, optionally with an empty slab x in [empty_from, empty_to) of index `slab_eta`.
struct RandomVolume {
  DenseGrid density, albedo, eta;
};
RandomVolume random_volume(int nx, int ny, int nz, uint64_t seed, int empty_from = 0,
                           int empty_to = 0) {
  RandomVolume v{DenseGrid(nx, ny, nz), DenseGrid(nx, ny, nz), DenseGrid(nx, ny, nz)};
  Rng rng(seed, 7);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const bool empty = i >= empty_from && i < empty_to;
        v.density.at(i, j, k) =
            empty || rng.uniform() < 0.2 ? 0.0f : static_cast<float>(0.05 + 0.4 * rng.uniform());
        v.albedo.at(i, j, k) = static_cast<float>(0.3 + 0.6 * rng.uniform());
        v.eta.at(i, j, k) = empty ? 1.25f : static_cast<float>(1.0 + rng.uniform());
      }
  // The corner voxel is active so that the active box starts at the written offset.
  v.density.at(0, 0, 0) = 0.3f;
  return v;
}

std::string write_random(const std::string& path, const RandomVolume& v, const Vec3& index_offset,
                         double voxel = 0.7) {
  std::vector<VdbGridSpec> specs;
  const char* names[3] = {"density", "albedo", "eta"};
  const DenseGrid* grids[3] = {&v.density, &v.albedo, &v.eta};
  for (int g = 0; g < 3; ++g) {
    VdbGridSpec s;
    s.name = names[g];
    s.values = grids[g];
    s.voxel_mm = Vec3(voxel);
    s.index_offset = index_offset;
    s.origin_mm = index_offset * voxel;  // same placement for every grid
    s.grid_class = g == 0 ? VdbGridSpec::Class::FogVolume : VdbGridSpec::Class::Unknown;
    specs.push_back(s);
  }
  write_vdb(path, specs);
  return path;
}

VdbMediumDesc desc_of(const std::string& file, bool trilinear, VdbMediumDesc::Storage storage) {
  VdbMediumDesc d;
  d.file = file;
  d.sigma_t_scale = 1.5;
  d.albedo_grid = "albedo";
  d.eta_grid = "eta";
  d.eta = 1.25;
  d.interpolation =
      trilinear ? VdbMediumDesc::Interpolation::Trilinear : VdbMediumDesc::Interpolation::Nearest;
  d.storage = storage;
  return d;
}

struct Loaded {
  VolumeData data;
  GridMedium medium;
};
Loaded load_sparse(const VdbMediumDesc& d) {
  VolumeData v = load_volume(d, "scene.json", "/media/m");
  GridMedium m(v, d);
  return {std::move(v), std::move(m)};
}

std::vector<MediumSegment> walk(const GridMedium& m, const Ray& ray, double s_max) {
  std::vector<MediumSegment> out;
  GridMedium::Walker w(m, ray, s_max);
  MediumSegment seg;
  while (w.next(seg)) out.push_back(seg);
  return out;
}

bool same_sparse_bits(const MediumSegment& a, const MediumSegment& b) {
  if (a.s0 != b.s0 || a.s1 != b.s1) return false;
  for (int i = 0; i < 4; ++i)
    if (a.sigma_t.c[i] != b.sigma_t.c[i] || a.eta.c[i] != b.eta.c[i]) return false;
  return true;
}

// A random ray through (or near) the world box [lo, hi].
Ray random_ray(Rng& rng, const Vec3& lo, const Vec3& hi, double& s_max) {
  const Vec3 ext = hi - lo;
  const Vec3 o =
      lo - 0.3 * ext +
      Vec3(1.6 * ext.x * rng.uniform(), 1.6 * ext.y * rng.uniform(), 1.6 * ext.z * rng.uniform());
  const Vec3 t = lo + Vec3(ext.x * rng.uniform(), ext.y * rng.uniform(), ext.z * rng.uniform());
  s_max = length(t - o) * (0.5 + 1.5 * rng.uniform());
  return Ray{o, normalize(t - o)};
}

TimeAxis grid_axis_of(double t0, double width, int bins) {
  TimeAxis a;
  a.t_start_ps = t0;
  a.bin_width_ps = width;
  a.bins = bins;
  return a;
}

}  // namespace

// Catches: any difference in the sparse walk where both storages are exact: wrong brick or voxel
// order inside a leaf, wrong halo leaves for trilinear dual cells, wrong block bounds (a block
// skipped that dense walks, or the reverse), inactive voxels not set to the fill value. With the
// box starting on a node boundary the field coordinates are the same, so every segment (ends and
// cubic coefficients) must be bit-identical, and so every transmittance, OPL and pdf.
TEST_CASE("sparse and dense walks are bit-identical on an aligned volume", "[sparse]") {
  TempDir tmp("femto_sparse");
  // 150 voxels along x: two nodes; an empty slab of constant index crossed block by block.
  const RandomVolume rv = random_volume(150, 13, 17, 3, 60, 90);
  const std::string file = write_random((tmp.dir / "aligned.vdb").string(), rv, {0, 0, 0});
  for (bool trilinear : {false, true}) {
    const Loaded dense = load_sparse(desc_of(file, trilinear, VdbMediumDesc::Storage::Dense));
    const Loaded sparse = load_sparse(desc_of(file, trilinear, VdbMediumDesc::Storage::Sparse));
    REQUIRE(!dense.medium.sparse());
    REQUIRE(sparse.medium.sparse());
    CHECK(sparse.medium.max_sigma_t() == dense.medium.max_sigma_t());
    for (int k = 0; k < 17; ++k)  // every voxel centre
      for (int j = 0; j < 13; ++j)
        for (int i = 0; i < 150; ++i) {
          const Vec3 p = dense.data.to_world({i + 0.5, j + 0.5, k + 0.5});
          INFO("voxel " << i << " " << j << " " << k);
          REQUIRE(sparse.medium.sigma_t_at(p) == dense.medium.sigma_t_at(p));
          REQUIRE(sparse.medium.eta_at(p) == dense.medium.eta_at(p));
          REQUIRE(sparse.medium.albedo_at(p) == dense.medium.albedo_at(p));
        }
    Rng rng(17, 1);
    const Vec3 lo = dense.data.world_bounds_min, hi = dense.data.world_bounds_max;
    int segments = 0;
    for (int r = 0; r < 300; ++r) {
      double s_max;
      const Ray ray = random_ray(rng, lo, hi, s_max);
      const auto a = walk(dense.medium, ray, s_max), b = walk(sparse.medium, ray, s_max);
      INFO("trilinear " << trilinear << " ray " << r);
      REQUIRE(a.size() == b.size());
      for (size_t i = 0; i < a.size(); ++i) {
        INFO(std::setprecision(17)
             << "seg " << i << " d " << a[i].s0 << " " << a[i].s1 << " " << a[i].sigma_t.c[0] << " "
             << a[i].eta.c[0] << " s " << b[i].s0 << " " << b[i].s1 << " " << b[i].sigma_t.c[0]
             << " " << b[i].eta.c[0]);
        REQUIRE(same_sparse_bits(a[i], b[i]));
      }
      segments += static_cast<int>(a.size());
      const Vec3 p = ray.at(s_max * rng.uniform());
      REQUIRE(sparse.medium.sigma_t_at(p) == dense.medium.sigma_t_at(p));
      REQUIRE(sparse.medium.eta_at(p) == dense.medium.eta_at(p));
      REQUIRE(sparse.medium.albedo_at(p) == dense.medium.albedo_at(p));
    }
    CHECK(segments > 3000);  // the rays do cross the volume
  }
}

// Catches: errors that only appear where the box does not start on a node boundary (negative and
// odd offsets) or where whole nodes are empty and crossed in one step. The field coordinates then
// differ by the box start, so the segment ends differ in the last bits (and a run of constant
// segments is summed as one); optical depth and OPL must agree to about 1e-12.
TEST_CASE("sparse and dense integrals agree on a misaligned volume with empty nodes", "[sparse]") {
  TempDir tmp("femto_sparse");
  // 400 voxels along x with an empty, constant-index slab of 250 voxels: whole nodes are empty.
  const RandomVolume rv = random_volume(400, 9, 11, 5, 100, 350);
  const std::string file = write_random((tmp.dir / "offset.vdb").string(), rv, {-133, 45, 7});
  for (bool trilinear : {false, true}) {
    const Loaded dense = load_sparse(desc_of(file, trilinear, VdbMediumDesc::Storage::Dense));
    const Loaded sparse = load_sparse(desc_of(file, trilinear, VdbMediumDesc::Storage::Sparse));
    Rng rng(23, 1);
    const Vec3 lo = dense.data.world_bounds_min, hi = dense.data.world_bounds_max;
    size_t dense_segments = 0, sparse_segments = 0;
    for (int r = 0; r < 300; ++r) {
      double s_max;
      const Ray ray = random_ray(rng, lo, hi, s_max);
      for (int q = 0; q < 20; ++q) {
        const Vec3 p = ray.at(s_max * rng.uniform());
        const Vec3 g = dense.data.to_grid(p);
        INFO("grid point " << g.x << " " << g.y << " " << g.z);
        // The field coordinates differ by a few ulps (~1e-13 voxels here): so may each trilinear
        // weight, which moves a value by at most 8 * 1e-13 times the largest value (sigma_t
        // <= 0.675, eta <= 2, albedo <= 1); 1e-11 of the largest value leaves a margin.
        REQUIRE(sparse.medium.sigma_t_at(p) ==
                Approx(dense.medium.sigma_t_at(p)).epsilon(1e-12).margin(1e-11));
        REQUIRE(sparse.medium.eta_at(p) ==
                Approx(dense.medium.eta_at(p)).epsilon(1e-12).margin(2e-11));
        REQUIRE(sparse.medium.albedo_at(p) ==
                Approx(dense.medium.albedo_at(p)).epsilon(1e-12).margin(1e-11));
      }
      double tau_d, opl_d, tau_s, opl_s;
      GridMedium::Walker wd(dense.medium, ray, s_max), ws(sparse.medium, ray, s_max);
      integrate_segments(wd, tau_d, opl_d);
      integrate_segments(ws, tau_s, opl_s);
      INFO("trilinear " << trilinear << " ray " << r);
      // A cell boundary moved by a few ulps of the field coordinate changes tau by at most
      // sigma_max times the shift along the ray: bounded here by 1e-11 sigma_max s_max.
      REQUIRE(tau_s ==
              Approx(tau_d).epsilon(1e-12).margin(1e-11 * dense.medium.max_sigma_t() * s_max));
      REQUIRE(opl_s == Approx(opl_d).epsilon(1e-12).margin(1e-11 * 2.0 * s_max));
      dense_segments += walk(dense.medium, ray, s_max).size();
      sparse_segments += walk(sparse.medium, ray, s_max).size();
    }
    // Empty nodes are crossed in one step: fewer segments than block by block.
    CHECK(sparse_segments < dense_segments);
  }
}

// Catches: the automatic rule changing existing scenes (small volumes stay dense), a sparse
// volume spending memory on its empty box, tiles (constant regions) read wrong.
TEST_CASE("auto storage: small volumes stay dense, far-apart voxels load_sparse sparse",
          "[sparse]") {
  TempDir tmp("femto_sparse");
  const RandomVolume rv = random_volume(12, 12, 12, 9);
  const std::string small = write_random((tmp.dir / "small.vdb").string(), rv, {0, 0, 0});
  CHECK(!load_sparse(desc_of(small, true, VdbMediumDesc::Storage::Auto)).medium.sparse());

  // Two constant 64^3 blocks (stored as tiles after pruning) 30000 voxels apart: a dense box of
  // 30064 x 64 x 64 cells (470 MiB for one grid), a few MiB sparse.
  VdbGridSpec s;
  s.name = "density";
  const DenseGrid block(64, 64, 64, 0.25f);
  s.values = &block;
  for (int x = 30000; x < 30064; x += 8)
    for (int y = 0; y < 64; y += 8)
      for (int z = 0; z < 64; z += 8)
        for (int d = 0; d < 512; ++d)
          s.voxels.push_back({{x + (d & 7), y + ((d >> 3) & 7), z + (d >> 6)}, 0.25f});
  const std::string far = (tmp.dir / "far.vdb").string();
  write_vdb(far, {s});
  VdbMediumDesc d;
  d.file = far;
  d.sigma_t_scale = 2.0;
  const Loaded l = load_sparse(d);
  REQUIRE(l.medium.sparse());
  CHECK(l.data.memory_bytes() < (8u << 20));
  CHECK(l.data.sparse->tile_count > 0);
  // Along x through both blocks: optical depth 2 * 0.25 * 64 voxels per block.
  const Ray ray{l.data.to_world({-10, 32.5, 32.5}),
                normalize(l.data.to_world({1, 32.5, 32.5}) - l.data.to_world({0, 32.5, 32.5}))};
  double tau, opl;
  GridMedium::Walker w(l.medium, ray, length(l.data.to_world({30100, 32.5, 32.5}) - ray.o));
  integrate_segments(w, tau, opl);
  CHECK(tau == Approx(2 * 2.0 * 0.25 * 64).epsilon(1e-12));
}

// Catches: the sparse limit checked only after the trees are read (the metadata estimate must
// refuse first), and vector grids accepted or refused without naming the grid and file.
TEST_CASE("sparse memory limit and vector grids are bad input", "[sparse]") {
  TempDir tmp("femto_sparse");
  const RandomVolume rv = random_volume(40, 40, 40, 4);
  const std::string file = write_random((tmp.dir / "v.vdb").string(), rv, {0, 0, 0});
  VdbMediumDesc d = desc_of(file, false, VdbMediumDesc::Storage::Sparse);
  d.max_sparse_bytes = 100000;
  try {
    load_volume(d, "scene.json", "/media/m");
    FAIL("loaded above the sparse memory limit");
  } catch (const InputError& e) {
    CHECK_THAT(e.what(), Catch::Contains("/media/m/file") && Catch::Contains("v.vdb") &&
                             Catch::Contains("sparse grids need about") &&
                             Catch::Contains("--max-memory"));
  }
  VdbGridSpec vel;
  vel.name = "vel";
  vel.values = &rv.density;
  vel.type = VdbGridSpec::Type::Vec3;
  const std::string vfile = (tmp.dir / "vel.vdb").string();
  write_vdb(vfile, {vel});
  VdbMediumDesc dv;
  dv.file = vfile;
  dv.density_grid = "vel";
  try {
    load_volume(dv, "scene.json", "/media/m");
    FAIL("a vector grid loaded");
  } catch (const InputError& e) {
    CHECK_THAT(e.what(), Catch::Contains("/media/m/density_grid") && Catch::Contains("vel.vdb") &&
                             Catch::Contains("'vel'") && Catch::Contains("vector grids"));
  }
}

// Catches: a sparse medium that walks right but renders differently (albedo lookups, bounds used
// by the tracker, the mean sigma_t that picks connections): dense and sparse renders of a
// misaligned volume with per-voxel eta, from independent seeds, agree cell by cell within 4 SE.
TEST_CASE("dense and sparse renders agree bin by bin", "[sparse][statistical]") {
  TempDir tmp("femto_sparse");
  const int n = 12;
  DenseGrid density(n, n, n), eta(n, n, n), albedo(n, n, n);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        density.at(x, y, z) = 0.01f + 0.004f * static_cast<float>(x + y);
        eta.at(x, y, z) = 1.0f + 0.05f * static_cast<float>(z);
        albedo.at(x, y, z) = 0.6f + 0.02f * static_cast<float>(x);
      }
  std::vector<VdbGridSpec> specs;
  const char* names[3] = {"density", "eta", "albedo"};
  const DenseGrid* grids[3] = {&density, &eta, &albedo};
  for (int g = 0; g < 3; ++g) {
    VdbGridSpec s;
    s.name = names[g];
    s.values = grids[g];
    s.voxel_mm = Vec3(5.0);
    s.index_offset = {-37, 5, 130};
    s.origin_mm = {-30, 0, -30};
    specs.push_back(s);
  }
  const std::string file = (tmp.dir / "graded.vdb").string();
  write_vdb(file, specs);
  std::vector<std::vector<double>> cells_of[2];
  for (int sparse = 0; sparse < 2; ++sparse) {
    MediumDesc m;
    m.name = "vdb";
    m.type = MediumDesc::Type::Vdb;
    m.vdb.file = file;
    m.vdb.eta = 1.0;
    m.vdb.eta_grid = "eta";
    m.vdb.albedo_grid = "albedo";
    m.vdb.interpolation = VdbMediumDesc::Interpolation::Trilinear;
    m.vdb.storage = sparse ? VdbMediumDesc::Storage::Sparse : VdbMediumDesc::Storage::Dense;
    m.medium.g = 0.2;
    SceneDesc d;
    d.source = "voxels";
    d.camera = perspective({0, 30, 130}, {0, 25, 0}, 50, 16, 12);
    d.time = grid_axis_of(300, 100, 10);
    d.media.push_back(m);
    d.global_medium = 0;
    d.shapes.push_back(quad({-60, 0, 60}, {120, 0, 0}, {0, 0, -120}, diffuse(0.6)));
    d.lights.push_back(point_light({0, 80, 0}, 3000.0));
    const Scene scene(d);
    cells_of[sparse] =
        cells(batches(scene, IntegratorKind::Path, 32, 16, sparse ? 900 : 800), 4, 2);
  }
  require_agreement(cells_of[0], cells_of[1], 15);
}

// Catches: make-volume's sparse kinds not writing what they report, the `storage` key ignored or
// accepting anything, and femto info not saying which storage was used.
TEST_CASE("make-volume plume, the storage key and femto info", "[sparse]") {
  TempDir tmp("femto_sparse");
  Run r = run_femto(
      {"make-volume", "plume", "--resolution", "128", "--voxel", "0.5", "--out", "plume.vdb"},
      tmp.dir);
  REQUIRE(r.code == 0);
  CHECK_THAT(r.err,
             Catch::Contains("128 x 128 x 128 voxel box") && Catch::Contains("active voxels"));
  const auto scene = [&](const std::string& storage) {
    write_file(tmp.dir / "s.json",
               R"({"camera": {"position": [0, 0, 200], "look_at": [0, 0, 0], "resolution": [8, 8]},
      "time": {"bin_width": 10, "bins": 4},
      "media": {"vol": {"type": "vdb", "file": "plume.vdb", "sigma_t_scale": 0.1, "storage": )" +
                   storage + R"(}}, "medium": "vol",
      "lights": [{"type": "point", "position": [0, 80, 0], "intensity": 1}]})");
    return run_femto({"info", "s.json"}, tmp.dir);
  };
  r = scene("\"sparse\"");
  REQUIRE(r.code == 0);
  CHECK_THAT(r.out, Catch::Contains("storage:         sparse") && Catch::Contains("leaves") &&
                        Catch::Contains("OpenVDB trees"));
  r = scene("\"dense\"");
  REQUIRE(r.code == 0);
  CHECK_THAT(r.out, Catch::Contains("storage:         dense"));
  r = scene("\"compressed\"");
  CHECK(r.code == 2);
  CHECK_THAT(r.err, Catch::Contains("/media/vol/storage") && Catch::Contains("compressed"));
}
