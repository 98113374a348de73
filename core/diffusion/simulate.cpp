#include "core/diffusion/simulate.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "core/diffusion/models.h"
#include "core/distributed/bytes.h"
#include "core/distributed/comm.h"
#include "core/progress.h"
#include "core/sampling.h"

namespace femto::diffusion {

namespace {
constexpr uint64_t kBatch = 4096;  // photons per batch: the unit of work and of ordered reduction

// Traces one photon from its random stream; step(p, rng, seg) moves p along one segment.
template <class Step>
void trace_photon(const Step& step, double t_end, Rng rng, PhotonTally& tally, TallySums& sums) {
  Photon p;
  const double u1 = rng.uniform(), u2 = rng.uniform();
  p.d = sample_uniform_sphere(u1, u2);
  Segment seg;
  while (p.alive && p.t < t_end) {
    step(p, rng, seg);
    tally.add(seg, sums);
  }
  tally.end_photon(sums);
}

// Photons [p0, p1) into sums, in order.
void trace_photons(const PhotonTransport& transport, const DiffusionSetup& setup, uint64_t p0,
                   uint64_t p1, PhotonTally& tally, TallySums& sums) {
  const double t_end = setup.grid.time.t_end_ps();
  // The homogeneous medium's walk inlined (no virtual call per segment); the same segments.
  if (const auto* h = dynamic_cast<const InfiniteHomogeneous*>(&transport)) {
    auto step = [h](Photon& p, Rng& rng, Segment& seg) { h->step(p, rng, seg); };
    for (uint64_t i = p0; i < p1; ++i)
      trace_photon(step, t_end, Rng::for_sample(setup.seed, i, 0), tally, sums);
    return;
  }
  auto step = [&transport](Photon& p, Rng& rng, Segment& seg) { seg = transport.advance(p, rng); };
  for (uint64_t i = p0; i < p1; ++i)
    trace_photon(step, t_end, Rng::for_sample(setup.seed, i, 0), tally, sums);
}
double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// After the first round: how long all N photons will take, and how to stop earlier.
void print_estimate(double seconds, uint64_t done, uint64_t N) {
  if (done >= N || seconds <= 0) return;
  const double total = seconds * static_cast<double>(N) / static_cast<double>(done);
  std::fprintf(stderr,
               "diffusion: about %s for %llu photons; Ctrl-C (or --max-seconds) stops early and "
               "writes the photons traced so far\n",
               format_duration(total).c_str(), static_cast<unsigned long long>(N));
}
}  // namespace

DiffusionResult simulate(const DiffusionSetup& setup) {
  return simulate(setup, InfiniteHomogeneous(setup.medium, setup.absorption));
}

DiffusionResult simulate(const DiffusionSetup& setup, const PhotonTransport& transport) {
  const auto start = std::chrono::steady_clock::now();
  const Grid& grid = setup.grid;
  const TallyLayout layout{grid.shells, grid.time.bins};
  const uint64_t N = setup.photons;
  const int hardware = tbb::info::default_concurrency();  // oneTBB runs no more than this
  const int threads = setup.threads > 0 ? std::min(setup.threads, hardware) : hardware;
  const uint64_t batches = (N + kBatch - 1) / kBatch;
  // Batches in flight per round: two per thread, within 1 GiB of partial sums.
  const size_t slot_bytes = 2 * sizeof(double) * layout.size();
  const distributed::Comm& comm = setup.comm ? *setup.comm : distributed::alone();
  // Rank 0's round size for every rank: rank r does units [first + r slots, first + (r+1) slots).
  const size_t slots = static_cast<size_t>(comm.from_root(std::max<size_t>(
      1, std::min<size_t>(2 * static_cast<size_t>(threads), (size_t{1} << 30) / slot_bytes))));
  const uint64_t round = static_cast<uint64_t>(slots) * static_cast<uint64_t>(comm.size());
  auto own_units = [&](uint64_t first, uint64_t& u0, uint64_t& u1) {
    u0 = std::min(batches, first + static_cast<uint64_t>(comm.rank()) * slots);
    u1 = std::min(batches, u0 + slots);
  };
  uint64_t own_photons = 0;
  for (uint64_t first = 0; first < batches; first += round) {
    uint64_t u0, u1;
    own_units(first, u0, u1);
    if (u1 > u0) own_photons += std::min(N, u1 * kBatch) - u0 * kBatch;
  }

  TallySums total;
  total.reset(layout.size());
  // Statistical batches: contiguous ranges of the work units, fixed by the photon count.
  const uint64_t stat_batches =
      std::clamp<uint64_t>(static_cast<uint64_t>(std::max(setup.batches, 1)), 1, batches);
  std::vector<std::vector<double>> batch_sum(stat_batches, std::vector<double>(layout.size(), 0.0));
  std::vector<uint64_t> batch_photons(stat_batches, 0);
  bool stopped_early = false;
  std::vector<TallySums> partial(slots);
  tbb::enumerable_thread_specific<PhotonTally> tallies([&] { return PhotonTally(grid); });
  Progress progress(own_photons, "diffusion", setup.quiet, "photons");
  tbb::task_arena arena(threads);
  for (uint64_t first = 0; first < batches; first += round) {
    uint64_t u0, u1;
    own_units(first, u0, u1);
    const size_t count = static_cast<size_t>(u1 - u0);
    arena.execute([&] {
      tbb::parallel_for(size_t{0}, count, [&](size_t k) {
        PhotonTally& tally = tallies.local();
        TallySums& sums = partial[k];
        sums.reset(layout.size());
        const uint64_t p0 = (u0 + k) * kBatch, p1 = std::min(N, p0 + kBatch);
        trace_photons(transport, setup, p0, p1, tally, sums);
        progress.add(p1 - p0);
      });
    });
    // Unit order: thread-independent; across ranks, rank r's units follow rank r - 1's.
    auto fold = [&](uint64_t unit, const TallySums& part) {
      total.add(part);
      const uint64_t b = unit * stat_batches / batches;
      std::vector<double>& bs = batch_sum[b];
      for (size_t i = 0; i < bs.size(); ++i) bs[i] += part.sum(i);
      batch_photons[b] += part.photons;
    };
    if (comm.single()) {
      for (size_t k = 0; k < count; ++k) fold(u0 + k, partial[k]);
    } else {
      distributed::ByteWriter mine;
      if (!comm.root())
        for (size_t k = 0; k < count; ++k) {
          mine.put_vector(partial[k].sums);
          mine.put(partial[k].photons);
          mine.put(partial[k].segments);
        }
      TallySums theirs;
      comm.gather(mine.bytes(), [&](int rank, const std::vector<char>& bytes) {
        if (rank == 0) {
          for (size_t k = 0; k < count; ++k) fold(u0 + k, partial[k]);
          return;
        }
        const uint64_t r0 = std::min(batches, first + static_cast<uint64_t>(rank) * slots);
        const uint64_t r1 = std::min(batches, r0 + slots);
        distributed::ByteReader in(bytes);
        for (uint64_t unit = r0; unit < r1; ++unit) {
          theirs.sums = in.get_vector<double>();
          theirs.photons = in.get<uint64_t>();
          theirs.segments = in.get<uint64_t>();
          fold(unit, theirs);
        }
      });
    }
    const double elapsed = seconds_since(start);
    if (first == 0 && !setup.quiet) print_estimate(elapsed, round * kBatch, N);
    const bool more = first + round < batches;
    // Rank 0 decides whether to stop, for every rank.
    if (more && comm.root_flag((setup.stop && setup.stop->load()) ||
                               (setup.max_seconds > 0 && elapsed >= setup.max_seconds))) {
      stopped_early = true;
      break;
    }
  }
  progress.finish();

  DiffusionResult r = estimate(setup, total);
  r.stopped_early = stopped_early;
  r.threads = threads;
  for (size_t b = 0; b < stat_batches; ++b)
    if (batch_photons[b] > 0) {  // batches not reached when stopped early are left out
      r.batch_sum.push_back(std::move(batch_sum[b]));
      r.batch_photons.push_back(batch_photons[b]);
    }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

DiffusionResult estimate(const DiffusionSetup& setup, const TallySums& total) {
  const Grid& grid = setup.grid;
  const TallyLayout layout{grid.shells, grid.time.bins};
  DiffusionResult r;
  r.grid = grid;
  r.photons = total.photons;
  r.segments = total.segments;
  const double n = static_cast<double>(std::max<uint64_t>(total.photons, 1));
  // Mean and standard error of the per-photon integrals at index i, times scale.
  auto estimate = [&](size_t i, double scale, double& mean, double& err) {
    const double m = total.sum(i) / n;
    const double var = n > 1 ? std::max(0.0, (total.sum2(i) - n * m * m) / (n - 1)) : 0.0;
    mean = m * scale;
    err = std::sqrt(var / n) * scale;
  };
  const size_t bins = static_cast<size_t>(grid.time.bins),
               shells = static_cast<size_t>(grid.shells);
  r.u.resize(bins * shells), r.u_err.resize(bins * shells);
  for (auto* v : {&r.energy, &r.energy_err, &r.r2, &r.r2_err, &r.r4, &r.r4_err, &r.unscattered,
                  &r.unscattered_err, &r.single, &r.single_err})
    v->resize(bins);
  const double dt = grid.time.bin_width_ps;
  for (int j = 0; j < grid.time.bins; ++j) {
    for (int i = 0; i < grid.shells; ++i) {
      const size_t c = r.cell(i, j);
      estimate(layout.cell(i, j), 1 / (grid.shell_volume(i) * dt), r.u[c], r.u_err[c]);
    }
    const double t0 = grid.time.bin_start_ps(j);
    estimate(layout.slot(Quantity::Energy, j), 1 / dt, r.energy[j], r.energy_err[j]);
    // Expected energy-time in the bin: exact for a homogeneous medium, else the MC estimate.
    const double exact =
        setup.normalise_by_energy ? r.energy[j] * dt : survival_integral(setup.medium, t0, t0 + dt);
    const double rel_den =
        setup.normalise_by_energy && r.energy[j] > 0 ? r.energy_err[j] / r.energy[j] : 0.0;
    auto ratio = [&](Quantity q, double& mean, double& err) {
      estimate(layout.slot(q, j), exact > 0 ? 1 / exact : 0.0, mean, err);
      if (rel_den > 0 && mean != 0) err = std::hypot(err, std::abs(mean) * rel_den);
    };
    ratio(Quantity::R2, r.r2[j], r.r2_err[j]);
    ratio(Quantity::R4, r.r4[j], r.r4_err[j]);
    ratio(Quantity::Unscattered, r.unscattered[j], r.unscattered_err[j]);
    ratio(Quantity::Single, r.single[j], r.single_err[j]);
  }
  return r;
}

}  // namespace femto::diffusion
