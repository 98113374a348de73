#pragma once
// Affine transforms as Mitsuba's <transform> builds them (translate, rotate, scale, matrix,
// lookat; each new operation applied after the previous ones), and their split into femto's
// shape transform (scale, then rotate about x, y, z, then translate).
#include <cmath>

#include "core/constants.h"
#include "core/vec3.h"

namespace femto::mitsuba {

struct Affine {
  double m[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};  ///< rows; column 3 = translation

  Vec3 point(const Vec3& p) const {
    return {m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3],
            m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
            m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3]};
  }
  Vec3 vector(const Vec3& v) const {
    return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
            m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
  }
  Vec3 column(int j) const { return {m[0][j], m[1][j], m[2][j]}; }
  double det() const { return dot(column(0), cross(column(1), column(2))); }
  bool is_identity() const {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 4; ++j)
        if (m[i][j] != (i == j ? 1.0 : 0.0)) return false;
    return true;
  }
  /// Whether the linear part is diagonal (scale and translation only).
  bool is_diagonal() const {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (i != j && m[i][j] != 0.0) return false;
    return true;
  }

  /// `a` applied after `b`.
  friend Affine operator*(const Affine& a, const Affine& b) {
    Affine r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 4; ++j) {
        double s = j == 3 ? a.m[i][3] : 0.0;
        for (int k = 0; k < 3; ++k) s += a.m[i][k] * b.m[k][j];
        r.m[i][j] = s;
      }
    return r;
  }

  static Affine translate(const Vec3& t) {
    Affine a;
    a.m[0][3] = t.x;
    a.m[1][3] = t.y;
    a.m[2][3] = t.z;
    return a;
  }
  static Affine scale(const Vec3& s) {
    Affine a;
    a.m[0][0] = s.x;
    a.m[1][1] = s.y;
    a.m[2][2] = s.z;
    return a;
  }
  /// Right-handed rotation by `deg` degrees about the unit `axis` (Rodrigues).
  static Affine rotate(const Vec3& axis, double deg) {
    const double a = deg * kPi / 180.0, c = std::cos(a), s = std::sin(a), t = 1 - c;
    const Vec3 u = axis;
    Affine r;
    r.m[0][0] = t * u.x * u.x + c;
    r.m[0][1] = t * u.x * u.y - s * u.z;
    r.m[0][2] = t * u.x * u.z + s * u.y;
    r.m[1][0] = t * u.x * u.y + s * u.z;
    r.m[1][1] = t * u.y * u.y + c;
    r.m[1][2] = t * u.y * u.z - s * u.x;
    r.m[2][0] = t * u.x * u.z - s * u.y;
    r.m[2][1] = t * u.y * u.z + s * u.x;
    r.m[2][2] = t * u.z * u.z + c;
    return r;
  }
  /// Mitsuba's look-at frame: local +z towards the target, +y up, +x to the image's left.
  static Affine lookat(const Vec3& origin, const Vec3& target, const Vec3& up) {
    const Vec3 dir = normalize(target - origin);
    const Vec3 left = normalize(cross(normalize(up), dir));
    const Vec3 new_up = cross(dir, left);
    Affine r;
    for (int i = 0; i < 3; ++i) {
      r.m[i][0] = left[i];
      r.m[i][1] = new_up[i];
      r.m[i][2] = dir[i];
      r.m[i][3] = origin[i];
    }
    return r;
  }
};

/// The first tangent of Mitsuba's coordinate_system(n) (Duff et al. 2017), which a <lookat>
/// without 'up' uses as its up direction.
inline Vec3 any_perpendicular(const Vec3& n) {
  const double sign = std::copysign(1.0, n.z);
  const double a = -1.0 / (sign + n.z), b = n.x * n.y * a;
  return {1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x};
}

/// femto's shape transform: p -> Rz Ry Rx (scale * p) + translate (docs/scene-format.md).
struct SplitTransform {
  Vec3 scale{1, 1, 1};
  Vec3 rotate_deg{0, 0, 0};
  Vec3 translate{0, 0, 0};
  bool rotates() const { return rotate_deg.x != 0 || rotate_deg.y != 0 || rotate_deg.z != 0; }
};

/// Splits `a` into scale, rotation and translation; false when its linear part is not a rotation
/// times a positive diagonal scale (shear or mirroring), to relative precision 1e-9.
inline bool split(const Affine& a, SplitTransform& out) {
  const Vec3 c0 = a.column(0), c1 = a.column(1), c2 = a.column(2);
  const double s0 = length(c0), s1 = length(c1), s2 = length(c2);
  if (!(s0 > 0 && s1 > 0 && s2 > 0) || !(a.det() > 0)) return false;
  const Vec3 r0 = c0 / s0, r1 = c1 / s1, r2 = c2 / s2;  // columns of the rotation
  constexpr double kTol = 1e-9;
  if (std::abs(dot(r0, r1)) > kTol || std::abs(dot(r0, r2)) > kTol || std::abs(dot(r1, r2)) > kTol)
    return false;
  out.scale = {s0, s1, s2};
  out.translate = {a.m[0][3], a.m[1][3], a.m[2][3]};
  out.rotate_deg = {0, 0, 0};
  if (a.is_diagonal()) return true;
  // R = Rz(gamma) Ry(beta) Rx(alpha): R[2][0] = -sin(beta), R[2][1] = cos(beta) sin(alpha), ...
  const double R00 = r0.x, R10 = r0.y, R20 = r0.z, R01 = r1.x, R11 = r1.y, R21 = r1.z, R22 = r2.z;
  const double beta = std::asin(std::clamp(-R20, -1.0, 1.0));
  double alpha, gamma;
  if (std::abs(R20) < 1 - 1e-12) {
    alpha = std::atan2(R21, R22);
    gamma = std::atan2(R10, R00);
  } else {  // gimbal lock: only alpha -+ gamma is defined; put it all in alpha
    gamma = 0;
    alpha = R20 < 0 ? std::atan2(R01, R11) : std::atan2(-R01, R11);
  }
  const double to_deg = 180.0 / kPi;
  out.rotate_deg = {alpha * to_deg, beta * to_deg, gamma * to_deg};
  return true;
}

}  // namespace femto::mitsuba
