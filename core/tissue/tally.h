#pragma once
// The tallies of the tissue photon walk (docs/tissue.md, "Design"): a Tally sees the segments and
// escapes of one photon at a time and adds them to the fixed-point volume sums of its thread
// (fluence, face images) and to the sums of the photon's chunk (energy balance, detectors).
// Inline: its calls sit in the walk's loop.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/tissue/chunk_sums.h"
#include "core/tissue/setup.h"
#include "core/transport/photon.h"
#include "core/zeroed_array.h"
#include "media/grid_medium.h"  // clamped_floor

namespace femto::tissue {

/// Fluence cells in 4 x 4 x 4 bricks (512 bytes of sums each): a photon's neighbouring voxels
// share cache lines, where a row-major layout puts x neighbours a whole plane apart.
struct BrickLayout {
  int nb[3] = {0, 0, 0};
  size_t slots = 0;  ///< bricks x 64, padded cells included
  explicit BrickLayout(const int n[3]) {
    for (int a = 0; a < 3; ++a) nb[a] = (n[a] + 3) / 4;
    slots = static_cast<size_t>(nb[0]) * nb[1] * nb[2] * 64;
  }
  /// The slot is a sum of one term per axis (brick and place in the brick alike): a tally can
  /// keep the terms in tables and move along an axis by changing one term.
  size_t part(int axis, int c) const {
    const size_t brick = static_cast<size_t>(c >> 2), in = static_cast<size_t>(c & 3);
    if (axis == 0) return brick * static_cast<size_t>(nb[1]) * nb[2] * 64 + (in << 4);
    if (axis == 1) return brick * static_cast<size_t>(nb[2]) * 64 + (in << 2);
    return brick * 64 + in;
  }
  size_t index(int i, int j, int k) const { return part(0, i) + part(1, j) + part(2, k); }
};

/// A fluence deposit waiting in a thread's queue.
struct Deposit {
  size_t index;    ///< gate * slots + brick slot
  uint64_t value;  ///< fixed point
};

/// Integer sums of the volume tallies of one thread (fixed point: order-independent), and the
/// queue of its deposits not yet added.
struct ThreadSums {
  ZeroedArray<uint64_t> fluence;  // pages mapped as deposits first touch them
  std::array<ZeroedArray<uint64_t>, 6> faces;
  std::vector<Deposit> queue;
  /// Adds another thread's sums (of the same shape) to these.
  void add(const ThreadSums& o) {
    for (size_t i = 0; i < fluence.size(); ++i) fluence[i] += o.fluence[i];
    for (size_t f = 0; f < faces.size(); ++f)
      for (size_t i = 0; i < faces[f].size(); ++i) faces[f][i] += o.faces[f][i];
  }
};

/// The tallies of the photon walks of one chunk, plugged into walk_step's loop. The chunk's sums
/// stay with it; its volume deposits go to the sums of the thread that walks it (bind, unbind).
class Tally {
 public:
  Tally(const Setup& s, double scale)
      : layout_(s.fluence_grid.n),
        s_(s),
        scale_(scale),
        gates_(s.time.bins),
        same_grid_(s.fluence && same_grid(s)),
        labels_(s.volume.optics.size()) {
    const FluenceGrid& fg = s.fluence_grid;
    h_ = fg.spacing();
    cells_ = layout_.slots;
    plane_tolerance_ = 1e-6 * s.volume.voxel;
    for (int a = 0; a < 3; ++a)
      for (int c = 0; c < fg.n[a]; ++c) part_[static_cast<size_t>(a)].push_back(layout_.part(a, c));
  }
  /// A chunk of `photons` photons starts: their partial paths are 0 and no record is kept.
  void start_chunk(ChunkSums& out, size_t photons) {
    out_ = &out;
    ppaths_.assign(s_.detectors.empty() ? 0 : photons * labels_, 0.0);
    record_photon_.clear();
  }
  /// The thread walking the chunk now: its sums take the deposits until unbind(). Its queue is
  /// shared by every Tally the thread binds (one at a time; unbind leaves it empty).
  void bind(ThreadSums& sums) {
    if (sums.queue.size() < kQueue) sums.queue.resize(kQueue);
    sums_ = &sums;
    queue_ = sums.queue.data();
  }
  /// The deposits still queued go into the bound thread's sums.
  void unbind() {
    drain();
    sums_ = nullptr;
    queue_ = nullptr;
  }
  /// The walk is in gate j (it stops at the gate's end): segments inside it deposit there.
  void gate(int j) {
    gate_lo_ = s_.time.bin_start_ps(j);
    gate_hi_ = s_.time.bin_start_ps(j + 1);
    gate_offset_ = static_cast<size_t>(j) * cells_;
  }
  /// Photon `slot` of the chunk walks on (a chunk's photons walk gate by gate, in turns).
  void begin(size_t slot) {
    slot_ = slot;
    ppath_ = ppaths_.empty() ? nullptr : ppaths_.data() + slot * labels_;
  }

  void segment(const Segment& seg) {
    ++out_->segments;
    out_->absorbed[static_cast<size_t>(seg.label)] += seg.absorbed;
    out_->balance.absorbed += seg.absorbed;
    if (ppath_) ppath_[static_cast<size_t>(seg.label)] += seg.length();
    if (!s_.fluence || !(seg.duration > 0)) return;
    const VoxelCrossings* vc = seg.crossings;
    // Most steps: in the gate the walk is in, with the voxel faces the walk crossed.
    if (vc && vc->complete() && seg.t0 >= gate_lo_ && seg.t0 + seg.duration <= gate_hi_)
      fluence_faces(seg, *vc);
    else
      fluence(seg);
  }

  void escape(const Photon& p) {
    const LabelVolume& vol = s_.volume;
    int face = -1;
    for (int a = 0; a < 3; ++a) {
      if (p.cell[a] < 0) face = 2 * a;
      if (p.cell[a] >= vol.n[a]) face = 2 * a + 1;
    }
    if (face < 0) {
      out_->balance.escaped_inside += p.w;
    } else {
      out_->balance.escaped_faces[static_cast<size_t>(face)] += p.w;
      if (s_.faces) face_image(face, p);
    }
    if (!s_.detectors.empty()) detect(p);
  }

  void alive(const Photon& p) { out_->balance.alive += p.w; }
  void end() {
    if (s_.fluence) flush();
  }
  /// The chunk's detected-photon records in photon order (they were made gate by gate).
  void end_chunk() { sort_records(out_->records, record_photon_); }
  /// Where the walk should record the voxel faces of its steps (nullptr: not needed).
  VoxelCrossings* crossings() { return same_grid_ ? &crossings_ : nullptr; }

 private:
  static bool same_grid(const Setup& s) {
    const FluenceGrid& fg = s.fluence_grid;
    const LabelVolume& v = s.volume;
    for (int a = 0; a < 3; ++a)
      if (fg.n[a] != v.n[a] || fg.origin[a] != v.origin[a] || fg.size[a] != v.n[a] * v.voxel)
        return false;
    return true;
  }

  // Through int64 (values stay below 2^63 by the choice of scale): one instruction, where a
  // direct double -> uint64 conversion needs a branch for the upper half.
  uint64_t fixed(double x) const {
    return static_cast<uint64_t>(static_cast<int64_t>(x * scale_ + 0.5));
  }

  // Consecutive deposits into the same entry (scatterings inside one voxel) are summed first:
  // fewer memory round trips and fewer roundings. Without a branch on whether the entry changes
  // (a coin flip for the predictor): the pending entry is always written to the queue's next
  // slot, and the slot is kept only when a new entry starts. The first pending entry is slot 0
  // with nothing in it (adding 0 is harmless).
  void add(size_t i, double x) {
    const bool next = i != pending_;
    queue_[queued_] = {pending_, fixed(pending_value_)};
    queued_ += next ? 1 : 0;
    pending_value_ = next ? x : pending_value_ + x;
    pending_ = i;
    if (queued_ == kQueue) drain();
  }
  void flush() {
    queue_[queued_++] = {pending_, fixed(pending_value_)};
    pending_ = 0;
    pending_value_ = 0;
    if (queued_ == kQueue) drain();
  }
  // The queued deposits into the sums, each prefetched kAhead deposits before its add: most
  // sums are cache misses, and a loop of independent adds keeps many of them in flight (the walk
  // would wait for each one).
  void drain() {
    constexpr size_t kAhead = 32;
    uint64_t* sums = sums_->fluence.data();
    const Deposit* q = queue_;
    const size_t n = queued_;
    for (size_t i = 0; i < std::min(n, kAhead); ++i) __builtin_prefetch(sums + q[i].index, 1);
    for (size_t i = 0; i < n; ++i) {
      if (i + kAhead < n) __builtin_prefetch(sums + q[i + kAhead].index, 1);
      sums[q[i].index] += q[i].value;
    }
    queued_ = 0;
  }

  // Adds the weighted track length of seg over tau in [a, b] (ps since its start) to cell `c`,
  // split at the gate boundaries.
  void deposit(const Segment& seg, size_t c, double a, double b) {
    const TimeAxis& ax = s_.time;
    const double lo = std::max(seg.t0 + a, ax.t_start_ps), hi = std::min(seg.t0 + b, ax.t_end_ps());
    if (!(hi > lo)) return;
    int j = std::clamp(static_cast<int>((lo - ax.t_start_ps) / ax.bin_width_ps), 0, gates_ - 1);
    // Gate-major: a photon's consecutive deposits fall in one gate's grid, which stays in cache.
    const size_t stride = cells_;
    for (double t = lo; t < hi && j < gates_; ++j) {
      const double te = j == gates_ - 1 ? hi : std::min(hi, ax.bin_start_ps(j + 1));
      if (te > t)
        add(c + j * stride, seg.w0 * seg.v * exp_integral(seg.k, t - seg.t0, te - seg.t0));
      t = std::max(t, te);
    }
  }

  // The pieces of a step inside one gate, split at the voxel faces the walk crossed. A piece
  // [sa, sb] gets w0 (F(sb) - F(sa)), F = decay_integral: each boundary's F on its own, so the
  // pieces do not wait for one another. The slot moves by one axis's term per face.
  void fluence_faces(const Segment& seg, const VoxelCrossings& vc) {
    const double d[3] = {seg.d.x, seg.d.y, seg.d.z};  // a face's step: only for axes crossed
    int c[3] = {seg.cell[0], seg.cell[1], seg.cell[2]};
    size_t slot = gate_offset_ + part_[0][static_cast<size_t>(c[0])] +
                  part_[1][static_cast<size_t>(c[1])] + part_[2][static_cast<size_t>(c[2])];
    double Fa = 0;
    for (int q = 0; q < vc.count; ++q) {
      const double Fb = decay_integral(seg.mu, vc.s[q]);
      add(slot, seg.w0 * (Fb - Fa));  // a piece of length 0 (a corner) adds 0
      Fa = Fb;
      const int a = vc.axis[q];
      const size_t* part = part_[static_cast<size_t>(a)].data();
      const int next = c[a] + (d[a] > 0 ? 1 : -1);
      slot += part[next] - part[c[a]];  // unsigned wrap-around moves the slot either way
      c[a] = next;
    }
    add(slot, seg.w0 * (seg.decay - Fa));
  }

  [[gnu::noinline]] void fluence(const Segment& seg) {
    if (same_grid_) {
      // The label grid's voxels along the segment; a piece [sa, sb] inside one gate gets
      // w0 (F(sb) - F(sa)), F = decay_integral: each boundary's F on its own, so the pieces do
      // not wait for one another.
      const double L = seg.distance, mu = seg.mu;
      // The gate the walk is in (it stops at gate ends): no division to find it.
      const bool one_gate = seg.t0 >= gate_lo_ && seg.t0 + seg.duration <= gate_hi_;
      const size_t gate_offset = one_gate ? gate_offset_ : 0;
      const VoxelCrossings* vc = seg.crossings;
      double sa = 0, Fa = 0;
      auto piece = [&](int cx, int cy, int cz, double sb) {
        if (!(sb > sa)) return;
        const size_t c = layout_.index(cx, cy, cz);
        if (one_gate) {
          const double Fb = decay_integral(mu, sb);
          add(c + gate_offset, seg.w0 * (Fb - Fa));
          Fa = Fb;
        } else {  // the segment crosses gates (or the window start): split exactly
          deposit(seg, c, sa / seg.v, sb / seg.v);
        }
        sa = sb;
      };
      int cx = seg.cell[0], cy = seg.cell[1], cz = seg.cell[2];
      if (vc && vc->complete()) {  // the faces the walk's march crossed: no second march
        const int step[3] = {seg.d[0] > 0 ? 1 : -1, seg.d[1] > 0 ? 1 : -1, seg.d[2] > 0 ? 1 : -1};
        for (int q = 0; q < vc->count; ++q) {
          piece(cx, cy, cz, vc->s[q]);
          const int a = vc->axis[q];
          (a == 0 ? cx : (a == 1 ? cy : cz)) += step[a];
        }
        piece(cx, cy, cz, L);
        return;
      }
      const LabelVolume& vol = s_.volume;
      const VoxelDda dda(seg.x0, seg.d, seg.cell, vol.origin, Vec3(vol.voxel));
      // One label: every voxel is in the grid.
      double tx = dda.t_max[0], ty = dda.t_max[1], tz = dda.t_max[2];
      while (true) {
        const int a = tx < ty && tx < tz ? 0 : (!(tx < ty) && ty < tz ? 1 : 2);  // VoxelDda::axis()
        const double t = a == 0 ? tx : (a == 1 ? ty : tz);
        if (t >= L) break;
        piece(cx, cy, cz, t);
        if (a == 0)
          cx += dda.step[0], tx += dda.t_delta[0];
        else if (a == 1)
          cy += dda.step[1], ty += dda.t_delta[1];
        else
          cz += dda.step[2], tz += dda.t_delta[2];
      }
      piece(cx, cy, cz, L);
      return;
    }
    // Walk the fluence grid's cells along the segment (3-D DDA), clipped to its box.
    const FluenceGrid& fg = s_.fluence_grid;
    const double L = seg.length();
    double s0 = 0, s1 = L;
    for (int a = 0; a < 3; ++a) {
      const double lo = fg.origin[a], hi = fg.origin[a] + fg.size[a], x = seg.x0[a], d = seg.d[a];
      if (d == 0) {
        if (x < lo || x >= hi) return;
        continue;
      }
      const double ta = (lo - x) / d, tb = (hi - x) / d;
      s0 = std::max(s0, std::min(ta, tb));
      s1 = std::min(s1, std::max(ta, tb));
    }
    if (!(s1 > s0)) return;
    int c[3], step[3];
    double next[3], delta[3];
    const double sm = 0.5 * (s0 + std::min(s1, s0 + 1e-9 * (1 + L)));  // a point just inside
    for (int a = 0; a < 3; ++a) {
      const double x = seg.x0[a] + seg.d[a] * sm, d = seg.d[a];
      c[a] = std::clamp(clamped_floor((x - fg.origin[a]) / h_[a]), 0, fg.n[a] - 1);
      step[a] = d > 0 ? 1 : -1;
      const double face = fg.origin[a] + (c[a] + (d > 0 ? 1 : 0)) * h_[a];
      next[a] = d != 0 ? (face - seg.x0[a]) / d : std::numeric_limits<double>::infinity();
      delta[a] = d != 0 ? h_[a] / std::abs(d) : std::numeric_limits<double>::infinity();
    }
    double s = s0;
    while (s < s1) {
      const int a = next[0] < next[1] ? (next[0] < next[2] ? 0 : 2) : (next[1] < next[2] ? 1 : 2);
      const double e = std::min(next[a], s1);
      if (e > s) {
        deposit(seg, layout_.index(c[0], c[1], c[2]), s / seg.v, e / seg.v);
      }
      s = std::max(s, e);
      c[a] += step[a];
      next[a] += delta[a];
      if (c[a] < 0 || c[a] >= fg.n[a]) break;
    }
  }

  void face_image(int face, const Photon& p) {
    const int gate = s_.time.bin_of(p.t);
    if (gate < 0) return;
    const int axis = face / 2, b = axis == 0 ? 1 : 0, c = axis == 2 ? 1 : 2;
    const LabelVolume& vol = s_.volume;
    const size_t pix = static_cast<size_t>(p.cell[b]) * vol.n[c] + p.cell[c];
    sums_->faces[static_cast<size_t>(face)][pix * gates_ + gate] += fixed(p.w);
  }

  void detect(const Photon& p) {
    const double n_out = s_.volume.optics[0].n;
    for (size_t i = 0; i < s_.detectors.size(); ++i) {
      const Detector& det = s_.detectors[i];
      const Vec3 r = p.x - det.center;
      if (dot(r, r) > det.radius * det.radius) continue;
      // The disc lies in the plane of the face the photon leaves through.
      if (p.face_axis >= 0 && std::abs(r[p.face_axis]) > plane_tolerance_) continue;
      if (det.na > 0 && p.face_axis >= 0) {
        const double cos_out = std::abs(p.d[p.face_axis]);  // exit angle from the face normal
        const double sin_max = det.na / n_out;
        if (sin_max < 1 && cos_out * cos_out < 1 - sin_max * sin_max) continue;
      }
      const int gate = s_.time.bin_of(p.t);
      if (gate >= 0) out_->tpsf[i * static_cast<size_t>(gates_) + gate] += p.w;
      out_->detected[i] += p.w;
      DetectedPhotons& rec = out_->records;
      if (!s_.save_detected) return;
      rec.detector.push_back(static_cast<int32_t>(i));
      rec.scatterings.push_back(p.scatterings);
      rec.weight.push_back(p.w);
      rec.time_ps.push_back(p.t);
      record_photon_.push_back(static_cast<uint32_t>(slot_));
      rec.ppath.insert(rec.ppath.end(), ppath_ + 1, ppath_ + labels_);
      rec.exit.insert(rec.exit.end(), {p.x.x, p.x.y, p.x.z, p.d.x, p.d.y, p.d.z});
      return;  // a photon counts for the first detector it reaches
    }
  }

  BrickLayout layout_;
  const Setup& s_;
  ThreadSums* sums_ = nullptr;  // the bound thread's
  double scale_;
  int gates_;
  bool same_grid_;
  Vec3 h_;
  size_t cells_ = 0;
  double plane_tolerance_ = 0;
  static constexpr size_t kQueue = 4096;  // 64 KiB: stays in L2 between its fill and drain
  Deposit* queue_ = nullptr;              // the bound thread's: kQueue slots, queued_ filled
  size_t queued_ = 0;
  double gate_lo_ = kInf, gate_hi_ = -kInf;  // the current gate (none yet)
  size_t gate_offset_ = 0;
  size_t pending_ = 0;
  double pending_value_ = 0;
  size_t labels_;
  std::vector<double> ppaths_;           // (photon of the chunk, label): partial path lengths
  double* ppath_ = nullptr;              // this photon's row
  size_t slot_ = 0;                      // this photon's place in the chunk
  std::vector<uint32_t> record_photon_;  // per record: its photon's place in the chunk
  VoxelCrossings crossings_;             // the faces of the current step, from the walk
  std::array<std::vector<size_t>, 3> part_;  // BrickLayout::part per axis and voxel coordinate
  ChunkSums* out_ = nullptr;
};

}  // namespace femto::tissue
