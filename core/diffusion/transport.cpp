#include "core/diffusion/transport.h"

#include <cmath>
#include <limits>

#include "core/constants.h"
#include "media/phase_hg.h"
#include "samplers/distance.h"
#include "samplers/medium_distance.h"

namespace femto::diffusion {

InfiniteHomogeneous::InfiniteHomogeneous(const HomogeneousMedium& medium, Absorption absorption)
    : space_(TissueOptics{medium.sigma_a, medium.sigma_s, medium.g, medium.eta}),
      settings_{absorption, std::numeric_limits<double>::infinity()} {}

Segment InfiniteHomogeneous::advance(Photon& p, Rng& rng) const {
  Segment seg;
  walk_step(space_, settings_, p, rng, seg);
  return seg;
}

VoxelTransport::VoxelTransport(const GridMedium& grid, double g, const Vec3& origin)
    : grid_(grid), g_(g), origin_(origin) {}

Segment VoxelTransport::advance(Photon& p, Rng& rng) const {
  if (p.tau_left < 0) p.tau_left = unit_exponential(rng.uniform());
  Segment seg;
  seg.x0 = p.x, seg.d = p.d, seg.t0 = p.t, seg.w0 = p.w, seg.k = 0.0;
  seg.scatterings = p.scatterings;
  GridMedium::Walker walker(grid_, Ray{origin_ + p.x, p.d}, std::numeric_limits<double>::infinity());
  MediumSegment ms;
  if (!walker.next(ms) || !std::isfinite(ms.s1)) {  // left the grid for good: one endless flight
    seg.v = kSpeedOfLight / grid_.eta_outside();
    seg.duration = std::numeric_limits<double>::infinity();
    p.alive = false;
    p.t = std::numeric_limits<double>::infinity();
    return seg;
  }
  const double L = ms.s1 - ms.s0;
  const double tau = ms.sigma_t.integral(L);
  const bool collides = tau >= p.tau_left && tau > 0;
  const double s = collides ? invert_integral(ms.sigma_t, p.tau_left, L) : L;
  const double opl = ms.eta.integral(s);
  seg.duration = opl / kSpeedOfLight;
  seg.v = s > 0 ? s / seg.duration : kSpeedOfLight / ms.eta(0);
  p.x += p.d * s;
  p.t += seg.duration;
  if (!collides) {
    p.tau_left -= tau;
    if (!(L > 0)) p.x += p.d * (1e-9 * (1.0 + max_abs_component(origin_ + p.x)));  // never stall
    return seg;
  }
  p.tau_left = -1;
  if (rng.uniform() >= grid_.albedo_at(origin_ + p.x)) {
    p.alive = false;
    return seg;
  }
  const double u2 = rng.uniform();  // the azimuth's first (a stated order, as GCC had it)
  const double u1 = rng.uniform();
  p.d = hg_sample(p.d, g_, u1, u2).dir;
  ++p.scatterings;
  return seg;
}

}  // namespace femto::diffusion
