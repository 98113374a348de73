// Tissue optics (docs/tissue.md): the shared photon walk over labelled grids, its tallies, the
// energy balance, determinism, Fresnel interfaces, the re-weighting of detected photons to new
// mu_a, NIfTI-1 and OpenVDB label volumes (the command line: test_tissue_cli.cpp; pulse
// statistics: test_tissue_pulse.cpp).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "core/bsdf/fresnel.h"
#include "core/io/nifti.h"
#include "core/tissue/scene.h"
#include "core/tissue/simulate.h"
#include "core/transport/tissue_walk.h"
#include "media/label_grid_vdb.h"
#include "media/volume_data.h"
#include "temp_dir.h"
#include "tissue_setups.h"

using namespace femto;
using namespace femto::tissue;
using femto::test::tissue_box;
namespace fs = std::filesystem;

namespace {
// Two-label cube with an inner block of higher index: reflections at inner and outer faces.
Setup two_label_cube() {
  Setup s = tissue_box(20, 20, 20, 1.0, TissueOptics{0.02, 2.0, 0.8, 1.4});
  s.volume.optics.push_back(TissueOptics{0.1, 5.0, 0.5, 1.6});
  for (int i = 6; i < 14; ++i)
    for (int j = 6; j < 14; ++j)
      for (int k = 4; k < 12; ++k) s.volume.labels[s.volume.index(i, j, k)] = 2;
  s.fresnel = true;
  s.source.type = Source::Type::Gaussian;
  s.source.waist = 2.0;
  s.source.direction = normalize(Vec3(0.3, 0, 1));
  s.source.position = {11, 10, -10};  // the launch plane stays clear of the tissue
  s.source.specular = true;
  s.source.fwhm_ps = 20;
  s.source.offset_ps = 30;
  s.time = TimeAxis{0, 25, 12};
  s.detectors = {{{10, 14, 0}, 2.0, 0.0}, {{10, 10, 20}, 3.0, 0.5}};
  s.faces = true;
  s.fluence_stderr = true;
  s.photons = 20000;
  s.seed = 3;
  return s;
}
}  // namespace

// Catches weight lost or counted twice at reflections, refractions, escapes, the window end or
// the source's specular reflection: per photon, absorbed + carried is the launched weight.
TEST_CASE("tissue energy balance holds to machine precision", "[tissue]") {
  for (int mode = 0; mode < 3; ++mode) {
    const bool fresnel = mode != 1;
    Setup s = two_label_cube();
    s.fresnel = fresnel;
    s.absorption = mode == 2 ? Absorption::Analog : Absorption::Weighted;
    const Result r = simulate(s);
    const Balance& b = r.balance;
    INFO("mode " << mode << ": absorbed " << b.absorbed << " escaped " << b.escaped() << " alive "
                 << b.alive << " specular " << b.specular << " missed " << b.missed);
    CHECK(b.launched == static_cast<double>(s.photons));
    CHECK(std::abs(b.residual()) <= 1e-12 * b.launched);
    CHECK(b.absorbed > 0);
    CHECK(b.alive > 0);
    CHECK(b.escaped() > 0);
    CHECK(b.missed == 0);
    double per_label = 0;
    for (double a : r.absorbed_per_label) per_label += a;
    CHECK(std::abs(per_label - b.absorbed) <= 1e-12 * b.launched);
    CHECK(r.absorbed_per_label[0] == 0);  // nothing is absorbed outside
    CHECK(r.absorbed_per_label[2] > 0);
    // Specular loss at entry: R of the first face at the beam's angle, for every photon.
    const double cos_i = s.source.direction.z;
    const double R0 = fresnel_dielectric(cos_i, 1.4).R;
    CHECK(b.specular == Approx(fresnel ? R0 * static_cast<double>(s.photons) : 0.0).margin(1e-9));
  }
}

namespace {
// Runs s on 1 and 2 threads, checks that they give the same bits and returns the first.
Result same_on_1_and_2_threads(Setup s) {
  s.threads = 1;
  const Result a = simulate(s);
  s.threads = 2;
  const Result b = simulate(s);
  femto::test::check_same_outputs(a, b);
  CHECK(a.detected.ppath == b.detected.ppath);
  return a;
}
}  // namespace

// Catches reductions that depend on which thread traced which photons. Two chunks per batch: on
// 2 threads each chunk walks through all gates in one task, on 1 thread the chunks stop at every
// gate together, so this also compares the two ways.
TEST_CASE("tissue outputs are bit-identical for any thread count", "[tissue]") {
  const Result a = same_on_1_and_2_threads(two_label_cube());
  REQUIRE(a.detected.size() > 10);
}

// Runs of several waves (65,536 photons each, walked gate by gate with each gate's chunks shared
// among the threads): catches a chunk's deposits going to another thread's sums while it walks,
// deposits left in a queue between gates, and chunks finished twice or never (the balance).
TEST_CASE("tissue runs of several waves are bit-identical for any thread count", "[tissue]") {
  Setup s = tissue_box(8, 8, 8, 1.0, TissueOptics{0.05, 0.5, 0.5, 1.4});  // a few steps each
  s.fresnel = true;
  s.time = TimeAxis{0, 10, 8};
  s.detectors = {{{4, 4, 0}, 3.0, 0.0}};
  s.faces = true;
  s.batches = 1;
  s.photons = 2 * 65536 + 3000;  // two whole waves and part of a third
  const Result a = same_on_1_and_2_threads(s);
  CHECK(a.balance.launched == static_cast<double>(s.photons));
  CHECK(std::abs(a.balance.residual()) <= 1e-12 * a.balance.launched);
  CHECK(a.balance.alive > 0);  // some photons walk through every gate
  REQUIRE(a.detected.size() > 1000);
}

// Catches detected-photon records out of photon order (a chunk's photons walk gate by gate, so
// they are detected gate by gate): the records of the first photons of a run are the first
// records of a longer run with the same seed, in the same order.
TEST_CASE("detected-photon records come in photon order", "[tissue]") {
  Setup s = tissue_box(20, 20, 20, 1.0, TissueOptics{0.01, 1.0, 0.5, 1.4});
  s.time = TimeAxis{0, 20, 12};
  s.detectors = {{{10, 10, 0}, 8.0, 0.0}};
  s.fluence = true;  // with a fluence volume, a chunk's photons walk gate by gate
  s.batches = 1;
  s.photons = 1000;  // one chunk
  const Result all = simulate(s);
  s.photons = 500;
  const Result first = simulate(s);
  REQUIRE(first.detected.size() > 50);
  REQUIRE(all.detected.size() > first.detected.size());
  const size_t n = first.detected.size();
  for (size_t i = 0; i < n; ++i) {
    INFO("record " << i);
    CHECK(first.detected.time_ps[i] == all.detected.time_ps[i]);
    CHECK(first.detected.weight[i] == all.detected.weight[i]);
    CHECK(first.detected.ppath[i] == all.detected.ppath[i]);
    CHECK(first.detected.exit[6 * i] == all.detected.exit[6 * i]);
  }
}

// Catches errors in the track-length estimator: the weight integral exp(-mu_a s) per voxel,
// the splitting of a segment at gate boundaries, the fluence normalisation (1/mm^2 per unit
// energy) and the speed c / n. Unscattered pencil beam, so every photon follows the same line.
TEST_CASE("fluence of an unscattered beam is the exact integral of its weight", "[tissue]") {
  const double mu_a = 0.3, n = 1.5, h = 0.5;
  Setup s = tissue_box(3, 3, 40, h, TissueOptics{mu_a, 0.0, 0.0, n});
  s.fresnel = false;
  s.time = TimeAxis{0, 7.0, 10};  // gates end mid-voxel: segments split between gates
  s.photons = 50;
  s.batches = 5;
  const Result r = simulate(s);
  const double v = kSpeedOfLight / n;
  const size_t T = static_cast<size_t>(s.time.bins);
  for (int k = 0; k < 40; ++k)
    for (int g = 0; g < s.time.bins; ++g) {
      // Depth interval of voxel k inside gate g: z in [k h, (k+1) h] and z = v t.
      const double z0 = std::max(k * h, v * s.time.bin_start_ps(g));
      const double z1 = std::min((k + 1) * h, v * s.time.bin_start_ps(g + 1));
      const double expected =
          z1 > z0 ? (std::exp(-mu_a * z0) - std::exp(-mu_a * z1)) / mu_a / (h * h * h) : 0.0;
      const size_t i = s.volume.index(1, 1, k) * T + static_cast<size_t>(g);
      INFO("voxel " << k << " gate " << g);
      CHECK(r.fluence[i] == Approx(expected).epsilon(1e-6).margin(1e-9));
      CHECK(r.fluence[s.volume.index(0, 1, k) * T + static_cast<size_t>(g)] == 0);
    }
  // Beyond the window's reach (v t_end = 14 mm of 20) the rest is alive.
  CHECK(r.balance.alive / static_cast<double>(s.photons) ==
        Approx(std::exp(-mu_a * v * s.time.t_end_ps())).epsilon(1e-12));
}

// Catches a fluence grid of its own resolution and placement summed differently from the label
// grid: a 2x coarser grid shifted by one label voxel must hold the sums of the fine cells.
TEST_CASE("a fluence grid of its own resolution sums the fine grid's cells", "[tissue]") {
  Setup s = tissue_box(12, 12, 12, 1.0, TissueOptics{0.05, 1.5, 0.3, 1.0});
  s.time = TimeAxis{0, 10, 6};
  s.photons = 3000;
  s.fresnel = false;
  const Result fine = simulate(s);
  s.fluence_grid.n[0] = s.fluence_grid.n[1] = s.fluence_grid.n[2] = 5;
  s.fluence_grid.origin = {1, 1, 1};
  s.fluence_grid.size = {10, 10, 10};
  const Result coarse = simulate(s);
  const size_t T = 6;
  for (int I = 0; I < 5; ++I)
    for (int J = 0; J < 5; ++J)
      for (int K = 0; K < 5; ++K)
        for (size_t g = 0; g < T; ++g) {
          double sum = 0;
          for (int di = 0; di < 2; ++di)
            for (int dj = 0; dj < 2; ++dj)
              for (int dk = 0; dk < 2; ++dk)
                sum += fine.fluence[s.volume.index(1 + 2 * I + di, 1 + 2 * J + dj, 1 + 2 * K + dk) *
                                        T +
                                    g];
          const double c = coarse.fluence[((static_cast<size_t>(I) * 5 + J) * 5 + K) * T + g];
          CHECK(c == Approx(sum / 8).epsilon(1e-5).margin(1e-7));
        }
}

// Catches a wrong Fresnel reflectance or Snell refraction at a voxel face between labels: a
// clear two-index box, an oblique pencil beam; the fraction transmitted is T(theta) within 4
// binomial standard errors and the transmitted photons leave the far face where Snell puts them.
TEST_CASE("an interface between labels reflects with Fresnel's R and refracts by Snell's law",
          "[tissue]") {
  const double n1 = 1.0, n2 = 1.5, theta = 50 * kPi / 180;
  Setup s = tissue_box(40, 10, 20, 1.0, TissueOptics{0, 0, 0, n1}, n1);
  s.volume.optics.push_back(TissueOptics{0, 0, 0, n2});
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 10; ++j)
      for (int k = 10; k < 20; ++k) s.volume.labels[s.volume.index(i, j, k)] = 2;
  s.volume.optics[0].n = n2;  // outside matches the far side: no reflection when leaving it
  s.fresnel = true;
  s.source.position = {5, 5, 0};
  s.source.direction = {std::sin(theta), 0, std::cos(theta)};
  s.time = TimeAxis{0, 100, 4};
  s.photons = 40000;
  const double sin_t = std::sin(theta) * n1 / n2, cos_t = std::sqrt(1 - sin_t * sin_t);
  // Far face detector: where the refracted ray leaves z = 20.
  const double x_exit = 5 + 10 * std::tan(theta) + 10 * sin_t / cos_t;
  s.detectors = {{{x_exit, 5, 20}, 0.01, 0.0}};
  s.fluence = false;
  // The entry face (outside n2 -> n1 = 1) would reflect too: launch inside instead.
  s.source.position = {5, 5, 1e-9};
  const Result r = simulate(s);
  const double T = fresnel_dielectric(std::cos(theta), n2 / n1).T;
  const double N = static_cast<double>(s.photons);
  // First pass through the interface: straight out of the far face (outside n = n2) at the
  // Snell point. The reflected part reaches the near face (n1 -> n2, same angle): T of it leaves.
  const double got = r.detected_weight[0] / N, back = r.balance.escaped_faces[4] / N;
  const double se = std::sqrt(T * (1 - T) / N),
               se_back = std::sqrt((1 - T) * T * (1 - (1 - T) * T) / N);
  INFO("transmitted " << got << " expected " << T << " +- " << se << "; back out " << back
                      << " expected " << (1 - T) * T << " +- " << se_back);
  CHECK(std::abs(got - T) <= 4 * se);
  CHECK(std::abs(back - (1 - T) * T) <= 4 * se_back);
}

// Catches partial path lengths that do not belong to the detected weight (wrong label, missing
// pieces), which would make re-weighting to new mu_a wrong. Weighted absorption does not change
// the walk, so re-weighting a mu_a = 0 run must reproduce a direct run with the same seed to
// rounding, and one with another seed within 4 standard errors per gate.
TEST_CASE("detected photons re-weighted to new mu_a reproduce a direct run", "[tissue]") {
  auto make = [](double mu_a1, double mu_a2, uint64_t seed) {
    Setup s = tissue_box(30, 30, 15, 1.0, TissueOptics{mu_a1, 1.0, 0.5, 1.37});
    s.volume.optics.push_back(TissueOptics{mu_a2, 2.0, 0.7, 1.37});
    for (int i = 0; i < 30; ++i)
      for (int j = 0; j < 30; ++j)
        for (int k = 3; k < 15; ++k) s.volume.labels[s.volume.index(i, j, k)] = 2;
    s.fresnel = true;
    s.time = TimeAxis{0, 40, 10};
    s.detectors = {{{15, 20, 0}, 2.5, 0.0}};
    s.fluence = false;
    s.photons = 40000;
    s.batches = 20;
    s.seed = seed;
    return s;
  };
  const double mu_a1 = 0.02, mu_a2 = 0.05;
  const Result base = simulate(make(0.0, 0.0, 11));
  const Result same = simulate(make(mu_a1, mu_a2, 11));
  const Result other = simulate(make(mu_a1, mu_a2, 12));
  const Setup s = make(mu_a1, mu_a2, 11);
  const size_t T = static_cast<size_t>(s.time.bins);
  std::vector<double> tpsf(T, 0.0);
  const DetectedPhotons& d = base.detected;
  REQUIRE(d.size() > 500);
  REQUIRE(d.labels == 2);
  for (size_t i = 0; i < d.size(); ++i) {
    const double w = d.weight[i] * std::exp(-mu_a1 * d.ppath[2 * i] - mu_a2 * d.ppath[2 * i + 1]);
    const int g = s.time.bin_of(d.time_ps[i]);
    if (g >= 0) tpsf[static_cast<size_t>(g)] += w;
  }
  const double unit =
      1.0 / (static_cast<double>(s.photons) * kPi * 2.5 * 2.5 * s.time.bin_width_ps);
  for (size_t g = 0; g < T; ++g) {
    const double rw = tpsf[g] * unit;
    INFO("gate " << g << ": re-weighted " << rw << ", same seed " << same.tpsf[g] << ", other seed "
                 << other.tpsf[g] << " +- " << other.tpsf_err[g]);
    CHECK(rw == Approx(same.tpsf[g]).epsilon(1e-9).margin(1e-15));
    CHECK(std::abs(rw - other.tpsf[g]) <= 4 * std::hypot(other.tpsf_err[g], same.tpsf_err[g]));
  }
}

// Catches NIfTI axis order (x fastest), header fields and scaling errors, and the label table
// check, through the scene loader; and OpenVDB Int32 label grids with their placement.
TEST_CASE("label volumes load from NIfTI-1 and OpenVDB", "[tissue]") {
  femto::test::TempDir tmp("femto_tissue_labels");
  const std::array<int, 4> dim{4, 3, 2, 1};
  std::vector<float> data(24);
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 4; ++i)
        data[static_cast<size_t>((k * 3 + j) * 4 + i)] =
            static_cast<float>(i == 3 ? 2 : (k == 1 ? 1 : 0));
  const std::string nii = (tmp.dir / "labels.nii").string();
  write_nifti_float32(nii, dim, {0.5, 0.5, 0.5, 1}, data.data());
  const NiftiVolume nv = read_nifti(nii);
  CHECK(nv.dim == dim);
  CHECK(nv.pixdim[0] == 0.5);
  const std::string labels =
      R"("labels": [{"label": 1, "mu_a": 0.1, "mu_s": 1, "g": 0, "n": 1.4}, {"label": 2, "mu_a": 0.2, "mu_s": 2, "g": 0.5, "n": 1.3}],)"
      R"("source": {"type": "isotropic", "position": [1, 1, 0.75]}, "time": {"bin_width": 10, "bins": 2}})";
  const Setup s =
      load_tissue_scene(R"({"tissue": {"volume": {"nifti": "labels.nii"},)" + labels + "}",
                        "t.json", tmp.dir.string());
  CHECK(s.volume.n[0] == 4);
  CHECK(s.volume.n[2] == 2);
  CHECK(s.volume.voxel == 0.5);
  CHECK(s.volume.label_at(3, 1, 0) == 2);
  CHECK(s.volume.label_at(1, 2, 1) == 1);
  CHECK(s.volume.label_at(1, 2, 0) == 0);
  CHECK(s.volume.optics[2].n == 1.3);
  CHECK_THROWS_WITH(
      load_tissue_scene(R"({"tissue": {"volume": {"nifti": "labels.nii"},)" +
                            labels.substr(0, labels.find("{\"label\": 2")) +
                            "{\"label\": 3, \"mu_a\": 0, \"mu_s\": 1, \"g\": 0, \"n\": 1}]," +
                            labels.substr(labels.find("\"source\"")) + "}",
                        "t.json", tmp.dir.string()),
      Catch::Contains(
          "t.json: /tissue/labels: label 2 occurs in the volume but has no optical properties"));

  LabelGridData g;
  g.n = {3, 2, 2};
  g.voxel = 0.25;
  g.origin = {1, 2, 3};
  g.labels = {1, 1, 1, 2, 1, 1, 1, 1, 1, 1, 2, 1};
  const std::string vdb = (tmp.dir / "labels.vdb").string();
  write_vdb_labels(vdb, "labels", g);
  const Setup v = load_tissue_scene(
      R"({"tissue": {"volume": {"vdb": "labels.vdb"},)" + labels + "}", "t.json", tmp.dir.string());
  CHECK(v.volume.n[0] == 3);
  CHECK(v.volume.voxel == Approx(0.25));
  CHECK(v.volume.origin.x == Approx(1));
  CHECK(v.volume.origin.z == Approx(3));
  for (size_t i = 0; i < g.labels.size(); ++i) CHECK(v.volume.labels[i] == g.labels[i]);

  // A float grid where labels are expected: refused by its type, naming the file and the grid.
  DenseGrid density(2, 2, 2, 1.0f);
  const std::string fog = (tmp.dir / "fog.vdb").string();
  write_volume(fog, density, nullptr, nullptr, 0.5, Vec3(0), "labels");
  CHECK_THROWS_WITH(load_tissue_scene(R"({"tissue": {"volume": {"vdb": "fog.vdb"},)" + labels + "}",
                                      "t.json", tmp.dir.string()),
                    Catch::Contains("fog.vdb: grid 'labels' is of type float; labels need an "
                                    "Int32 grid"));
}

// Catches analog absorption that differs from the weighted estimator it must agree with on
// average (collision rate mu_t, absorption probability mu_a / mu_t): absorbed energy per label
// and escaped energy agree within 4 standard errors (bounded by p (1 - p) / N per run, since
// every photon's share lies in [0, 1]).
TEST_CASE("analog and weighted absorption agree", "[tissue]") {
  Setup s = two_label_cube();
  s.photons = 40000;
  s.fluence = false;
  const Result w = simulate(s);
  s.absorption = Absorption::Analog;
  s.seed = 99;
  const Result a = simulate(s);
  const double N = static_cast<double>(s.photons);
  auto check = [&](double x, double y, const char* what) {
    const double p = 0.5 * (x + y) / N, se = std::sqrt(2 * p * (1 - p) / N);
    INFO(what << ": weighted " << x / N << ", analog " << y / N << " +- " << se);
    CHECK(std::abs(x - y) / N <= 4 * se);
  };
  check(w.absorbed_per_label[1], a.absorbed_per_label[1], "label 1");
  check(w.absorbed_per_label[2], a.absorbed_per_label[2], "label 2");
  check(w.balance.escaped(), a.balance.escaped(), "escaped");
  check(w.balance.alive, a.balance.alive, "alive");
}

// Catches wrong per-voxel batch standard errors: identical photons give zero (up to rounding), and
// a disc beam through a clear slab, where each photon crosses one voxel column with track h (a
// Bernoulli per voxel with p = the column's share of the disc), gives sum_c se_c^2 =
// sum_c p_c (1 - p_c) h^2 / (N V^2) in expectation; the sum of B-batch variance estimates over
// K columns scatters by sqrt(2 / ((B - 1) K)) relatively, so it must lie within 4 of those.
TEST_CASE("per-voxel fluence standard errors from batches", "[tissue]") {
  {
    Setup s = tissue_box(3, 3, 10, 0.5, TissueOptics{0.3, 0.0, 0.0, 1.0});
    s.time = TimeAxis{0, 7.0, 4};
    s.photons = 50;
    s.batches = 5;
    s.fluence_stderr = true;
    const Result r = simulate(s);
    for (size_t i = 0; i < r.fluence.size(); ++i)
      CHECK(r.fluence_err[i] <= 1e-6 * r.fluence[i]);  // rounding only
  }
  const int n = 40;
  const double h = 0.25, V = h * h * h;
  Setup s = tissue_box(n, n, 1, h, TissueOptics{0, 0, 0, 1.0});
  s.source.type = Source::Type::Disk;
  s.source.radius = 4.0;
  s.source.position = {5, 5, -1};
  s.time = TimeAxis{0, 100, 1};
  s.photons = 100000;
  s.batches = 20;
  s.fluence_stderr = true;
  const Result r = simulate(s);
  const double N = static_cast<double>(s.photons);
  double se2 = 0, expected = 0;
  int K = 0;
  for (size_t c = 0; c < r.fluence.size(); ++c) {
    const double p = r.fluence[c] * V / h;
    if (p <= 0) continue;
    ++K;
    se2 += static_cast<double>(r.fluence_err[c]) * r.fluence_err[c];
    expected += p * (1 - p) * h * h / (N * V * V);
  }
  const double rel = std::sqrt(2.0 / ((s.batches - 1) * K));
  INFO(K << " columns: sum se^2 " << se2 << ", expected " << expected << " (relative sd " << rel
         << ")");
  REQUIRE(K > 500);
  CHECK(std::abs(se2 / expected - 1) <= 4 * rel);
}

// Catches a numerical aperture applied to the wrong angle or medium: an isotropic point 1 mm
// below the surface of a clear, index-matched slab; a detector covering the face with NA 0.5
// accepts exactly the cone of half-angle 30 degrees, (1 - cos 30 deg) / 2 of the photons (within
// 4 binomial standard errors), while without an NA it accepts everything leaving that face.
TEST_CASE("detector numerical aperture selects the exit cone", "[tissue]") {
  Setup s = tissue_box(40, 40, 10, 1.0, TissueOptics{0, 0, 0, 1.0});
  s.source.type = Source::Type::Isotropic;
  s.source.position = {20.3, 19.8, 1.0};
  s.time = TimeAxis{0, 1000, 1};
  s.fluence = false;
  s.detectors = {{{20, 20, 0}, 30.0, 0.5}, {{20, 20, 0}, 30.0, 0.0}};
  s.photons = 40000;
  const Result r = simulate(s);
  const double N = static_cast<double>(s.photons), p = (1 - std::cos(kPi / 6)) / 2;
  const double got = r.detected_weight[0] / N;
  INFO("NA 0.5: " << got << " expected " << p);
  CHECK(std::abs(got - p) <= 4 * std::sqrt(p * (1 - p) / N));
  // The second detector sees the rest of the face (a photon counts for the first detector only).
  CHECK(r.detected_weight[0] + r.detected_weight[1] ==
        Approx(r.balance.escaped_faces[4]).epsilon(1e-12));
  // Catches exit records taken before the photon reaches the face, or from another photon: every
  // detected photon's exit point lies on the z = 0 face within its detector's disc, its direction
  // leaves through that face, and the first detector's directions lie within the NA's cone.
  const DetectedPhotons& d = r.detected;
  REQUIRE(d.exit.size() == 6 * d.size());
  REQUIRE(d.size() > 1000);
  for (size_t i = 0; i < d.size(); ++i) {
    const double* e = &d.exit[6 * i];
    CHECK(std::abs(e[2]) < 1e-9);
    CHECK(std::hypot(e[0] - 20, e[1] - 20) <= 30.0);
    CHECK(e[5] < 0);
    CHECK(std::hypot(e[3], e[4], e[5]) == Approx(1.0).epsilon(1e-12));
    if (d.detector[i] == 0) CHECK(-e[5] >= std::cos(kPi / 6) - 1e-12);
    // The exit point is where the straight flight from the source meets the face (no scattering).
    const double flight = -1.0 / e[5];
    CHECK(e[0] - flight * e[3] == Approx(20.3).margin(1e-9));
    CHECK(e[1] - flight * e[4] == Approx(19.8).margin(1e-9));
  }
}

// Catches a wrong or too short series in the walk's absorbed fraction 1 - exp(-mu_a s) (the
// energy balance alone would not: absorbed + carried is w0 by construction whatever its value).
TEST_CASE("the walk's 1 - exp(-x) is accurate to 1e-13 on both sides of its series", "[tissue]") {
  double worst = 0;
  for (double x = 1e-12; x < 2; x *= 1.001) {
    const double exact = -std::expm1(-x);
    worst = std::max(worst, std::abs(one_minus_exp(x) - exact) / exact);
  }
  CHECK(worst < 1e-13);
}
