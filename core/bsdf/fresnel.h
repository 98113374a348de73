#pragma once
// Optics of a smooth interface: reflection, refraction (Snell's law) and Fresnel reflectance.
#include <algorithm>
#include <cmath>

#include "core/spectrum.h"
#include "core/vec3.h"

namespace femto {

/// w reflected about the unit normal m (both pointing away from the surface).
inline Vec3 reflect(const Vec3& w, const Vec3& m) {
  return m * (2.0 * dot(w, m)) - w;
}

/// Fresnel transmittance 1 - R of unpolarised light refracted between cosines cos_i (incident
/// side) and cos_t (far side), eta = index of the far side / index of the incident side. From
/// 1 - r^2 = 4 eta cos_i cos_t / d^2 for both polarisations, so it is symmetric under swapping
/// the sides (cos_i <-> cos_t, eta -> 1 / eta) and precise near grazing angles.
inline double fresnel_transmittance(double cos_i, double cos_t, double eta) {
  const double d_s = cos_i + eta * cos_t, d_p = eta * cos_i + cos_t;
  if (!(d_s > 0.0) || !(d_p > 0.0)) return 0.0;
  const double four_eta_cc = 4.0 * eta * cos_i * cos_t;
  return 0.5 * (four_eta_cc / (d_s * d_s) + four_eta_cc / (d_p * d_p));
}

/// Fresnel coefficients of unpolarised light at a smooth dielectric interface.
struct Fresnel {
  double R = 1.0;      ///< reflectance
  double T = 0.0;      ///< transmittance 1 - R
  double cos_t = 0.0;  ///< cosine of the refracted direction with the far-side normal
};

/// Exact Fresnel equations. cos_i: cosine between the incident direction and the normal on its
/// side, in [0, 1]; eta: index of the far side / index of the incident side (> 0). Total
/// internal reflection gives R = 1, T = 0, cos_t = 0.
inline Fresnel fresnel_dielectric(double cos_i, double eta) {
  cos_i = std::clamp(cos_i, 0.0, 1.0);
  const double sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);  // Snell: sin_t = sin_i / eta
  Fresnel fr;
  if (!(sin2_t < 1.0)) return fr;
  fr.cos_t = std::sqrt(1.0 - sin2_t);
  // Both denominators are > 0: cos_t > 0, and cos_i = 0 only when eta > 1.
  const double r_s = (cos_i - eta * fr.cos_t) / (cos_i + eta * fr.cos_t);
  const double r_p = (eta * cos_i - fr.cos_t) / (eta * cos_i + fr.cos_t);
  fr.R = 0.5 * (r_s * r_s + r_p * r_p);
  fr.T = fresnel_transmittance(cos_i, fr.cos_t, eta);
  return fr;
}

/// w refracted through an interface with unit normal m on w's side (cos_i = dot(w, m) > 0);
/// cos_t (Fresnel::cos_t) and eta (far side / w's side) as for fresnel_dielectric. Unit when w
/// and m are.
inline Vec3 refract(const Vec3& w, const Vec3& m, double cos_i, double cos_t, double eta) {
  return -w / eta + m * (cos_i / eta - cos_t);
}

/// Schlick's approximation of a conductor's Fresnel reflectance, F0 = reflectance at normal
/// incidence, cos_i = cosine between the incident direction and the (micro)normal.
inline RGB fresnel_schlick(const RGB& f0, double cos_i) {
  const double m = 1.0 - std::clamp(cos_i, 0.0, 1.0);
  const double m2 = m * m;
  return f0 + (RGB(1.0) - f0) * (m2 * m2 * m);
}

}  // namespace femto
