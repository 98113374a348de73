#include "core/diffusion/transport.h"

#include <cmath>
#include <limits>

#include "core/constants.h"
#include "media/phase_hg.h"
#include "samplers/distance.h"

namespace femto::diffusion {

InfiniteHomogeneous::InfiniteHomogeneous(const HomogeneousMedium& medium, Absorption absorption)
    : m_(medium), absorption_(absorption), v_(kSpeedOfLight / medium.eta) {}

Segment InfiniteHomogeneous::advance(Photon& p, Rng& rng) const {
  const bool analog = absorption_ == Absorption::Analog;
  const double s = sample_exponential(analog ? m_.sigma_t() : m_.sigma_s, rng.uniform());
  Segment seg;
  seg.x0 = p.x, seg.d = p.d, seg.t0 = p.t, seg.v = v_, seg.w0 = p.w;
  seg.k = analog ? 0.0 : m_.sigma_a * v_;
  seg.scatterings = p.scatterings;
  seg.duration = s / v_;
  if (!std::isfinite(s)) {  // a clear (or purely absorbing, weighted) medium: one endless flight
    p.alive = false;
    p.t = std::numeric_limits<double>::infinity();
    return seg;
  }
  p.x += p.d * s;
  p.t += seg.duration;
  p.w *= std::exp(-seg.k * seg.duration);
  if (analog && rng.uniform() * m_.sigma_t() < m_.sigma_a) {
    p.alive = false;
    return seg;
  }
  p.d = hg_sample(p.d, m_.g, rng.uniform(), rng.uniform()).dir;
  ++p.scatterings;
  return seg;
}

}  // namespace femto::diffusion
