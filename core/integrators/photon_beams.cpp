#include "core/integrators/photon_beams.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/constants.h"
#include "core/transport/chunked_paths.h"
#include "core/transport/light_walk.h"
#include "media/phase_hg.h"

namespace femto {

namespace {
constexpr int64_t kBeamChunk = 256;  // light paths per task: the unit of deterministic ordering
/// Beam streams are keyed apart from camera pixels and photons.
constexpr uint64_t kBeamStream = 0x6000000000000000ULL;
constexpr uint32_t kLeafSize = 2;

}  // namespace

namespace {
/// A float box that surely holds the double interval [lo, hi] (padded against the rounding of
/// the float slab test).
void outward(double lo, double hi, float& flo, float& fhi) {
  const double pad = 1e-5 * (std::fabs(lo) + std::fabs(hi) + 1.0);
  flo = std::nextafter(static_cast<float>(lo - pad), -std::numeric_limits<float>::infinity());
  fhi = std::nextafter(static_cast<float>(hi + pad), std::numeric_limits<float>::infinity());
}

struct BuildItem {
  float lo[3], hi[3];
  float centre[3];
};

// Binned surface-area heuristic: camera segments are long and cross the beams' bundles, so the
// expected number of boxes a segment meets (proportional to their surface area) is what a split
// should make small; a median split of converging beams gives children that overlap.
constexpr int kSahBins = 8;
// Depth up to which splits follow the heuristic; median splits below it add at most
// log2(pieces) levels, so trees stay within BeamBvh::query's stack of 64.
constexpr uint32_t kSahDepth = 24;
// Nodes of fewer pieces split at the median: binning them cost more build time than it saved.
constexpr uint32_t kSahMinCount = 256;

int sah_bin(float centre, float lo, float scale) {
  return std::clamp(static_cast<int>((centre - lo) * scale), 0, kSahBins - 1);
}

struct Box {
  float lo[3] = {std::numeric_limits<float>::infinity(), std::numeric_limits<float>::infinity(),
                 std::numeric_limits<float>::infinity()};
  float hi[3] = {-std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                 -std::numeric_limits<float>::infinity()};
  void grow(const float l[3], const float h[3]) {
    for (int c = 0; c < 3; ++c) lo[c] = std::min(lo[c], l[c]), hi[c] = std::max(hi[c], h[c]);
  }
  double half_area() const {
    const double x = hi[0] - lo[0], y = hi[1] - lo[1], z = hi[2] - lo[2];
    return x * y + y * z + z * x;
  }
};

struct SahSplit {
  int axis = -1;  ///< -1: no split separates the centres
  int bin = 0;    ///< bins 0..bin go left
};

SahSplit sah_split(const std::vector<BuildItem>& items, const uint32_t* order, uint32_t count,
                   const float clo[3], const float ext[3]) {
  SahSplit best;
  double best_cost = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (!(ext[a] > 0)) continue;
    const float scale = kSahBins / ext[a];
    Box box[kSahBins];
    uint32_t n[kSahBins] = {};
    for (uint32_t k = 0; k < count; ++k) {
      const BuildItem& it = items[order[k]];
      const int b = sah_bin(it.centre[a], clo[a], scale);
      box[b].grow(it.lo, it.hi);
      ++n[b];
    }
    double right_cost[kSahBins];  // area x count of bins b + 1 .. end
    Box acc;
    uint32_t acc_n = 0;
    for (int b = kSahBins - 1; b > 0; --b) {
      acc.grow(box[b].lo, box[b].hi);
      acc_n += n[b];
      right_cost[b - 1] = acc_n > 0 ? acc.half_area() * acc_n : 0.0;
    }
    Box left;
    uint32_t left_n = 0;
    for (int b = 0; b + 1 < kSahBins; ++b) {
      left.grow(box[b].lo, box[b].hi);
      left_n += n[b];
      if (left_n == 0 || left_n == count) continue;
      const double cost = left.half_area() * left_n + right_cost[b];
      if (cost < best_cost) best_cost = cost, best.axis = a, best.bin = b;
    }
  }
  return best;
}
}  // namespace

void BeamBvh::build(std::vector<Beam> beams, double radius) {
  beams_ = std::move(beams);
  pieces_.clear();
  nodes_.clear();
  if (beams_.empty()) return;
  std::vector<BuildItem> items;
  for (size_t i = 0; i < beams_.size(); ++i) {
    const Beam& b = beams_[i];
    const double want = std::ceil(b.length / (4.0 * radius));
    const auto n = static_cast<uint32_t>(std::clamp(want, 1.0, double{kMaxPieces}));
    float v_prev = 0.0f;
    for (uint32_t k = 0; k < n; ++k) {
      // Shared float ends: piece k's v1 is piece k + 1's v0, so the ranges tile the beam.
      const float v1 = k + 1 == n ? std::numeric_limits<float>::infinity()
                                  : static_cast<float>(b.length * (k + 1) / n);
      const double a_v = v_prev, b_v = k + 1 == n ? b.length : static_cast<double>(v1);
      const Vec3 a = b.o + b.d * a_v, e = b.o + b.d * b_v;
      const Vec3 lo = vmin(a, e) - Vec3(radius), hi = vmax(a, e) + Vec3(radius);
      BuildItem it;
      outward(lo.x, hi.x, it.lo[0], it.hi[0]);
      outward(lo.y, hi.y, it.lo[1], it.hi[1]);
      outward(lo.z, hi.z, it.lo[2], it.hi[2]);
      for (int c = 0; c < 3; ++c) it.centre[c] = 0.5f * (it.lo[c] + it.hi[c]);
      pieces_.push_back({static_cast<uint32_t>(i), v_prev, v1});
      items.push_back(it);
      v_prev = v1;
    }
  }
  // Splits by the binned surface-area heuristic (median splits of the widest axis of the centres
  // in small nodes, deep in the tree and where it finds none), over an index permutation: the
  // same tree on every run. A node's children are adjacent.
  std::vector<uint32_t> order(pieces_.size());
  for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  nodes_.reserve(2 * pieces_.size() / kLeafSize + 2);
  struct Task {
    uint32_t first, count, node, depth;
  };
  std::vector<Task> todo;
  nodes_.push_back({});
  todo.push_back({0, static_cast<uint32_t>(order.size()), 0, 0});
  while (!todo.empty()) {
    const Task t = todo.back();
    todo.pop_back();
    float blo[3], bhi[3], clo[3], chi[3];
    for (int c = 0; c < 3; ++c) {
      blo[c] = clo[c] = std::numeric_limits<float>::infinity();
      bhi[c] = chi[c] = -std::numeric_limits<float>::infinity();
    }
    for (uint32_t i = t.first; i < t.first + t.count; ++i) {
      const BuildItem& it = items[order[i]];
      for (int c = 0; c < 3; ++c) {
        blo[c] = std::min(blo[c], it.lo[c]);
        bhi[c] = std::max(bhi[c], it.hi[c]);
        clo[c] = std::min(clo[c], it.centre[c]);
        chi[c] = std::max(chi[c], it.centre[c]);
      }
    }
    Node& node = nodes_[t.node];
    for (int c = 0; c < 3; ++c) node.lo[c] = blo[c], node.hi[c] = bhi[c];
    const float ext[3] = {chi[0] - clo[0], chi[1] - clo[1], chi[2] - clo[2]};
    const int widest = ext[0] >= ext[1] && ext[0] >= ext[2] ? 0 : (ext[1] >= ext[2] ? 1 : 2);
    if (t.count <= kLeafSize || !(ext[widest] > 0)) {
      node.first = t.first;
      node.count = t.count;
      continue;
    }
    // Below kSahDepth median splits only: the depth stays within the query's stack.
    const SahSplit split = t.depth < kSahDepth && t.count > kSahMinCount
                               ? sah_split(items, order.data() + t.first, t.count, clo, ext)
                               : SahSplit{};
    uint32_t half;
    if (split.axis >= 0) {
      // Pieces whose centre falls in bins 0..split.bin go left (a deterministic partition).
      const int a = split.axis;
      const float scale = kSahBins / ext[a];
      auto* first = order.data() + t.first;
      auto* mid = std::partition(first, first + t.count, [&](uint32_t i) {
        return sah_bin(items[i].centre[a], clo[a], scale) <= split.bin;
      });
      half = static_cast<uint32_t>(mid - first);
    } else {  // no bin boundary separates the centres: split at the median of the widest axis
      half = t.count / 2;
      std::nth_element(order.begin() + t.first, order.begin() + t.first + half,
                       order.begin() + t.first + t.count, [&](uint32_t a, uint32_t b) {
                         const float ca = items[a].centre[widest], cb = items[b].centre[widest];
                         return ca < cb || (ca == cb && a < b);
                       });
    }
    const auto left = static_cast<uint32_t>(nodes_.size()), right = left + 1;
    nodes_.push_back({});
    nodes_.push_back({});
    nodes_[t.node].first = left;
    todo.push_back({t.first + half, t.count - half, right, t.depth + 1});
    todo.push_back({t.first, half, left, t.depth + 1});
  }
  std::vector<Piece> sorted(pieces_.size());
  for (size_t i = 0; i < order.size(); ++i) sorted[i] = pieces_[order[i]];
  pieces_ = std::move(sorted);
}

uint64_t BeamBvh::memory_bytes() const {
  return beams_.capacity() * sizeof(Beam) + pieces_.capacity() * sizeof(Piece) +
         nodes_.capacity() * sizeof(Node);
}

void BeamGather::gather(int m, const Ray& ray, double s_max, const RGB& beta, double t,
                        double t_factor, PixelAccumulator& acc, PathStats& stats) const {
  const Medium& med = scene->media()[static_cast<size_t>(m)];
  double norm = inv_paths / (2.0 * radius);  // 1-D kernel 1 / (2 R)
  double R2 = radius * radius;
  bvh->query(ray.o, ray.d, s_max, [&](const Beam& b, const BeamBvh::Piece& piece) {
    if (b.medium != m) return;
    // Closest approach of the camera line o + tc u and the beam line b.o + vb b.d.
    const Vec3 w0 = ray.o - b.o;
    const double cos_ub = dot(ray.d, b.d), du = dot(ray.d, w0), db = dot(b.d, w0);
    const double sin2 = 1.0 - cos_ub * cos_ub;
    if (!(sin2 > 1e-12)) return;  // parallel lines meet in a set of measure zero
    const double tc = (cos_ub * db - du) / sin2, vb = (db - cos_ub * du) / sin2;
    // The piece that holds the closest approach owns the crossing (pieces tile the beam).
    if (!(tc >= 0 && tc < s_max && vb >= piece.v0 && vb < piece.v1 && vb < b.length)) return;
    const Vec3 xc = ray.at(tc);
    if (radius_per_mm > 0) {
      const double R = std::max(radius, radius_per_mm * tc);
      norm = inv_paths / (2.0 * R);
      R2 = R * R;
    }
    if (length_squared(xc - (b.o + b.d * vb)) >= R2) return;
    const double sigma_s = med.type == Medium::Type::Grid
                               ? med.grid->sigma_t_at(xc) * med.grid->albedo_at(xc)
                               : med.homogeneous.sigma_s;
    if (!(sigma_s > 0)) return;
    double tau_c, opl_c, tau_b, opl_b;
    tracker->segment_integrals(m, ray, tc, tau_c, opl_c);
    tracker->segment_integrals(b.medium, {b.o, b.d}, vb, tau_b, opl_b);
    // Light travels along b.d and scatters towards the camera, along -u.
    const double f = hg_eval(-cos_ub, b.g);
    const double tau = carry_transmittance ? tau_c + tau_b : tau_c;
    const RGB value = beta * b.power * (std::exp(-tau) * sigma_s * f * norm / std::sqrt(sin2));
    const double time = t + opl_c * t_factor + b.t_ps + opl_b / kSpeedOfLight;
    if (!value.is_finite() || !std::isfinite(time)) {
      ++stats.nonfinite_dropped;
      return;
    }
    ++stats.beam_gathers;
    acc.add_now(kernel, time, b.sigma_ps, value, bandwidth_ps);
  });
}

std::vector<Beam> trace_beams(const Scene& scene, uint64_t seed, int pass, int64_t count,
                              int max_depth, double t_cut_ps, PathStats& stats, bool caustic_only,
                              const distributed::Comm* comm) {
  const MediumTracker tracker(scene);
  return trace_in_chunks<Beam>(
      count, kBeamChunk, stats,
      [&](int64_t i, std::vector<Beam>& out, PathStats& st) {
        Rng rng = Rng::for_sample(seed, kBeamStream + static_cast<uint64_t>(pass),
                                  static_cast<uint64_t>(i));
        walk_light_path(
            scene, tracker, rng, max_depth, t_cut_ps, st,
            [&](const LightVertex& v) {
              // A caustic path is over once it scatters off a diffuse surface or in a medium.
              if (caustic_only && v.chain < 0) return false;
              if (v.kind != LightVertex::Kind::Segment) return true;
              if (caustic_only && v.chain < 1) return true;
              // Beyond the window's end nothing it lights can be seen (eta >= 1: time >= distance /
              // c).
              const double length = std::fmin(v.length, (t_cut_ps - v.t_ps) * kSpeedOfLight);
              if (length > 0) {
                out.push_back({v.p, v.d, length, v.beta, v.t_ps, v.sigma_ps, v.g, v.medium});
                ++st.beams_stored;
              }
              return true;
            },
            /*segments=*/true);
      },
      comm);
}

}  // namespace femto
