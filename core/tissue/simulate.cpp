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
#include "core/progress.h"
#include "core/tissue/chunk_sums.h"
#include "core/tissue/launch.h"
#include "core/tissue/tally.h"
#include "core/transport/voxel_space.h"

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
// Chunks walked together, gate by gate: every photon of a wave reaches the end of gate j before
// any goes on into gate j + 1, so one gate's grid of sums takes the wave's deposits while it is in
// cache (a single chunk's photons touched most of it once per chunk: mostly cache misses).
constexpr size_t kWaveChunks = 64;
// Chunks per wave: at least kWaveChunks, and enough to keep every thread busy in every gate.
size_t wave_chunks(int threads) {
  return std::max(kWaveChunks, 4 * static_cast<size_t>(threads));
}

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

// A photon of a chunk between its turns (the chunk walks gate by gate).
struct Walker {
  Photon p;
  Rng rng;
  uint32_t slot;  // place in the chunk
};

// Walks p until it dies or reaches `stop` (ws.t_end: the end of the current gate); true if it
// walks on in the next gate. `last`: stop is the window end.
template <class Space, class Tally>
bool walk_until(const Space& space, const WalkSettings& stop, bool last, Photon& p, Rng& rng,
                Tally& tally, ChunkSums& out) {
  if (p.t >= stop.t_end) {  // emitted after this gate
    if (!last) return true;
    tally.alive(p);
    return false;
  }
  Segment seg;
  seg.crossings = tally.crossings();
  while (true) {
    const StepEvent ev = walk_step(space, stop, p, rng, seg);
    tally.segment(seg);
    if (ev == StepEvent::Scattered) continue;
    if (ev == StepEvent::Escaped) tally.escape(p);
    if (ev == StepEvent::WindowEnd) {
      if (!last) {  // a gate's end: the optical depth to the next scattering carries on
        p.alive = true;
        p.tau_left = std::max(0.0, p.tau_left);
        return true;
      }
      tally.alive(p);
    }
    if (!p.alive) break;
  }
  out.scatterings += static_cast<uint64_t>(p.scatterings);
  return false;
}

// Photons q0 .. q1 - 1 of a chunk, launched into `walkers`. Photon i always draws from
// Rng::for_sample(seed, i, 0).
template <class Space>
void launch_chunk(const Setup& s, const Space& space, const Emitter& emitter, uint64_t q0,
                  uint64_t q1, std::vector<Walker>& walkers, ChunkSums& out) {
  walkers.reserve(static_cast<size_t>(q1 - q0));
  for (uint64_t i = q0; i < q1; ++i) {
    Walker w{Photon{}, Rng::for_sample(s.seed, i, 0), static_cast<uint32_t>(i - q0)};
    double specular = 0;
    const bool entered = launch(s, space, emitter, w.rng, w.p, specular);
    out.balance.launched += w.p.w + specular;  // 1, or a spot light's falloff weight (mean 1)
    if (!entered) {
      out.balance.missed += w.p.w;
      continue;
    }
    out.balance.specular += specular;
    walkers.push_back(w);
  }
}

// Turn j of a chunk: its photons, in order, to the end of gate j (the last turn: to the window
// end); those that walk on stay in `walkers`.
template <class Space, class Tally>
void walk_turn(const Setup& s, const Space& space, const WalkSettings& ws, int j, int turns,
               std::vector<Walker>& walkers, Tally& tally, ChunkSums& out) {
  const bool last = j + 1 == turns;
  WalkSettings stop = ws;
  if (!last) stop.t_end = s.time.bin_start_ps(j + 1);
  size_t kept = 0;
  if (s.fluence) tally.gate(j);
  for (Walker& w : walkers) {
    tally.begin(w.slot);
    const bool on = walk_until(space, stop, last, w.p, w.rng, tally, out);
    tally.end();
    if (on) walkers[kept++] = w;
  }
  walkers.resize(kept);
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
  // Integer sums per thread (and of the batches so far, with errors); float results; double sums
  // of squares for errors.
  const uint64_t sums = static_cast<uint64_t>(threads) + (s.fluence_stderr ? 1 : 0);
  uint64_t bytes = (volume + faces) * 8 * sums + (volume + faces) * 4;
  if (s.fluence_stderr) bytes += volume * (8 + 4);
  const uint64_t record = 8 * 2 + 4 * 2 + 8 * (s.volume.optics.size());
  if (!s.detectors.empty() && s.save_detected)
    bytes += record * std::min<uint64_t>(s.max_detected, s.photons);
  // The photons of one wave between gates, their partial paths with detectors, and the
  // chunks' tallies (slot tables per axis).
  const uint64_t wave = std::min<uint64_t>(s.photons, wave_chunks(threads) * kChunk);
  bytes += wave * (sizeof(Walker) + (s.detectors.empty() ? 0 : 8 * s.volume.optics.size()));
  const FluenceGrid& fg = s.fluence_grid;
  bytes += wave_chunks(threads) *
           (sizeof(Tally) + 8 * static_cast<uint64_t>(fg.n[0] + fg.n[1] + fg.n[2]));
  // The walk's safe distances: one byte per voxel (core/transport/safe_distance.h).
  return bytes + s.volume.memory_bytes() + s.volume.cells();
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
  // Zeros from the kernel, touched only where photons deposit (core/zeroed_array.h).
  auto zeroed_sums = [&] {
    ThreadSums t;
    t.fluence = ZeroedArray<uint64_t>(volume_size);
    for (size_t f = 0; f < 6; ++f) t.faces[f] = ZeroedArray<uint64_t>(face_size[f]);
    return t;
  };
  tbb::enumerable_thread_specific<ThreadSums> thread_sums(zeroed_sums);
  // With standard errors, the sums of the batches so far (the threads' start again each batch).
  ThreadSums total = s.fluence_stderr ? zeroed_sums() : ThreadSums{};
  ZeroedArray<double> sum2(s.fluence_stderr ? volume_size : 0);

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
  const size_t wave = wave_chunks(threads);
  // Calls f with the space the photons walk: the voxel medium's, or the labelled grid's.
  auto with_space = [&](auto&& f) {
    if (voxel_space)
      f(*voxel_space);
    else
      f(space);
  };
  // The photons of a wave's chunks between turns: kept for the whole run, so that each chunk
  // reuses its slot's memory (fresh memory costs page faults).
  std::vector<std::vector<Walker>> walkers(wave);
  for (int b = 0; b < batches; ++b) {
    uint64_t p0, p1;
    batch_range(b, p0, p1);
    const size_t chunks = static_cast<size_t>((p1 - p0 + kChunk - 1) / kChunk);
    std::vector<ChunkSums> chunk(chunks);
    const auto trace_start = std::chrono::steady_clock::now();
    // Wave by wave (this rank's chunks only); within a wave, gate by gate; within a gate, chunk
    // by chunk on any thread. A chunk's own sums see its photons in the same order whichever
    // thread walks it, and its volume deposits are integers: the outputs do not depend on the
    // threads or ranks. Without a fluence volume, nothing gains from the gates' stops: one turn
    // to the window end.
    const int turns = s.fluence ? gates : 1;
    std::vector<size_t> owned;
    for (size_t c = 0; c < chunks; ++c)
      if (comm.owns(static_cast<int64_t>(c))) owned.push_back(c);
    // With few chunks per thread a stop at every gate would leave threads waiting for the
    // slowest chunk; then each task walks its chunk through all gates.
    const bool gate_stops = threads == 1 || owned.size() >= 8 * static_cast<size_t>(threads);
    for (size_t w0 = 0; w0 < owned.size(); w0 += wave) {
      const size_t w1 = std::min(owned.size(), w0 + wave);
      std::vector<std::optional<Tally>> tally(w1 - w0);
      std::vector<char> done(w1 - w0, 0);
      // Turn j of chunk owned[i]; false once the chunk is done.
      auto turn = [&](size_t i, int j) {
        const size_t k = i - w0, c = owned[i];
        if (done[k]) return false;
        if (s.stop && s.stop->load()) {  // the batch is thrown away: Stopped below
          done[k] = 1;
          return false;
        }
        ChunkSums& out = chunk[c];
        const uint64_t q0 = p0 + c * kChunk, q1 = std::min(p1, q0 + kChunk);
        if (j == 0) {
          walkers[k].clear();  // a stopped run's wave may leave photons here
          out.reset(labels, tpsf_size, ndet);
          with_space(
              [&](const auto& sp) { launch_chunk(s, sp, emitter, q0, q1, walkers[k], out); });
          tally[k].emplace(s, scale);
          tally[k]->start_chunk(out, static_cast<size_t>(q1 - q0));
        }
        // The thread's deposit queue is this task's until unbind: nothing in between may wait
        // on TBB (another task run meanwhile on this thread would share the queue).
        tally[k]->bind(thread_sums.local());
        with_space(
            [&](const auto& sp) { walk_turn(s, sp, ws, j, turns, walkers[k], *tally[k], out); });
        tally[k]->unbind();
        if (!walkers[k].empty() && j + 1 < turns) return true;
        tally[k]->end_chunk();
        tally[k].reset();
        walkers[k].clear();
        done[k] = 1;
        progress.add(q1 - q0);
        if (s.photons_done) s.photons_done->fetch_add(q1 - q0);
        return false;
      };
      if (!gate_stops) {
        arena.execute([&] {
          tbb::parallel_for(w0, w1, [&](size_t i) {
            for (int j = 0; j < turns && turn(i, j); ++j) {
            }
          });
        });
      } else {
        for (int j = 0; j < turns; ++j) {
          arena.execute([&] { tbb::parallel_for(w0, w1, [&](size_t i) { turn(i, j); }); });
          if (std::all_of(done.begin(), done.end(), [](char d) { return d != 0; })) break;
        }
      }
      if (s.stop && s.stop->load()) break;
    }
    r.trace_seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - trace_start).count();
    if (s.stop && s.stop->load()) throw Stopped();
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
    // Integer sums of the threads: exact, so their order does not matter. Without standard
    // errors the threads keep adding theirs until the last batch (the scale allows all photons),
    // and the sum over threads is made after it.
    if (!s.fluence_stderr) continue;
    const double batch_n = static_cast<double>(p1 - p0);
    for (const ThreadSums& ts : thread_sums) total.add(ts);
    // The batch's integer sum is the sum over threads; square its mean per photon.
    for (size_t i = 0; i < volume_size; ++i) {
      uint64_t v = 0;
      for (ThreadSums& ts : thread_sums) v += ts.fluence[i];
      const double m = static_cast<double>(v) / batch_n;
      sum2[i] += m * m;
    }
    for (ThreadSums& ts : thread_sums) {
      std::fill(ts.fluence.begin(), ts.fluence.end(), 0);
      for (auto& f : ts.faces) std::fill(f.begin(), f.end(), 0);
    }
  }
  progress.finish();
  // Without standard errors: the other threads' sums added into this thread's (no third array).
  const ThreadSums* summed = &total;
  if (!s.fluence_stderr) {
    ThreadSums& mine = thread_sums.local();
    for (const ThreadSums& ts : thread_sums)
      if (&ts != &mine) mine.add(ts);
    summed = &mine;
  }

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
    const size_t n = fg.cells() * G;
    resize_in_huge_pages(r.fluence, n);
    if (s.fluence_stderr) resize_in_huge_pages(r.fluence_err, n);
    const double B = batches, to_fluence = 1.0 / (scale * h.x * h.y * h.z);
    const uint64_t* sums = summed->fluence.data();
    // Slice by slice of x on every thread: each cell is written once, by one thread.
    arena.execute([&] {
      tbb::parallel_for(0, fg.n[0], [&](int i) {
        size_t c = static_cast<size_t>(i) * fg.n[1] * fg.n[2];
        for (int j = 0; j < fg.n[1]; ++j)
          for (int k = 0; k < fg.n[2]; ++k, ++c) {
            const size_t slot = layout.index(i, j, k);
            for (size_t g = 0; g < G; ++g) {
              const size_t q = g * slots + slot;
              r.fluence[c * G + g] = static_cast<float>(static_cast<double>(sums[q]) * unit);
              if (!s.fluence_stderr) continue;
              const double mean = static_cast<double>(sums[q]) / N;  // per photon, fixed units
              const double var = B > 1 ? std::max(0.0, (sum2[q] - B * mean * mean) / (B - 1)) : 0.0;
              r.fluence_err[c * G + g] = static_cast<float>(std::sqrt(var / B) * to_fluence);
            }
          }
      });
    });
  }
  const double area_pix = s.volume.voxel * s.volume.voxel;
  for (size_t f = 0; f < 6; ++f) {
    r.face_exitance[f].resize(face_size[f]);
    const double unit = 1.0 / (scale * N * area_pix * s.time.bin_width_ps);
    for (size_t i = 0; i < face_size[f]; ++i)
      r.face_exitance[f][i] = static_cast<float>(static_cast<double>(summed->faces[f][i]) * unit);
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
