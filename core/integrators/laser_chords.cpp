// Laser chords: the segment connections of the path tracer to lasers. A laser lights only its
// beam, a cylinder of its radius, so a camera path that waits for a collision inside a thin beam
// to do next-event estimation finds the beam's light by chance (a 0.5 mm beam in thin fog stayed
// speckled at 4096 samples per pixel). Every medium segment that crosses the beam instead takes
// one point on the crossing, drawn with the decay of the camera-side and laser-side
// transmittances along it, and the collisions do no next-event estimation to lasers.
#include <cmath>

#include "core/integrators/volpath.h"
#include "core/laser_cylinder.h"
#include "media/phase_hg.h"
#include "samplers/interval_exponential.h"

namespace femto {

void VolPathIntegrator::estimate_laser_chords(const Medium& med, int m, const Ray& ray,
                                              double s_surf, double t, double t_factor,
                                              const RGB& beta, Rng& rng, PixelAccumulator& acc,
                                              PathStats& stats) const {
  if (beta.is_black()) return;
  const LightSet& lights = scene_.lights();
  for (int li : lasers_) {
    const Light& L = lights.light(li);
    double a = 0.0, b = s_surf;
    if (!laser_chord(L, ray, a, b)) continue;
    const double u = rng.uniform();
    // Along the chord the camera's transmittance falls as exp(-sigma_t s) and the laser's as
    // exp(-sigma_t s cos), cos the cosine between the ray and the beam: exact in a homogeneous
    // medium; a grid medium takes its coefficient at the chord's middle.
    const double mid = std::isfinite(b) ? 0.5 * (a + b) : a;
    const double sigma_t = med.sigma_t_at(ray.at(mid));
    const double lambda = sigma_t * std::fmax(0.0, 1.0 + dot(ray.d, L.direction));
    const IntervalExponential chord(a, b, lambda);
    if (!chord.valid()) continue;
    const double s = chord.sample(u);
    const Vec3 y = ray.at(s);
    LightSample ls;
    if (!lights.sample(li, y, 0.0, 0.0, ls)) continue;  // the pad of laser_chord
    const double sigma_s = med.type == Medium::Type::Grid
                               ? med.sigma_t_at(y) * med.grid->albedo_at(y)
                               : med.homogeneous.sigma_s;
    if (!(sigma_s > 0)) continue;
    const double f = hg_eval(dot(ray.d, ls.wi), med.g());
    double Tr, dt;
    if (!(f > 0) || !tracker_.connect(y, m, ls.wi, ls.dist, Tr, dt, stats)) continue;
    double tau, opl;
    tracker_.segment_integrals(m, ray, s, tau, opl);
    const double weight = sigma_s * std::exp(-tau) * f * Tr / chord.pdf(s);
    deposit(t + opl * t_factor + dt + L.pulse.offset_ps, L.pulse.sigma_ps(), beta * ls.Li * weight,
            acc, stats);
  }
}

}  // namespace femto
