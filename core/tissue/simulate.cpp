#include "core/tissue/simulate.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>

#include "core/distributed/bytes.h"
#include "core/distributed/comm.h"
#include "core/lights.h"
#include "core/progress.h"
#include "core/sampling.h"
#include "core/transport/voxel_space.h"
#include "media/grid_medium.h"

namespace femto::tissue {

double Balance::escaped() const {
  double e = escaped_inside;
  for (double f : escaped_faces) e += f;
  return e;
}

double Balance::residual() const {
  return launched - (absorbed + escaped() + specular + missed + alive);
}

namespace {
constexpr uint64_t kChunk = 1024;  // photons per task: the unit of ordered reduction

// Fluence cells in 4 x 4 x 4 bricks (512 bytes of sums each): a photon's neighbouring voxels
// share cache lines, where a row-major layout puts x neighbours a whole plane apart.
struct BrickLayout {
  int nb[3] = {0, 0, 0};
  size_t slots = 0;  ///< bricks x 64, padded cells included
  explicit BrickLayout(const int n[3]) {
    for (int a = 0; a < 3; ++a) nb[a] = (n[a] + 3) / 4;
    slots = static_cast<size_t>(nb[0]) * nb[1] * nb[2] * 64;
  }
  size_t index(int i, int j, int k) const {
    const size_t brick = (static_cast<size_t>(i >> 2) * nb[1] + (j >> 2)) * nb[2] + (k >> 2);
    return brick * 64 + static_cast<size_t>(((i & 3) << 4) | ((j & 3) << 2) | (k & 3));
  }
};

double standard_normal(Rng& rng) {
  const double u1 = rng.uniform(), u2 = rng.uniform();
  return std::sqrt(-2.0 * std::log1p(-u1)) * std::cos(2.0 * kPi * u2);
}

// Sums of one chunk of photons, reduced in chunk order (small: independent of the volume size).
struct ChunkSums {
  Balance balance;
  std::vector<double> absorbed;  // per label
  std::vector<double> tpsf;      // det * gates + gate: detected weight
  std::vector<double> detected;  // per detector
  DetectedPhotons records;
  uint64_t scatterings = 0, segments = 0;
  void reset(int labels, size_t tpsf_size, size_t detectors) {
    balance = Balance{};
    absorbed.assign(static_cast<size_t>(labels), 0.0);
    tpsf.assign(tpsf_size, 0.0);
    detected.assign(detectors, 0.0);
    records = DetectedPhotons{};
    scatterings = segments = 0;
  }
};

// A chunk's sums as bytes, bit for bit (for rank 0, core/distributed/comm.h).
void write_chunk(distributed::ByteWriter& w, const ChunkSums& c) {
  w.put(c.balance);
  w.put_vector(c.absorbed);
  w.put_vector(c.tpsf);
  w.put_vector(c.detected);
  const DetectedPhotons& r = c.records;
  w.put(r.labels);
  w.put_vector(r.detector);
  w.put_vector(r.scatterings);
  w.put_vector(r.weight);
  w.put_vector(r.time_ps);
  w.put_vector(r.ppath);
  w.put_vector(r.exit);
  w.put(r.dropped);
  w.put(c.scatterings);
  w.put(c.segments);
}
void read_chunk(distributed::ByteReader& in, ChunkSums& c) {
  c.balance = in.get<Balance>();
  c.absorbed = in.get_vector<double>();
  c.tpsf = in.get_vector<double>();
  c.detected = in.get_vector<double>();
  DetectedPhotons& r = c.records;
  r.labels = in.get<int>();
  r.detector = in.get_vector<int32_t>();
  r.scatterings = in.get_vector<int32_t>();
  r.weight = in.get_vector<double>();
  r.time_ps = in.get_vector<double>();
  r.ppath = in.get_vector<double>();
  r.exit = in.get_vector<double>();
  r.dropped = in.get<uint64_t>();
  c.scatterings = in.get<uint64_t>();
  c.segments = in.get<uint64_t>();
}

// Integer sums of the volume tallies of one thread (fixed point: order-independent).
struct ThreadSums {
  std::vector<uint64_t> fluence;
  std::array<std::vector<uint64_t>, 6> faces;
};

// The fixed-point scale 2^k: no cell of any sum can overflow 2^63 (a photon's track length is at
// most c times the window; a launched photon's weight is at most max_weight).
int fixed_point_bits(const Setup& s, double max_weight) {
  const double t_span =
      s.time.t_end_ps() - std::min(s.time.t_start_ps, s.source.offset_ps - 8 * s.source.sigma_ps());
  const double max_track = kSpeedOfLight * std::max(t_span, s.time.bin_width_ps) + 1.0;
  const double headroom =
      9.2e18 / (static_cast<double>(std::max<uint64_t>(s.photons, 1)) * max_track * max_weight);
  return std::clamp(static_cast<int>(std::floor(std::log2(headroom))), 0, 40);
}

// The tallies of one photon walk, plugged into walk_step's loop.
class Tally {
 public:
  Tally(const Setup& s, ThreadSums& sums, double scale)
      : layout_(s.fluence_grid.n),
        s_(s),
        sums_(sums),
        scale_(scale),
        gates_(s.time.bins),
        same_grid_(s.fluence && same_grid(s)),
        ppath_(s.volume.optics.size(), 0.0) {
    const FluenceGrid& fg = s.fluence_grid;
    h_ = fg.spacing();
    cells_ = layout_.slots;
    plane_tolerance_ = 1e-6 * s.volume.voxel;
  }
  void begin(ChunkSums& out) {
    out_ = &out;
    std::fill(ppath_.begin(), ppath_.end(), 0.0);
  }

  void segment(const Segment& seg) {
    ++out_->segments;
    out_->absorbed[static_cast<size_t>(seg.label)] += seg.absorbed;
    out_->balance.absorbed += seg.absorbed;
    if (!s_.detectors.empty()) ppath_[static_cast<size_t>(seg.label)] += seg.length();
    if (s_.fluence && seg.duration > 0) fluence(seg);
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
  void end() { flush(); }

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
  // fewer memory round trips and fewer roundings.
  void add(size_t i, double x) {
    if (i != pending_) {
      flush();
      pending_ = i;
    }
    pending_value_ += x;
  }
  void flush() {
    if (pending_ != kNone) sums_.fluence[pending_] += fixed(pending_value_);
    pending_ = kNone;
    pending_value_ = 0;
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

  // Integral of exp(-mu s) over a piece of length ds, divided by ds: (1 - e^-x) / x with
  // x = mu ds, and e^-x itself (a series for small x: no exponential per voxel).
  static double mean_decay(double x, double& e) {
    if (x < 0.01) {  // truncation below x^5 / 720 < 1.4e-13
      const double g = 1 - x * (0.5 - x * (1.0 / 6 - x * (1.0 / 24 - x * (1.0 / 120))));
      e = 1 - x * g;
      return g;
    }
    e = std::exp(-x);
    return (1 - e) / x;
  }

  void fluence(const Segment& seg) {
    if (same_grid_) {
      // The label grid's voxels along the segment; the weight factor exp(-mu_a s) is carried
      // from voxel to voxel.
      const LabelVolume& vol = s_.volume;
      const TimeAxis& ax = s_.time;
      const double L = seg.distance, mu = seg.k / seg.v, inv_v = 1.0 / seg.v;
      const int j0 = ax.bin_of(seg.t0);
      const bool one_gate = j0 >= 0 && seg.t0 + seg.duration <= ax.bin_start_ps(j0 + 1);
      const size_t gate_offset = one_gate ? static_cast<size_t>(j0) * cells_ : 0;
      const VoxelDda dda(seg.x0, seg.d, seg.cell, vol.origin, Vec3(vol.voxel));
      // One label: every voxel is in the grid.
      double tx = dda.t_max[0], ty = dda.t_max[1], tz = dda.t_max[2];
      int cx = seg.cell[0], cy = seg.cell[1], cz = seg.cell[2];
      double sa = 0, ea = 1;
      while (true) {
        const int a = tx < ty && tx < tz ? 0 : (!(tx < ty) && ty < tz ? 1 : 2);  // VoxelDda::axis()
        const double t = a == 0 ? tx : (a == 1 ? ty : tz);
        const bool last = t >= L;
        const double sb = last ? L : t;
        if (sb > sa) {
          const size_t c = layout_.index(cx, cy, cz);
          if (one_gate) {
            double e;
            const double g = mean_decay(mu * (sb - sa), e);
            add(c + gate_offset, seg.w0 * ea * (sb - sa) * g);
            ea *= e;
          } else {  // the segment crosses gates (or the window start): split exactly
            deposit(seg, c, sa * inv_v, sb * inv_v);
            ea = mu > 0 ? std::exp(-mu * sb) : 1.0;
          }
        }
        if (last) break;
        sa = sb;
        if (a == 0)
          cx += dda.step[0], tx += dda.t_delta[0];
        else if (a == 1)
          cy += dda.step[1], ty += dda.t_delta[1];
        else
          cz += dda.step[2], tz += dda.t_delta[2];
      }
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
    sums_.faces[static_cast<size_t>(face)][pix * gates_ + gate] += fixed(p.w);
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
      rec.ppath.insert(rec.ppath.end(), ppath_.begin() + 1, ppath_.end());
      rec.exit.insert(rec.exit.end(), {p.x.x, p.x.y, p.x.z, p.d.x, p.d.y, p.d.z});
      return;  // a photon counts for the first detector it reaches
    }
  }

  BrickLayout layout_;
  const Setup& s_;
  ThreadSums& sums_;
  double scale_;
  int gates_;
  bool same_grid_;
  Vec3 h_;
  size_t cells_ = 0;
  double plane_tolerance_ = 0;
  static constexpr size_t kNone = ~size_t{0};
  size_t pending_ = kNone;
  double pending_value_ = 0;
  std::vector<double> ppath_;  // per label, this photon
  ChunkSums* out_ = nullptr;
};

// Sources emitted by the camera scenes' light code (spot): the light and the normalisation that
// makes the mean launch weight 1.
struct Emitter {
  SceneDesc scene;
  std::unique_ptr<LightSet> lights;
  double inv_mean_beta = 1;
  double max_weight = 1;  ///< the largest launch weight
  explicit Emitter(const Source& src) {
    if (src.type != Source::Type::Spot) return;
    LightDesc d;
    d.type = LightDesc::Type::Spot;
    d.position = src.position;
    d.direction = src.direction;
    d.intensity = RGB(1.0);
    d.cone_angle_deg = src.cone_angle_deg;
    d.falloff_deg = src.falloff_start_deg;
    scene.lights = {d};
    lights = std::make_unique<LightSet>(scene);
    // E[beta] over u1 (the cone's cosine is linear in u1, the falloff smooth): midpoint rule,
    // relative error ~1e-10.
    const int m = 200000;
    double sum = 0, carry = 0;  // compensated: a constant weight comes out 1 to rounding
    for (int i = 0; i < m; ++i) {
      LightEmission e;
      if (!lights->sample_emission(0, (i + 0.5) / m, 0.25, 0.5, 0.5, e)) continue;
      const double y = e.beta.r - carry, t = sum + y;
      carry = (t - sum) - y;
      sum = t;
    }
    inv_mean_beta = sum > 0 ? m / sum : 0.0;
    // The largest beta: falloff 1 over the cone's solid angle (unit intensity).
    max_weight = inv_mean_beta * 2 * kPi * (1 - std::cos(src.cone_angle_deg * kPi / 180));
  }
};

template <class Space>
bool launch(const Setup& s, const Space& space, const Emitter& emitter, Rng& rng, Photon& p,
            double& specular);

template <class Space, class Tally>
void trace_photon(const Setup& s, const Space& space, const Emitter& emitter,
                  const WalkSettings& ws, Rng rng, Tally& tally, ChunkSums& out) {
  Photon p;
  double specular = 0;
  const bool entered = launch(s, space, emitter, rng, p, specular);
  out.balance.launched += p.w + specular;  // 1, or a spot light's falloff weight (mean 1)
  if (!entered) {
    out.balance.missed += p.w;
    return;
  }
  out.balance.specular += specular;
  tally.begin(out);
  if (p.t >= ws.t_end) {  // emitted after the window
    tally.alive(p);
    tally.end();
    return;
  }
  Segment seg;
  while (true) {
    const StepEvent ev = walk_step(space, ws, p, rng, seg);
    tally.segment(seg);
    if (ev == StepEvent::Scattered) continue;
    if (ev == StepEvent::Escaped) tally.escape(p);
    if (ev == StepEvent::WindowEnd) tally.alive(p);
    if (!p.alive) break;
  }
  tally.end();
  out.scatterings += static_cast<uint64_t>(p.scatterings);
}
}  // namespace

namespace {
// Launches photon p from the source (position, direction, time, weight) and moves it to the first
// tissue voxel; false when it never reaches tissue. `specular` receives the weight reflected at
// the entry surface (source.specular), already removed from p.w.
template <class Space>
bool launch(const Setup& s, const Space& space, const Emitter& emitter, Rng& rng, Photon& p,
            double& specular) {
  const Source& src = s.source;
  const LabelVolume& vol = space.volume();
  specular = 0;
  p = Photon{};
  p.t = src.offset_ps + (src.fwhm_ps > 0 ? src.sigma_ps() * standard_normal(rng) : 0.0);
  p.x = src.position;
  p.d = src.direction;
  if (src.type == Source::Type::Gaussian || src.type == Source::Type::Disk) {
    const double u = rng.uniform(), phi = 2.0 * kPi * rng.uniform();
    // Gaussian: intensity exp(-2 r^2 / w^2) (w: 1/e^2 radius); disk: uniform in area.
    const double r = src.type == Source::Type::Gaussian
                         ? src.waist * std::sqrt(-0.5 * std::log1p(-u))
                         : src.radius * std::sqrt(u);
    p.x += Frame(src.direction).to_world({r * std::cos(phi), r * std::sin(phi), 0.0});
  } else if (src.type == Source::Type::Isotropic) {
    const double u1 = rng.uniform(), u2 = rng.uniform();
    p.d = sample_uniform_sphere(u1, u2);
  } else if (src.type == Source::Type::Spot) {
    const double u1 = rng.uniform(), u2 = rng.uniform();
    LightEmission e;
    if (!emitter.lights->sample_emission(0, u1, u2, 0.5, 0.5, e)) {
      p.w = 0;  // outside the falloff: no energy (never for u1 < 1)
      return false;
    }
    p.d = e.ray.d;
    p.w = e.beta.r * emitter.inv_mean_beta;
  }
  // Into the grid's box (slab test); `axis` is the face it enters through, -1 if inside.
  double s_in = 0, s_out = std::numeric_limits<double>::infinity();
  int axis = -1;
  const Vec3 hi = vol.upper();
  for (int a = 0; a < 3; ++a) {
    const double x = p.x[a], d = p.d[a];
    if (d == 0) {
      if (x < vol.origin[a] || x > hi[a]) return false;
      continue;
    }
    const double ta = (vol.origin[a] - x) / d, tb = (hi[a] - x) / d;
    const double near = std::min(ta, tb), far = std::max(ta, tb);
    if (near >= s_in) s_in = near, axis = a;
    s_out = std::min(s_out, far);
  }
  if (!(s_out > s_in)) return false;
  double travelled = s_in;
  p.x += p.d * s_in;
  for (int a = 0; a < 3; ++a)
    p.cell[a] = std::clamp(clamped_floor((p.x[a] - vol.origin[a]) / vol.voxel), 0, vol.n[a] - 1);
  if (axis >= 0) p.x[axis] = vol.origin[axis] + (p.d[axis] > 0 ? 0 : vol.n[axis]) * vol.voxel;
  // Through label-0 voxels to the first tissue voxel.
  if (vol.label_at(p.cell[0], p.cell[1], p.cell[2]) == 0) {
    VoxelDda dda(p.x, p.d, p.cell, vol.origin, Vec3(vol.voxel));
    double s_entry = 0;
    while (vol.label_at(dda.cell[0], dda.cell[1], dda.cell[2]) == 0) {
      axis = dda.axis();
      s_entry = dda.t_max[axis];
      dda.advance(axis);
      if (dda.cell[axis] < 0 || dda.cell[axis] >= vol.n[axis]) return false;
    }
    travelled += s_entry;
    p.x += p.d * s_entry;
    for (int a = 0; a < 3; ++a) p.cell[a] = dda.cell[a];
    p.x[axis] = vol.origin[axis] + (p.cell[axis] + (p.d[axis] > 0 ? 0 : 1)) * vol.voxel;
  }
  p.label = vol.label_at(p.cell[0], p.cell[1], p.cell[2]);
  const double n1 = space.outside_n(), n2 = space.optics_at(p).n;
  p.t += travelled * n1 / kSpeedOfLight;
  if (axis >= 0 && s.fresnel && n1 != n2) {
    const Fresnel fr = fresnel_dielectric(std::abs(p.d[axis]), n2 / n1);
    if (src.specular) {
      specular = p.w * fr.R;
      p.w -= specular;
    }
    if (fr.R < 1.0) {  // Snell at the entry surface
      const double sign = p.d[axis] > 0 ? 1.0 : -1.0;
      Vec3 d = p.d * (n1 / n2);
      d[axis] = sign * fr.cos_t;
      p.d = normalize(d);
    }
  }
  return true;
}
}  // namespace

int threads_for(const Setup& s) {
  const int hardware = tbb::info::default_concurrency();
  return s.threads > 0 ? std::min(s.threads, hardware) : hardware;
}

uint64_t fluence_bytes_per_thread(const Setup& s) {
  return s.fluence ? BrickLayout(s.fluence_grid.n).slots * static_cast<uint64_t>(s.time.bins) * 8
                   : 0;
}

uint64_t memory_bytes(const Setup& s, int threads) {
  const uint64_t gates = static_cast<uint64_t>(s.time.bins);
  uint64_t volume = s.fluence ? BrickLayout(s.fluence_grid.n).slots * gates : 0;
  uint64_t faces = 0;
  if (s.faces)
    for (int a = 0; a < 3; ++a)
      faces += 2 * static_cast<uint64_t>(s.volume.n[(a + 1) % 3]) * s.volume.n[(a + 2) % 3] * gates;
  // Integer sums per thread and in total; float results; double sums of squares for errors.
  uint64_t bytes =
      (volume + faces) * 8 * (static_cast<uint64_t>(threads) + 1) + (volume + faces) * 4;
  if (s.fluence_stderr) bytes += volume * (8 + 4);
  const uint64_t record = 8 * 2 + 4 * 2 + 8 * (s.volume.optics.size());
  if (!s.detectors.empty() && s.save_detected)
    bytes += record * std::min<uint64_t>(s.max_detected, s.photons);
  return bytes + s.volume.memory_bytes();
}

Result simulate(const Setup& s) {
  const auto start = std::chrono::steady_clock::now();
  const LabelSpace space(s.volume, s.fresnel);
  std::optional<VoxelSpace> voxel_space;  // a voxel medium: each voxel its own optics
  if (!s.volume.voxel_optics.empty()) voxel_space.emplace(s.volume, s.fresnel);
  const Emitter emitter(s.source);
  const WalkSettings ws{s.absorption, s.time.t_end_ps()};
  const int threads = threads_for(s);
  const int gates = s.time.bins;
  const int labels = static_cast<int>(s.volume.optics.size());
  const size_t ndet = s.detectors.size();
  const size_t tpsf_size = ndet * static_cast<size_t>(gates);
  const int bits = fixed_point_bits(s, std::max(1.0, emitter.max_weight));
  const double scale = std::ldexp(1.0, bits);

  const BrickLayout layout(s.fluence_grid.n);
  const size_t volume_size = s.fluence ? layout.slots * static_cast<size_t>(gates) : 0;
  std::array<size_t, 6> face_size{};
  Result r;
  for (int f = 0; f < 6; ++f) {
    const int a = f / 2, b = a == 0 ? 1 : 0, c = a == 2 ? 1 : 2;
    r.face_shape[static_cast<size_t>(f)] = {s.volume.n[b], s.volume.n[c]};
    face_size[static_cast<size_t>(f)] =
        s.faces ? static_cast<size_t>(s.volume.n[b]) * s.volume.n[c] * gates : 0;
  }
  tbb::enumerable_thread_specific<ThreadSums> thread_sums([&] {
    ThreadSums t;
    t.fluence.assign(volume_size, 0);
    for (size_t f = 0; f < 6; ++f) t.faces[f].assign(face_size[f], 0);
    return t;
  });
  ThreadSums total;
  total.fluence.assign(volume_size, 0);
  for (size_t f = 0; f < 6; ++f) total.faces[f].assign(face_size[f], 0);
  std::vector<double> sum2(s.fluence_stderr ? volume_size : 0, 0.0);

  ChunkSums all;
  all.reset(labels, tpsf_size, ndet);
  all.records.labels = labels - 1;
  const int batches =
      static_cast<int>(std::clamp<uint64_t>(static_cast<uint64_t>(s.batches), 1, s.photons));
  r.tpsf_batches.assign(static_cast<size_t>(batches) * tpsf_size, 0.0);
  // Across ranks, chunk c of every batch is traced by rank c % ranks: rank 0 folds the chunk sums
  // in chunk order and adds the integer volume sums (exact in any order).
  const distributed::Comm& comm = s.comm ? *s.comm : distributed::alone();
  auto batch_range = [&](int b, uint64_t& p0, uint64_t& p1) {
    p0 = s.photons * static_cast<uint64_t>(b) / static_cast<uint64_t>(batches);
    p1 = s.photons * static_cast<uint64_t>(b + 1) / static_cast<uint64_t>(batches);
  };
  uint64_t own_photons = 0;
  for (int b = 0; b < batches; ++b) {
    uint64_t p0, p1;
    batch_range(b, p0, p1);
    for (uint64_t q0 = p0, c = 0; q0 < p1; q0 += kChunk, ++c)
      if (comm.owns(static_cast<int64_t>(c))) own_photons += std::min(p1, q0 + kChunk) - q0;
  }
  Progress progress(own_photons, "tissue", s.quiet, "photons");
  tbb::task_arena arena(threads);
  for (int b = 0; b < batches; ++b) {
    uint64_t p0, p1;
    batch_range(b, p0, p1);
    const size_t chunks = static_cast<size_t>((p1 - p0 + kChunk - 1) / kChunk);
    std::vector<ChunkSums> chunk(chunks);
    const auto trace_start = std::chrono::steady_clock::now();
    arena.execute([&] {
      tbb::parallel_for(size_t{0}, chunks, [&](size_t c) {
        if (!comm.owns(static_cast<int64_t>(c))) return;
        ThreadSums& ts = thread_sums.local();
        ChunkSums& out = chunk[c];
        out.reset(labels, tpsf_size, ndet);
        Tally tally(s, ts, scale);
        const uint64_t q0 = p0 + c * kChunk, q1 = std::min(p1, q0 + kChunk);
        for (uint64_t i = q0; i < q1; ++i) {
          const Rng rng = Rng::for_sample(s.seed, i, 0);
          if (voxel_space)
            trace_photon(s, *voxel_space, emitter, ws, rng, tally, out);
          else
            trace_photon(s, space, emitter, ws, rng, tally, out);
        }
        progress.add(q1 - q0);
      });
    });
    r.trace_seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - trace_start).count();
    if (!comm.single()) {
      distributed::ByteWriter mine;
      if (!comm.root())
        for (size_t c = 0; c < chunks; ++c)
          if (comm.owns(static_cast<int64_t>(c))) write_chunk(mine, chunk[c]);
      comm.gather(mine.bytes(), [&](int rank, const std::vector<char>& bytes) {
        if (rank == 0) return;
        distributed::ByteReader in(bytes);
        for (size_t c = static_cast<size_t>(rank); c < chunks;
             c += static_cast<size_t>(comm.size()))
          read_chunk(in, chunk[c]);
      });
      // Integer volume sums: without standard errors, other ranks keep adding theirs until the
      // last batch. Rank 0 gets the sums of all threads of all ranks in one thread's sums; the
      // others start again from 0.
      if (s.fluence_stderr || b + 1 == batches) {
        std::vector<uint64_t> sums(volume_size, 0);
        for (size_t f = 0; f < 6; ++f) sums.resize(sums.size() + face_size[f], 0);
        for (ThreadSums& ts : thread_sums) {
          size_t at = 0;
          for (size_t i = 0; i < volume_size; ++i) sums[at++] += ts.fluence[i];
          for (size_t f = 0; f < 6; ++f)
            for (size_t i = 0; i < face_size[f]; ++i) sums[at++] += ts.faces[f][i];
          std::fill(ts.fluence.begin(), ts.fluence.end(), 0);
          for (auto& f : ts.faces) std::fill(f.begin(), f.end(), 0);
        }
        comm.sum_to_root(sums);
        if (comm.root()) {
          ThreadSums& ts = thread_sums.local();
          size_t at = 0;
          for (size_t i = 0; i < volume_size; ++i) ts.fluence[i] = sums[at++];
          for (size_t f = 0; f < 6; ++f)
            for (size_t i = 0; i < face_size[f]; ++i) ts.faces[f][i] = sums[at++];
        }
      }
      if (!comm.root()) continue;  // rank 0 folds the batch
    }
    // Chunk order: the reduction does not depend on which thread traced what.
    std::vector<double> batch_tpsf(tpsf_size, 0.0);
    for (ChunkSums& c : chunk) {
      Balance& B = all.balance;
      const Balance& cb = c.balance;
      B.launched += cb.launched, B.absorbed += cb.absorbed, B.escaped_inside += cb.escaped_inside;
      B.specular += cb.specular, B.missed += cb.missed, B.alive += cb.alive;
      for (size_t f = 0; f < 6; ++f) B.escaped_faces[f] += cb.escaped_faces[f];
      for (size_t l = 0; l < all.absorbed.size(); ++l) all.absorbed[l] += c.absorbed[l];
      for (size_t i = 0; i < tpsf_size; ++i) batch_tpsf[i] += c.tpsf[i];
      for (size_t i = 0; i < ndet; ++i) all.detected[i] += c.detected[i];
      all.scatterings += c.scatterings, all.segments += c.segments;
      DetectedPhotons& R = all.records;
      const DetectedPhotons& cr = c.records;
      for (size_t i = 0; i < cr.size(); ++i) {
        if (R.size() >= s.max_detected) {
          ++R.dropped;
          continue;
        }
        R.detector.push_back(cr.detector[i]);
        R.scatterings.push_back(cr.scatterings[i]);
        R.weight.push_back(cr.weight[i]);
        R.time_ps.push_back(cr.time_ps[i]);
        const size_t w = static_cast<size_t>(R.labels);
        R.ppath.insert(R.ppath.end(), cr.ppath.begin() + static_cast<std::ptrdiff_t>(i * w),
                       cr.ppath.begin() + static_cast<std::ptrdiff_t>((i + 1) * w));
        R.exit.insert(R.exit.end(), cr.exit.begin() + static_cast<std::ptrdiff_t>(6 * i),
                      cr.exit.begin() + static_cast<std::ptrdiff_t>(6 * i + 6));
      }
    }
    for (size_t i = 0; i < tpsf_size; ++i) {
      all.tpsf[i] += batch_tpsf[i];
      r.tpsf_batches[static_cast<size_t>(b) * tpsf_size + i] = batch_tpsf[i];
    }
    // Integer sums of the threads: exact, so their order does not matter.
    const double batch_n = static_cast<double>(p1 - p0);
    for (ThreadSums& ts : thread_sums) {
      for (size_t i = 0; i < volume_size; ++i) total.fluence[i] += ts.fluence[i];
      for (size_t f = 0; f < 6; ++f)
        for (size_t i = 0; i < face_size[f]; ++i) total.faces[f][i] += ts.faces[f][i];
    }
    if (s.fluence_stderr) {
      // The batch's integer sum is the sum over threads; square its mean per photon.
      for (size_t i = 0; i < volume_size; ++i) {
        uint64_t v = 0;
        for (ThreadSums& ts : thread_sums) v += ts.fluence[i];
        const double m = static_cast<double>(v) / batch_n;
        sum2[i] += m * m;
      }
    }
    for (ThreadSums& ts : thread_sums) {
      std::fill(ts.fluence.begin(), ts.fluence.end(), 0);
      for (auto& f : ts.faces) std::fill(f.begin(), f.end(), 0);
    }
  }
  progress.finish();

  const double N = static_cast<double>(s.photons);
  r.gates = gates;
  r.labels = labels;
  r.photons = s.photons;
  r.threads = threads;
  r.batches = batches;
  r.scatterings = all.scatterings;
  r.segments = all.segments;
  r.balance = all.balance;
  r.absorbed_per_label = all.absorbed;
  r.detected = std::move(all.records);
  r.detected_weight = all.detected;
  r.fixed_point_quantum = 1.0 / scale;
  if (s.fluence) {
    const Vec3 h = s.fluence_grid.spacing();
    const double unit = 1.0 / (scale * N * h.x * h.y * h.z);  // weighted mm -> 1/mm^2 per photon
    // Sums are gate-major over bricks (gate * slots + brick slot); results are (X,Y,Z,T):
    // cell * gates + gate with cell = (i ny + j) nz + k.
    const FluenceGrid& fg = s.fluence_grid;
    const size_t slots = layout.slots, G = static_cast<size_t>(gates);
    r.fluence.resize(fg.cells() * G);
    if (s.fluence_stderr) r.fluence_err.resize(fg.cells() * G);
    const double B = batches, to_fluence = 1.0 / (scale * h.x * h.y * h.z);
    size_t c = 0;
    for (int i = 0; i < fg.n[0]; ++i)
      for (int j = 0; j < fg.n[1]; ++j)
        for (int k = 0; k < fg.n[2]; ++k, ++c) {
          const size_t slot = layout.index(i, j, k);
          for (size_t g = 0; g < G; ++g) {
            const size_t q = g * slots + slot;
            r.fluence[c * G + g] = static_cast<float>(static_cast<double>(total.fluence[q]) * unit);
            if (!s.fluence_stderr) continue;
            const double mean =
                static_cast<double>(total.fluence[q]) / N;  // per photon, fixed units
            const double var = B > 1 ? std::max(0.0, (sum2[q] - B * mean * mean) / (B - 1)) : 0.0;
            r.fluence_err[c * G + g] = static_cast<float>(std::sqrt(var / B) * to_fluence);
          }
        }
  }
  const double area_pix = s.volume.voxel * s.volume.voxel;
  for (size_t f = 0; f < 6; ++f) {
    r.face_exitance[f].resize(face_size[f]);
    const double unit = 1.0 / (scale * N * area_pix * s.time.bin_width_ps);
    for (size_t i = 0; i < face_size[f]; ++i)
      r.face_exitance[f][i] = static_cast<float>(static_cast<double>(total.faces[f][i]) * unit);
  }
  // TPSF: exitance through the detector's disc, averaged over each gate; errors from batches.
  r.tpsf.assign(tpsf_size, 0.0);
  r.tpsf_err.assign(tpsf_size, 0.0);
  for (size_t d = 0; d < ndet; ++d) {
    const double area = kPi * s.detectors[d].radius * s.detectors[d].radius;
    const double unit = 1.0 / (area * s.time.bin_width_ps);
    for (int j = 0; j < gates; ++j) {
      const size_t i = d * static_cast<size_t>(gates) + static_cast<size_t>(j);
      r.tpsf[i] = all.tpsf[i] / N * unit;
      double sq = 0;
      for (int b = 0; b < batches; ++b) {
        const uint64_t B = static_cast<uint64_t>(batches), k = static_cast<uint64_t>(b);
        const double nb = static_cast<double>(s.photons * (k + 1) / B - s.photons * k / B);
        double& m = r.tpsf_batches[static_cast<size_t>(b) * tpsf_size + i];
        m = m / nb * unit;  // this batch's own estimate
        sq += (m - r.tpsf[i]) * (m - r.tpsf[i]);
      }
      if (batches > 1) r.tpsf_err[i] = std::sqrt(sq / (batches * (batches - 1.0)));
    }
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

}  // namespace femto::tissue
