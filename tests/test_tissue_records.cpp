// Tissue optics (docs/tissue.md, "Outputs" and "Re-weighting"): what the per-photon records and
// the face images mean. Scattering counts that re-weight detected photons to a new mu_s, and face
// exitance images in absolute units (with the fluence rate written beside the fluence).
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/io/npy.h"
#include "core/tissue/simulate.h"
#include "run_femto.h"
#include "temp_dir.h"
#include "tissue_setups.h"

using namespace femto;
using namespace femto::tissue;
using femto::test::tissue_box;
namespace fs = std::filesystem;

namespace {
// Per detector and gate (index det * gates + gate), over the detected photons of a run: the sums
// of the photons' weights (as given by `weight`) and of their squares, and how many there are.
struct GateSums {
  std::vector<double> s1, s2;
  std::vector<int> count;
};

template <class Weight>
GateSums gate_sums(const Setup& s, const DetectedPhotons& d, Weight weight) {
  const size_t T = static_cast<size_t>(s.time.bins), n = s.detectors.size() * T;
  GateSums g{std::vector<double>(n, 0.0), std::vector<double>(n, 0.0), std::vector<int>(n, 0)};
  for (size_t i = 0; i < d.size(); ++i) {
    const int gate = s.time.bin_of(d.time_ps[i]);
    if (gate < 0) continue;
    const size_t at = static_cast<size_t>(d.detector[i]) * T + static_cast<size_t>(gate);
    const double w = weight(i);
    g.s1[at] += w, g.s2[at] += w * w, ++g.count[at];
  }
  return g;
}
}  // namespace

// Catches scattering counts that are not the number of scatterings of the recorded photon's path
// (docs/tissue.md, "Re-weighting"): a count off by one (the launch or the final exit counted as a
// scattering), counts not reset between photons or summed over them. With weighted absorption
// the flights are drawn at rate mu_s along the path (a Poisson process: the optical depth left is
// carried across voxel faces and gate stops), and nothing else in the walk depends on mu_s
// (the launch and Fresnel choices look at n, the phase function at g, the weight at mu_a, the
// window end is a time). In one label, a detected path with k scatterings and total length L in
// the tissue therefore has density proportional to mu_s^k exp(-mu_s L), and the same photons
// estimate a run at mu_s' with the likelihood ratio (mu_s'/mu_s)^k exp(-(mu_s' - mu_s) L). A run
// re-weighted to 1.15 and 0.9 times mu_s must agree with direct runs at those mu_s (other seeds)
// within 4 standard errors per detector and gate, per detector and over both detectors. The
// errors are from the per-photon sums of squared weights of both runs (exact sample variances
// over all photons; the direct run's records are checked to be its TPSF). A count off by one is
// a factor 1.15 (or 1 / 0.9) on every gate, 7 to 11 standard errors of the total (1.4%).
TEST_CASE("detected photons re-weighted to new mu_s by their scattering counts match direct runs",
          "[tissue][statistical]") {
  const double mu_a = 0.01, mu_s = 1.0;
  auto make = [&](double mus, uint64_t seed) {
    Setup s = tissue_box(20, 20, 10, 2.0, TissueOptics{mu_a, mus, 0.8, 1.37});  // 40x40x20 mm
    s.fresnel = true;
    s.source.position = {20, 20, 0};
    s.time = TimeAxis{0, 15, 12};
    // Discs 3 and 7 mm from the beam.
    s.detectors = {{{23, 20, 0}, 2.0, 0.0}, {{20, 27, 0}, 3.0, 0.0}};
    s.fluence = false;
    s.photons = 400000;
    s.seed = seed;
    return s;
  };
  const Setup sa = make(mu_s, 31);
  const Result a = simulate(sa);
  const DetectedPhotons& da = a.detected;
  REQUIRE(da.labels == 1);
  REQUIRE(da.dropped == 0);
  const size_t T = static_cast<size_t>(sa.time.bins), D = sa.detectors.size();
  const double N = static_cast<double>(sa.photons);
  // z of the difference of two runs' means per photon, from their sums of weights and of squared
  // weights over the N photons of each (a photon adds to one gate of one detector or to none).
  auto z_of = [N](double a1, double a2, double b1, double b2) {
    const double va = (a2 / N - (a1 / N) * (a1 / N)) / (N - 1);
    const double vb = (b2 / N - (b1 / N) * (b1 / N)) / (N - 1);
    return (a1 - b1) / N / std::sqrt(va + vb);
  };
  for (const double ratio : {1.15, 0.9}) {
    const Setup sb = make(ratio * mu_s, 32);
    const Result b = simulate(sb);
    const DetectedPhotons& db = b.detected;
    REQUIRE(db.dropped == 0);
    const GateSums ra = gate_sums(sa, da, [&](size_t i) {
      const double k = da.scatterings[i], L = da.ppath[i];
      return da.weight[i] * std::exp(k * std::log(ratio) - (ratio - 1) * mu_s * L);
    });
    const GateSums rb = gate_sums(sb, db, [&](size_t i) { return db.weight[i]; });
    double all[4] = {0, 0, 0, 0};
    size_t compared = 0;
    for (size_t d = 0; d < D; ++d) {
      const double unit =
          1.0 / (N * kPi * sa.detectors[d].radius * sa.detectors[d].radius * sa.time.bin_width_ps);
      double t[4] = {0, 0, 0, 0};
      for (size_t g = 0; g < T; ++g) {
        const size_t i = d * T + g;
        CHECK(rb.s1[i] * unit == Approx(b.tpsf[i]).epsilon(1e-12));  // B's records are its TPSF
        t[0] += ra.s1[i], t[1] += ra.s2[i], t[2] += rb.s1[i], t[3] += rb.s2[i];
        if (ra.count[i] == 0 && rb.count[i] == 0) continue;  // out of reach in this gate
        ++compared;
        const double z = z_of(ra.s1[i], ra.s2[i], rb.s1[i], rb.s2[i]);
        INFO("mu_s x " << ratio << ", detector " << d << ", gate " << g << ": re-weighted "
                       << ra.s1[i] * unit << " (" << ra.count[i] << " photons), direct "
                       << rb.s1[i] * unit << " (" << rb.count[i] << " photons), z = " << z);
        CHECK(std::abs(z) <= 4);
      }
      CHECK(t[2] == Approx(b.detected_weight[d]).epsilon(1e-12));
      const double z = z_of(t[0], t[1], t[2], t[3]);
      INFO("mu_s x " << ratio << ", detector " << d << ": detected fraction re-weighted "
                     << t[0] / N << ", direct " << t[2] / N << ", z = " << z);
      CHECK(std::abs(z) <= 4);
      for (int j = 0; j < 4; ++j) all[j] += t[j];
    }
    CHECK(compared >= D * T - 2);
    const double z = z_of(all[0], all[1], all[2], all[3]);
    const double se = std::sqrt(((all[1] / N - all[0] * all[0] / (N * N)) +
                                 (all[3] / N - all[2] * all[2] / (N * N))) /
                                (N - 1)) /
                      (all[2] / N);
    INFO("mu_s x " << ratio << ", both detectors: detected fraction re-weighted " << all[0] / N
                   << ", direct " << all[2] / N << " (relative standard error " << se
                   << "), z = " << z);
    CHECK(std::abs(z) <= 4);
    CHECK(se < 0.02);  // a count off by one (15% or 10%) would stand out by 5 or more
  }
}

namespace {
const char* kFaceNames[6] = {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};

// A 2.5 x 3.5 x 4.5 mm box of 0.5 mm voxels, 5 to 9 mean free paths across, Fresnel boundary, a
// pencil beam off the centre of the z = 0 face: every face lets light out, each a different
// amount. 100 gates of 2.5 ps (250 ps, 53 mm of path): none of these photons is still inside at
// the end.
const char* kFacesScene = R"({"tissue": {
  "volume": {"shape": [5, 7, 9], "fill": 1, "voxel": 0.5},
  "labels": [{"label": 1, "mu_a": 0.05, "mu_s": 2.0, "g": 0.6, "n": 1.4}],
  "boundary": "fresnel",
  "source": {"type": "pencil", "position": [1.1, 2.3, 0], "direction": [0, 0, 1]},
  "time": {"bin_width": 2.5, "bins": 100},
  "faces": true,
  "photons": 20000,
  "seed": 7,
  "batches": 4
}})";

// kFacesScene as the scene loader reads it.
Setup faces_setup() {
  Setup s = tissue_box(5, 7, 9, 0.5, TissueOptics{0.05, 2.0, 0.6, 1.4});
  s.fresnel = true;
  s.source.position = {1.1, 2.3, 0};
  s.time = TimeAxis{0, 2.5, 100};
  s.faces = true;
  s.photons = 20000;
  s.seed = 7;
  s.batches = 4;
  return s;
}

// How far the sum over a face image's pixels and gates, times the pixel area and the gate width,
// may lie from the energy that left through the face (per launched photon), `escaped`: the image
// is summed in fixed point, each photon's weight rounded to the quantum q (at most q / 2 per
// photon, at most N photons: q / 2 per launched photon), and stored as float32 (each value within
// 2^-24 of itself, all of them positive: 2^-24 of the sum); double-precision sums and products
// add a few 1e-16 per term, covered by 1e-12.
double face_sum_tolerance(double escaped, double q) {
  return (std::ldexp(1.0, -24) + 1e-12) * escaped + 0.5 * q;
}
}  // namespace

// Catches face images (exitance_*.npy) in the wrong units or on the wrong face: a missing pixel
// area or gate-width factor, a per-photon normalisation missing, faces swapped (in the tally or
// in the file names), pixels transposed or shifted, photons in the wrong gate, and a fluence rate
// that is not the fluence divided by the gate width. Face f's image is its exitance per pixel and
// gate, 1/(mm^2 ps) per launched photon; the same photons make the energy balance's escaped
// energy per face, so the sum of the image over pixels and gates times the pixel area and the
// gate width is that energy, to the fixed-point quantum and float32 rounding (no statistics).
// Pixel by pixel, a disc detector over each whole face records every photon leaving through it
// (position, time, weight), and those records rebuild each image value to the same rounding.
// Then femto render on the same scene: the written images and summary.json agree the same way
// (and are the bits of the run in process), and fluence_rate.npy is fluence.npy divided by the
// gate width to float32 rounding.
TEST_CASE("face exitance images integrate to the energy escaped through each face",
          "[tissue][cli]") {
  Setup s = faces_setup();
  const LabelVolume& v = s.volume;
  // One disc over each whole face, in face order (a photon is detected in the plane it leaves).
  const double ext[3] = {v.n[0] * v.voxel, v.n[1] * v.voxel, v.n[2] * v.voxel};
  for (int f = 0; f < 6; ++f) {
    const int a = f / 2;
    Vec3 c(0.5 * ext[0], 0.5 * ext[1], 0.5 * ext[2]);
    c[a] = f % 2 == 0 ? 0.0 : ext[a];
    s.detectors.push_back({c, 0.5 * std::hypot(ext[(a + 1) % 3], ext[(a + 2) % 3]) + 0.01, 0.0});
  }
  const Result r = simulate(s);
  const double N = static_cast<double>(s.photons), q = r.fixed_point_quantum;
  const double area = v.voxel * v.voxel, dt = s.time.bin_width_ps;
  const size_t T = static_cast<size_t>(s.time.bins);
  const Balance& b = r.balance;
  INFO("quantum " << q << ", alive at the window end " << b.alive / N);
  REQUIRE(q > 0);
  REQUIRE(q < 1e-9);
  CHECK(std::abs(b.residual()) <= 1e-12 * b.launched);
  CHECK(b.escaped_inside == 0);
  CHECK(b.alive / N < 1e-4);  // the gates hold nearly all the light (not needed for the sums)
  REQUIRE(r.detected.dropped == 0);
  // Rebuilt images: the weights of the photons leaving through each pixel in each gate.
  std::array<std::vector<double>, 6> w;
  std::array<std::vector<int>, 6> count;
  for (size_t f = 0; f < 6; ++f) {
    const int a = static_cast<int>(f) / 2, pb = a == 0 ? 1 : 0, pc = a == 2 ? 1 : 2;
    CHECK(r.face_shape[f] == std::array<int, 2>{v.n[pb], v.n[pc]});
    REQUIRE(r.face_exitance[f].size() == static_cast<size_t>(v.n[pb]) * v.n[pc] * T);
    w[f].assign(r.face_exitance[f].size(), 0.0);
    count[f].assign(r.face_exitance[f].size(), 0);
    // Every photon leaving through face f reaches its detector, and no other.
    CHECK(r.detected_weight[f] == Approx(b.escaped_faces[f]).epsilon(1e-12));
  }
  const DetectedPhotons& d = r.detected;
  size_t outside_window = 0;
  for (size_t i = 0; i < d.size(); ++i) {
    const size_t f = static_cast<size_t>(d.detector[i]);
    const int a = static_cast<int>(f) / 2, pb = a == 0 ? 1 : 0, pc = a == 2 ? 1 : 2;
    auto pixel = [&](int axis) {
      const double x = d.exit[6 * i + static_cast<size_t>(axis)];
      return std::clamp(static_cast<int>(std::floor(x / v.voxel)), 0, v.n[axis] - 1);
    };
    const int gate = s.time.bin_of(d.time_ps[i]);
    if (gate < 0) {  // escapes happen inside the window
      ++outside_window;
      continue;
    }
    const size_t at =
        (static_cast<size_t>(pixel(pb)) * v.n[pc] + pixel(pc)) * T + static_cast<size_t>(gate);
    w[f][at] += d.weight[i];
    ++count[f][at];
  }
  CHECK(outside_window == 0);
  const double to_exitance = 1.0 / (N * area * dt);
  std::array<double, 6> escaped{};
  for (size_t f = 0; f < 6; ++f) {
    const std::vector<float>& img = r.face_exitance[f];
    double sum = 0;
    size_t bad = 0;
    for (size_t i = 0; i < img.size(); ++i) {
      sum += img[i];
      const double expected = w[f][i] * to_exitance;
      const double tol =
          (std::ldexp(1.0, -24) + 1e-12) * expected + count[f][i] * 0.5 * q * to_exitance;
      if (!(std::abs(img[i] - expected) <= tol)) ++bad;
    }
    escaped[f] = b.escaped_faces[f] / N;
    const double got = sum * area * dt;
    INFO("face " << kFaceNames[f] << ": image sum x area x gate width " << got << ", escaped "
                 << escaped[f] << " (relative difference " << got / escaped[f] - 1 << ")");
    CHECK(bad == 0);
    CHECK(escaped[f] > 1e-3);
    CHECK(std::abs(got - escaped[f]) <= face_sum_tolerance(escaped[f], q));
  }
  // Faces apart by far more than the tolerance: a swap of two faces cannot pass.
  for (size_t f = 0; f < 6; ++f)
    for (size_t g = f + 1; g < 6; ++g)
      CHECK(std::abs(escaped[f] - escaped[g]) > 1000 * face_sum_tolerance(escaped[f], q));

  // The written files, from femto render on the same scene (no detectors).
  femto::test::TempDir tmp("femto_tissue_faces");
  femto::test::write_file(tmp.dir / "faces.json", kFacesScene);
  const auto run =
      femto::test::run_femto({"render", "faces.json", "--out", "out", "--quiet"}, tmp.dir);
  INFO(run.err);
  REQUIRE(run.code == 0);
  const fs::path out = tmp.dir / "out";
  const nlohmann::json sum = nlohmann::json::parse(femto::test::read_file(out / "summary.json"));
  const double q_file = sum["fixed_point_quantum_mm"].get<double>();
  CHECK(sum["photons"].get<double>() == N);
  for (size_t f = 0; f < 6; ++f) {
    std::vector<size_t> shape;
    std::vector<float> img;
    read_npy_float32((out / (std::string("exitance_") + kFaceNames[f] + ".npy")).string(), shape,
                     img);
    const int a = static_cast<int>(f) / 2, pb = a == 0 ? 1 : 0, pc = a == 2 ? 1 : 2;
    CHECK(shape ==
          std::vector<size_t>{static_cast<size_t>(v.n[pb]), static_cast<size_t>(v.n[pc]), T});
    double total = 0;
    for (float x : img) total += x;
    const double e = sum["energy_balance"]["escaped_per_face"][kFaceNames[f]].get<double>();
    INFO("exitance_" << kFaceNames[f] << ".npy: sum x area x gate width " << total * area * dt
                     << ", summary " << e);
    CHECK(e > 1e-3);
    CHECK(std::abs(total * area * dt - e) <= face_sum_tolerance(e, q_file));
    // The same photons as the run above (detectors do not change the walk): the same bits.
    CHECK(img == r.face_exitance[f]);
    CHECK(e == escaped[f]);
  }
  std::vector<size_t> shape, shape_rate;
  std::vector<float> fl, rate;
  read_npy_float32((out / "fluence.npy").string(), shape, fl);
  read_npy_float32((out / "fluence_rate.npy").string(), shape_rate, rate);
  CHECK(shape == std::vector<size_t>{5, 7, 9, T});
  REQUIRE(shape_rate == shape);
  REQUIRE(rate.size() == fl.size());
  // float32 of fluence times float32 of 1 / width: two roundings of at most 2^-24 each.
  size_t bad = 0, nonzero = 0;
  for (size_t i = 0; i < fl.size(); ++i) {
    const double expected = static_cast<double>(fl[i]) / dt;
    if (!(std::abs(rate[i] - expected) <= 1.000001 * std::ldexp(1.0, -23) * expected)) ++bad;
    nonzero += fl[i] > 0 ? 1 : 0;
  }
  CHECK(bad == 0);
  CHECK(nonzero > fl.size() / 4);
}
