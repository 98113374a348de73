// femto render --integrator photons | beams: camera paths plus transient progressive photon
// mapping (photons on surfaces) or transient progressive photon beams (media).
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <tuple>

#include "core/distributed/render_gather.h"
#include "core/integrators/camera_ball.h"
#include "core/integrators/photon_beams.h"
#include "core/integrators/photon_map.h"
#include "core/integrators/ppm_schedule.h"
#include "core/integrators/splat_deposit.h"
#include "core/pixel_sampler.h"
#include "core/progress.h"
#include "core/render.h"
#include "core/render_passes.h"
#include "core/transport/chunked_paths.h"

namespace femto {

namespace {
using passes::kTile;
constexpr int64_t kIndirectChunk = 1024;  // indirect-light paths per task (deterministic order)
/// Indirect-light streams are keyed apart from camera pixels, photons and beams.
constexpr uint64_t kIndirectStream = 0x7000000000000000ULL;
/// Fewest aimed photon or caustic beam paths a pass emits by default.
constexpr int64_t kMinAimedPaths = 100;
}

RenderResult render_photons(const Scene& scene, const RenderOptions& opt) {
  const Camera& camera = scene.camera();
  const int W = camera.width(), H = camera.height();
  const TimeAxis axis = scene.desc().time;
  const TemporalFilter filter(axis, TemporalFilter::Kind::Histogram);
  const VolPathIntegrator integrator(scene, filter, opt.max_depth, opt.roulette);
  const IntegratorKind kind = opt.integrator;
  // Photons: photons on surfaces; beams: all beams; hybrid: photons, caustic beams (with a
  // scattering medium) and light tracing's share.
  const bool use_photons = kind != IntegratorKind::Beams;
  const bool hybrid = kind == IntegratorKind::Hybrid;
  // The hybrid's caustic beams: none without a scattering medium (they would never be gathered).
  const bool caustic_beams = hybrid && has_scattering_medium(scene.desc());
  const bool use_beams = kind == IntegratorKind::Beams || caustic_beams;
  // Photons are stored at diffuse surfaces only: without one, tracing them would cost a share of
  // every pass and change nothing (a hybrid render of glass in fog).
  const bool trace_surface_photons =
      use_photons &&
      std::any_of(scene.desc().shapes.begin(), scene.desc().shapes.end(), [](const ShapeDesc& sh) {
        return sh.material.type == MaterialDesc::Type::Diffuse;
      });
  PhotonDesc photon_opts = opt.photons;
  if (hybrid && photon_opts.per_pass <= 0)
    photon_opts.per_pass = default_hybrid_photons_per_pass(static_cast<int64_t>(W) * H);
  PhotonDesc pd = progressive_settings(
      scene, kind == IntegratorKind::Beams ? IntegratorKind::Beams : IntegratorKind::Photons,
      photon_opts);
  PhotonDesc bd = progressive_settings(
      scene, caustic_beams ? IntegratorKind::Hybrid : IntegratorKind::Beams, opt.photons);
  // Aimed photons and caustic beams (core/transport/caustic_aim.h). Unless per_pass was chosen,
  // a pass emits the default count times the share of plain emission that aiming keeps: as many
  // photons and beams stored as plain emission gave, without tracing the paths that stored
  // nothing. (Aimed at the default count, a point light beside a small glass sphere stored 70x
  // more at 4x the cost of those parts, and lost at equal time: docs/PERFORMANCE.md.)
  const CausticAim aim = opt.photons.aim ? CausticAim(scene.desc(), scene.lights()) : CausticAim{};
  const bool aimed = aim.any() && (trace_surface_photons || caustic_beams);
  const double aim_share = aimed ? aim.path_share(scene.lights()) : 1.0;
  if (aimed && opt.photons.per_pass <= 0) {
    auto scaled = [&](int64_t n) {
      return std::max<int64_t>(kMinAimedPaths, std::llround(static_cast<double>(n) * aim_share));
    };
    if (trace_surface_photons) pd.per_pass = scaled(pd.per_pass);
    if (caustic_beams) bd.per_pass = scaled(bd.per_pass);
  }
  const double R1 = use_photons ? pd.radius : bd.radius,
               T1 = use_photons ? pd.bandwidth_ps : bd.bandwidth_ps;
  PpmSchedule schedule(pd.radius, pd.bandwidth_ps, pd.alpha, pd.beta_t, use_photons ? 2 : 1);
  PpmSchedule beam_schedule(bd.radius, bd.bandwidth_ps, bd.alpha, bd.beta_t, 1);
  const MediumTracker tracker(scene);
  // Hybrid: light paths splatted from their medium vertices once they have scattered (off a
  // diffuse surface or in a medium) or met a surface, and from the diffuse surface vertices the
  // partition gives them, which camera paths then leave out: one light path per four pixels per
  // pass (docs/ARCHITECTURE.md, "Path-space partition"). With no scattering medium, diffuse
  // surface or glossy surface they would splat nothing.
  const bool glossy_surface =
      std::any_of(scene.desc().shapes.begin(), scene.desc().shapes.end(),
                  [](const ShapeDesc& sh) { return sh.material.is_glossy(); });
  const bool light_indirect = hybrid && (caustic_beams || trace_surface_photons || glossy_surface);
  const int64_t indirect_paths = hybrid_light_paths_per_pass(opt, static_cast<int64_t>(W) * H);
  // Photon times include the emission offset: the window end plus the widest pulse spread.
  const double photon_t_cut = axis.t_end_ps() + 8.0 * scene.lights().max_sigma_ps();

  const size_t pixels = static_cast<size_t>(W) * static_cast<size_t>(H);
  // A pass is one photon pass (and one camera sample per pixel); the schedule's state is the
  // pass index, so a resumed render replays it.
  RenderState state = passes::start_state(opt, kind, false, pixels, axis.bins, opt.spp);
  for (int64_t i = 0; i < state.units_done; ++i) {
    schedule.advance();
    beam_schedule.advance();
  }
  const size_t stride = static_cast<size_t>(state.stride);
  const size_t nb = static_cast<size_t>(axis.bins) * 3;
  const int tiles_x = (W + kTile - 1) / kTile, tiles_y = (H + kTile - 1) / kTile;
  const int threads = opt.threads > 0 ? opt.threads : tbb::info::default_concurrency();

  // Across ranks, each pass's photons and beams are traced in chunks shared out over the ranks
  // and every rank receives them all (core/transport/chunked_paths.h); each rank gathers them
  // into its bands of tile rows.
  const distributed::Comm& comm = opt.comm ? *opt.comm : distributed::alone();
  Progress progress(static_cast<uint64_t>(opt.spp), use_beams ? "beam passes" : "photon passes",
                    opt.quiet, "passes");
  progress.add(static_cast<uint64_t>(state.units_done));
  tbb::enumerable_thread_specific<PixelAccumulator> accumulators;
  tbb::enumerable_thread_specific<PathStats> stats;
  PhotonGrid grid;
  BeamBvh bvh;
  LightTracer indirect_tracer(scene, opt.max_depth, photon_t_cut,
                              LightTracer::Vertices::MediumIndirect);
  // A camera inside a scattering medium: the medium points next to the pinhole are the camera
  // paths', gathered from the light pieces through the ball (core/integrators/camera_ball.h).
  const CameraBall ball = caustic_beams ? camera_ball(scene, opt.camera_ball_mm) : CameraBall{};
  indirect_tracer.set_camera_ball(ball);
  BeamBvh ball_bvh;
  uint64_t ball_beams_max = 0;
  // The indirect light paths' splats and ball beams, per chunk; kept across passes (memory reused).
  std::vector<std::tuple<std::vector<Splat>, std::vector<Beam>>> indirect_lists;
  SplatScratch splat_scratch;
  double seconds_beams = 0, seconds_photons = 0, seconds_light_paths = 0, seconds_camera = 0;
  auto since = [](std::chrono::steady_clock::time_point& t0) {  // seconds since t0; t0 = now
    const auto t1 = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(t1 - t0).count();
    t0 = t1;
    return s;
  };
  tbb::task_arena arena(threads);
  arena.execute([&] {
    while (state.units_done < opt.spp) {
      const auto pass_start = std::chrono::steady_clock::now();
      const int pass = static_cast<int>(state.units_done);
      PathStats photon_stats;
      BeamGather beam_gather;
      uint64_t pass_bytes = 0;
      auto part_start = pass_start;
      if (use_beams) {
        const int64_t paths = bd.per_pass;
        std::vector<Beam> beams =
            trace_beams(scene, opt.seed, pass, paths, opt.max_depth, photon_t_cut, photon_stats,
                        caustic_beams, opt.comm, &aim);
        state.photon_max_stored = std::max<uint64_t>(state.photon_max_stored, beams.size());
        bvh.build(std::move(beams), beam_schedule.radius());
        pass_bytes += bvh.memory_bytes();
        beam_gather.bvh = &bvh;
        beam_gather.scene = &scene;
        beam_gather.tracker = &tracker;
        beam_gather.radius = beam_schedule.radius();
        beam_gather.bandwidth_ps = beam_schedule.bandwidth();
        beam_gather.inv_paths = 1.0 / static_cast<double>(paths);
        beam_gather.kernel = TemporalFilter(axis, TemporalFilter::Kind::Kernel, bd.kernel);
        beam_gather.caustic_only = caustic_beams;
        seconds_beams += since(part_start);
      }
      if (trace_surface_photons) {
        std::vector<Photon> photons =
            trace_photons(scene, opt.seed, pass, pd.per_pass, opt.max_depth, photon_t_cut,
                          photon_stats, opt.comm, &aim);
        state.photon_max_stored = std::max<uint64_t>(state.photon_max_stored, photons.size());
        grid.build(std::move(photons), schedule.radius());
        pass_bytes += grid.memory_bytes();
        seconds_photons += since(part_start);
      }
      BeamGather ball_gather;
      if (light_indirect) {
        trace_in_chunk_lists<Splat, Beam>(
            indirect_paths, kIndirectChunk, photon_stats,
            [&](int64_t i, std::vector<Splat>& out, std::vector<Beam>& through_ball,
                PathStats& st) {
              Rng rng = Rng::for_sample(opt.seed, kIndirectStream + static_cast<uint64_t>(pass),
                                        static_cast<uint64_t>(i));
              indirect_tracer.trace(rng, out, st, &through_ball);
            },
            indirect_lists, opt.comm);
        if (ball.active()) {
          // The gather kernel shrinks with the caustic beams' schedule.
          const double ratio = beam_schedule.radius() / bd.radius;
          std::vector<Beam> ball_beams;
          for (const auto& lists : indirect_lists)
            ball_beams.insert(ball_beams.end(), std::get<1>(lists).begin(),
                              std::get<1>(lists).end());
          ball_beams_max = std::max<uint64_t>(ball_beams_max, ball_beams.size());
          ball_bvh.build(std::move(ball_beams), ball.widest(ratio));
          pass_bytes += ball_bvh.memory_bytes();
          ball_gather.bvh = &ball_bvh;
          ball_gather.scene = &scene;
          ball_gather.tracker = &tracker;
          ball_gather.radius = ball.r_min * ratio;
          ball_gather.radius_per_mm = ball.slope * ratio;
          ball_gather.inv_paths = 1.0 / static_cast<double>(indirect_paths);
          ball_gather.kernel = filter;  // the crossing's time is exact: no temporal kernel
          ball_gather.carry_transmittance = true;
          beam_gather.ball = &ball_gather;
          beam_gather.ball_radius = ball.radius;
        }
        // Each rank keeps the splats of its own bands of tile rows (gathered at the end).
        const size_t n_splats = deposit_splats(
            indirect_lists.size(),
            [&](size_t c) -> const std::vector<Splat>& { return std::get<0>(indirect_lists[c]); },
            1.0 / static_cast<double>(indirect_paths), filter, W, H, stride, nb, state.sums.data(),
            [&](size_t p) {
              return comm.owns(static_cast<int64_t>(p / static_cast<size_t>(W)) / kTile);
            },
            splat_scratch);
        pass_bytes += n_splats * (sizeof(Splat) + 2 * sizeof(const Splat*));
        seconds_light_paths += since(part_start);
      }
      state.photon_peak_bytes = std::max(state.photon_peak_bytes, pass_bytes);
      PhotonGather gather;
      gather.grid = &grid;
      gather.radius = schedule.radius();
      gather.bandwidth_ps = schedule.bandwidth();
      gather.inv_emitted = 1.0 / static_cast<double>(pd.per_pass);
      gather.kernel = TemporalFilter(axis, TemporalFilter::Kind::Kernel, pd.kernel);
      state.photon_radius_last = use_photons ? gather.radius : beam_gather.radius;
      state.photon_bandwidth_last_ps = use_photons ? gather.bandwidth_ps : beam_gather.bandwidth_ps;
      // One camera sample per pixel, the same stream as sample `pass` of a path-only render.
      tbb::parallel_for(
          tbb::blocked_range<int>(0, tiles_x * tiles_y, 1), [&](const tbb::blocked_range<int>& r) {
            PixelAccumulator& acc = accumulators.local();
            PathStats& st = stats.local();
            for (int tile = r.begin(); tile != r.end(); ++tile) {
              if (!comm.owns(tile / tiles_x)) continue;
              const int x0 = (tile % tiles_x) * kTile, y0 = (tile / tiles_x) * kTile;
              const int x1 = std::min(x0 + kTile, W), y1 = std::min(y0 + kTile, H);
              for (int y = y0; y < y1; ++y)
                for (int x = x0; x < x1; ++x) {
                  const size_t p =
                      static_cast<size_t>(y) * static_cast<size_t>(W) + static_cast<size_t>(x);
                  acc.reset_touched(axis.bins);  // a full reset per pixel and pass cost ~8%
                  Rng rng = Rng::for_sample(opt.seed, p, static_cast<uint64_t>(pass));
                  double dx, dy;
                  pixel_offset(opt.seed, p, static_cast<uint64_t>(pass), dx, dy);
                  const double fx = x + dx, fy = y + dy;
                  integrator.trace(camera.generate_ray(fx, fy), rng, acc, st,
                                   use_photons ? &gather : nullptr,
                                   use_beams ? &beam_gather : nullptr, light_indirect);
                  double* dst = state.sums.data() + p * stride;
                  for (size_t i = 3 * static_cast<size_t>(acc.touched_first);
                       i < 3 * static_cast<size_t>(acc.touched_last + 1); ++i)
                    dst[i] += acc.bins[i];
                  passes::store_rgb(dst + nb, passes::load_rgb(dst + nb) + acc.before);
                  passes::store_rgb(dst + nb + 3, passes::load_rgb(dst + nb + 3) + acc.after);
                }
            }
          });
      seconds_camera += since(part_start);
      schedule.advance();
      beam_schedule.advance();
      progress.add(1);
      ++state.units_done;
      state.stats += photon_stats;  // across ranks: this rank's chunks (summed at the end)
      if (passes::end_pass(state, stats, pass_start, opt, opt.spp)) break;
    }
  });
  progress.finish();
  distributed::gather_bands(comm, state, W, H, kTile);
  grid = PhotonGrid();
  bvh = BeamBvh();
  ball_bvh = BeamBvh();
  RenderResult result{TransientFilm(W, H, axis), state.stats, state.seconds, threads, {}, {}, 0};
  RenderResult::PhotonReport& rep = result.photons;
  rep.passes = static_cast<int>(state.units_done);
  rep.per_pass = pd.per_pass;
  rep.alpha = pd.alpha;
  rep.beta_t = pd.beta_t;
  rep.radius_first = R1;
  rep.bandwidth_first_ps = T1;
  rep.radius_last = state.photon_radius_last;
  if (light_indirect) rep.hybrid_light_paths = indirect_paths;
  rep.aim = aimed;
  rep.aim_paths_scale = aimed && opt.photons.per_pass <= 0 ? aim_share : 1.0;
  if (opt.photons.aim && (trace_surface_photons || caustic_beams))
    for (int i = 0; i < scene.lights().count(); ++i)
      rep.aim_share.push_back(aim.aims(i) ? aim.solid_angle_ratio(i) : -1.0);
  if (caustic_beams) {
    rep.hybrid_beams = true;
    rep.beam_radius_first = bd.radius;
    rep.beam_bandwidth_first_ps = bd.bandwidth_ps;
    rep.beam_radius_last = beam_schedule.radius();
    rep.beam_bandwidth_last_ps = beam_schedule.bandwidth();
    rep.beam_alpha = bd.alpha;
    rep.beam_beta_t = bd.beta_t;
    rep.beam_paths = bd.per_pass;
    rep.camera_ball_radius = ball.radius;
    rep.camera_ball_slope_first = ball.slope;
    rep.camera_ball_slope_last = ball.slope * beam_schedule.radius() / bd.radius;
    rep.camera_ball_r_min_first = ball.r_min;
    rep.camera_ball_r_min_last = ball.r_min * beam_schedule.radius() / bd.radius;
    rep.camera_ball_beams_max = ball_beams_max;
  }
  rep.bandwidth_last_ps = state.photon_bandwidth_last_ps;
  rep.max_stored_per_pass = state.photon_max_stored;
  rep.peak_photon_bytes = state.photon_peak_bytes;
  rep.seconds_beams = seconds_beams;
  rep.seconds_photons = seconds_photons;
  rep.seconds_light_paths = seconds_light_paths;
  rep.seconds_camera = seconds_camera;
  result.complete = state.units_done == opt.spp;
  result.units_done = state.units_done;
  result.units_total = opt.spp;
  result.unit = "photon passes (one camera sample per pixel each)";
  result.spp_done = state.units_done;
  result.sessions = state.sessions;
  passes::film_from_sums(result.film, state, axis.bins, 1.0, static_cast<int>(state.units_done));
  return result;
}

}  // namespace femto
