#include "core/integrators/photon_beams.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

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

/// The items themselves are partitioned (not an index array), so each node's pieces lie
/// contiguous in memory.
using BuildItem = BeamBuildItem;

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

SahSplit sah_split(const BuildItem* items, uint32_t count, const float clo[3], const float ext[3]) {
  // All three axes binned in one sweep over the node's pieces.
  Box box[3][kSahBins];
  uint32_t n[3][kSahBins] = {};
  float scale[3];
  for (int a = 0; a < 3; ++a) scale[a] = ext[a] > 0 ? kSahBins / ext[a] : 0.0f;
  for (uint32_t k = 0; k < count; ++k) {
    const BuildItem& it = items[k];
    for (int a = 0; a < 3; ++a) {
      if (!(ext[a] > 0)) continue;  // a flat axis has no split (and inf * 0 would be NaN)
      const int b = sah_bin(it.centre[a], clo[a], scale[a]);
      box[a][b].grow(it.lo, it.hi);
      ++n[a][b];
    }
  }
  SahSplit best;
  double best_cost = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (!(ext[a] > 0)) continue;
    double right_cost[kSahBins];  // area x count of bins b + 1 .. end
    Box acc;
    uint32_t acc_n = 0;
    for (int b = kSahBins - 1; b > 0; --b) {
      acc.grow(box[a][b].lo, box[a][b].hi);
      acc_n += n[a][b];
      right_cost[b - 1] = acc_n > 0 ? acc.half_area() * acc_n : 0.0;
    }
    Box left;
    uint32_t left_n = 0;
    for (int b = 0; b + 1 < kSahBins; ++b) {
      left.grow(box[a][b].lo, box[a][b].hi);
      left_n += n[a][b];
      if (left_n == 0 || left_n == count) continue;
      const double cost = left.half_area() * left_n + right_cost[b];
      if (cost < best_cost) best_cost = cost, best.axis = a, best.bin = b;
    }
  }
  return best;
}

// Subtrees of at least this many pieces build their two halves in parallel: the node array, and
// so every query's order, is that of a serial build.
constexpr uint32_t kParallelCount = 16384;

/// Builds the subtree of items [first, first + count) with its root at nodes[at] (BeamBvh's
/// node type is private: deduced here).
template <class Node>
void build_subtree(BuildItem* items, uint32_t first, uint32_t count, uint32_t depth,
                   std::vector<Node>& nodes, uint32_t at) {
  BuildItem* begin = items + first;
  float blo[3], bhi[3], clo[3], chi[3];
  for (int c = 0; c < 3; ++c) {
    blo[c] = clo[c] = std::numeric_limits<float>::infinity();
    bhi[c] = chi[c] = -std::numeric_limits<float>::infinity();
  }
  for (uint32_t i = 0; i < count; ++i) {
    const BuildItem& it = begin[i];
    for (int c = 0; c < 3; ++c) {
      blo[c] = std::min(blo[c], it.lo[c]);
      bhi[c] = std::max(bhi[c], it.hi[c]);
      clo[c] = std::min(clo[c], it.centre[c]);
      chi[c] = std::max(chi[c], it.centre[c]);
    }
  }
  for (int c = 0; c < 3; ++c) nodes[at].lo[c] = blo[c], nodes[at].hi[c] = bhi[c];
  const float ext[3] = {chi[0] - clo[0], chi[1] - clo[1], chi[2] - clo[2]};
  const int widest = ext[0] >= ext[1] && ext[0] >= ext[2] ? 0 : (ext[1] >= ext[2] ? 1 : 2);
  if (count <= kLeafSize || !(ext[widest] > 0)) {
    nodes[at].first = first;
    nodes[at].count = count;
    return;
  }
  // Below kSahDepth median splits only: the depth stays within the query's stack.
  const SahSplit split =
      depth < kSahDepth && count > kSahMinCount ? sah_split(begin, count, clo, ext) : SahSplit{};
  uint32_t half;
  if (split.axis >= 0) {
    // Pieces whose centre falls in bins 0..split.bin go left (a deterministic partition).
    const int a = split.axis;
    const float scale = kSahBins / ext[a];
    BuildItem* mid = std::partition(begin, begin + count, [&](const BuildItem& it) {
      return sah_bin(it.centre[a], clo[a], scale) <= split.bin;
    });
    half = static_cast<uint32_t>(mid - begin);
  } else {  // no bin boundary separates the centres: split at the median of the widest axis
    half = count / 2;
    std::nth_element(begin, begin + half, begin + count,
                     [&](const BuildItem& a, const BuildItem& b) {
                       const float ca = a.centre[widest], cb = b.centre[widest];
                       return ca < cb || (ca == cb && a.piece < b.piece);
                     });
  }
  const auto left = static_cast<uint32_t>(nodes.size());
  nodes[at].first = left;
  nodes.push_back({});
  nodes.push_back({});
  if (count < kParallelCount) {
    build_subtree(items, first, half, depth + 1, nodes, left);
    build_subtree(items, first + half, count - half, depth + 1, nodes, left + 1);
    return;
  }
  // The left half builds in place (the only writer of `nodes` meanwhile), the right half into
  // its own array, spliced after: its root into the slot beside its sibling, its other nodes at
  // the end, inner nodes' child indices moved with them (leaves index pieces, which stay).
  std::vector<Node> right(1);
  tbb::parallel_invoke(
      [&] { build_subtree(items, first, half, depth + 1, nodes, left); },
      [&] { build_subtree(items, first + half, count - half, depth + 1, right, 0); });
  const auto base = static_cast<uint32_t>(nodes.size()) - 1;  // local index i >= 1 -> base + i
  auto moved = [&](Node n) {
    if (n.count == 0) n.first += base;
    return n;
  };
  nodes[left + 1] = moved(right[0]);
  for (size_t i = 1; i < right.size(); ++i) nodes.push_back(moved(right[i]));
}
}  // namespace

void BeamBvh::build(std::vector<Beam> beams, double radius) {
  beams_ = std::move(beams);
  pieces_.clear();
  nodes_.clear();
  if (beams_.empty()) return;
  auto pieces_of = [&](const Beam& b) {
    const double want = std::ceil(b.length / (4.0 * radius));
    return static_cast<uint32_t>(std::clamp(want, 1.0, double{kMaxPieces}));
  };
  // Room for all pieces, so that their lists do not grow (and move) during the build.
  size_t total = 0;
  for (const Beam& b : beams_) total += pieces_of(b);
  std::vector<BuildItem>& items = items_;
  items.clear();
  items.reserve(total);
  pieces_.reserve(total);
  for (size_t i = 0; i < beams_.size(); ++i) {
    const Beam& b = beams_[i];
    const uint32_t n = pieces_of(b);
    float v_prev = 0.0f;
    for (uint32_t k = 0; k < n; ++k) {
      // Shared float ends: piece k's v1 is piece k + 1's v0, so the ranges tile the beam.
      const float v1 = k + 1 == n ? std::numeric_limits<float>::infinity()
                                  : static_cast<float>(b.length * (k + 1) / n);
      const double a_v = v_prev, b_v = k + 1 == n ? b.length : static_cast<double>(v1);
      const Vec3 a = b.o + b.d * a_v, e = b.o + b.d * b_v;
      const Vec3 lo = vmin(a, e) - Vec3(radius), hi = vmax(a, e) + Vec3(radius);
      BuildItem it;
      it.piece = static_cast<uint32_t>(pieces_.size());
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
  // in small nodes, deep in the tree and where it finds none), partitioning the items in place:
  // the same tree on every run and for any thread count. A node's children are adjacent.
  nodes_.reserve(2 * pieces_.size() / kLeafSize + 2);
  nodes_.push_back({});
  build_subtree(items.data(), 0, static_cast<uint32_t>(items.size()), 0, nodes_, 0);
  sorted_.resize(pieces_.size());
  for (size_t i = 0; i < items.size(); ++i) sorted_[i] = pieces_[items[i].piece];
  pieces_.swap(sorted_);  // the unsorted list's memory is the next build's sorted_
}

uint64_t BeamBvh::memory_bytes() const {
  return beams_.capacity() * sizeof(Beam) +
         (pieces_.capacity() + sorted_.capacity()) * sizeof(Piece) +
         nodes_.capacity() * sizeof(Node) + items_.capacity() * sizeof(BuildItem);
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
                              const distributed::Comm* comm, const CausticAim* aim) {
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
            /*segments=*/true, /*rays=*/false, caustic_only ? aim : nullptr);
      },
      comm);
}

}  // namespace femto
