#pragma once
// The voxel faces a short step crosses, in closed form (most steps of the tissue walk: a mean free
// path is about a voxel): per axis, the distance to the voxel's face ahead and whether the step
// reaches it, then the up to three faces sorted by a fixed network; where an axis has two faces
// (about one step in eight on cube60), the up to six sorted by a larger network; a merge only for
// more. No branch on the data: for a predictor, which axes have a face is a coin flip.
#include <cmath>
#include <cstdint>

#include "core/branchless.h"
#include "core/constants.h"
#include "core/transport/photon.h"
#include "core/transport/tissue_volume.h"
#include "core/vec3.h"
#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>
#endif

namespace femto {

/// The per-axis stage of a step: on each axis the distance to the first face ahead if the step
/// reaches it (else +inf) and the distance between faces (+inf where the direction has no
/// component), and the axes the step moves up along (bit a). Kept for the steps with two or more
/// faces on an axis, whose later stages (crossings_two_per_axis, crossings_from_axis_faces) then
/// need no division.
struct AxisFaces {
  double t[4];  // a fourth slot for the AVX stage's padding lane
  double delta[4];
  int up = 0;
  /// The voxel step on axis a: +1 up, -1 down.
  int step(int a) const { return 2 * ((up >> a) & 1) - 1; }
};

/// The per-axis part, one axis at a time: f.t[a] = the distance along dir from x to the face of
/// voxel `cell` ahead on axis a if it comes before s_stop, else +inf; f.delta, f.up as in
/// AxisFaces; end_cell = the voxel at s_stop; count = the faces before s_stop. Returns false when
/// an axis has a second face before s_stop (end_cell and count are then unspecified; f is not).
inline bool axis_faces_scalar(const LabelVolume& vol, const Vec3& x, const Vec3& dir,
                              const int cell[3], double s_stop, AxisFaces& f, int end_cell[3],
                              int& count) {
  static constexpr double kBeyond[2] = {kInf, 0.0};  // added to a face distance: no face, a face
  bool single = true;
  count = 0;
  f.up = 0;
  // Plain arrays: Vec3's operator[] is a chain of selects where a loop is not unrolled.
  const double o[3] = {vol.origin.x, vol.origin.y, vol.origin.z}, xs[3] = {x.x, x.y, x.z},
               ds[3] = {dir.x, dir.y, dir.z};
  const double h = vol.voxel;
  for (int a = 0; a < 3; ++a) {
    const double d = ds[a];
    const bool up = d > 0;
    const double face = o[a] + (cell[a] + (up ? 1 : 0)) * h;  // as the march computes it
    const double inv_d = 1 / d;                               // one division per axis
    const double ta = d != 0 ? select_max(0.0, (face - xs[a]) * inv_d) : kInf;
    const double delta = d != 0 ? h * std::abs(inv_d) : kInf;
    const bool c = ta < s_stop;
    count += int{c};
    single &= !(ta + delta < s_stop);
    f.t[a] = ta + kBeyond[c];  // +inf sorts an axis without a face last
    f.delta[a] = delta;
    f.up |= int{up} << a;
    end_cell[a] = cell[a] + int{c} * (2 * int{up} - 1);
  }
  return single;
}

#if defined(__AVX2__) && defined(__FMA__)
/// axis_faces_scalar with the three axes in the lanes of one AVX register (one division instead
/// of three); the same operations per lane, so the same results where the scalar code's
/// face = o + (cell + up) h is compiled as a fused multiply-add.
inline bool axis_faces_avx2(const LabelVolume& vol, const Vec3& x, const Vec3& dir,
                            const int cell[3], double s_stop, AxisFaces& f, int end_cell[3],
                            int& count) {
  const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0);
  const __m256d inf = _mm256_set1_pd(kInf), h = _mm256_set1_pd(vol.voxel);
  const __m256d stop = _mm256_set1_pd(s_stop);
  // Lane 3 has d = 0: no face, so it changes neither the count nor the test for second faces.
  const __m256d d = _mm256_set_pd(0.0, dir.z, dir.y, dir.x);
  const __m256d xs = _mm256_set_pd(0.0, x.z, x.y, x.x);
  const __m256d o = _mm256_set_pd(0.0, vol.origin.z, vol.origin.y, vol.origin.x);
  const __m256d c0 = _mm256_cvtepi32_pd(_mm_set_epi32(0, cell[2], cell[1], cell[0]));
  const __m256d up = _mm256_cmp_pd(d, zero, _CMP_GT_OQ);
  const __m256d moving = _mm256_cmp_pd(d, zero, _CMP_NEQ_UQ);  // d != 0 (NaN included)
  const __m256d face = _mm256_fmadd_pd(_mm256_add_pd(c0, _mm256_and_pd(up, one)), h, o);
  const __m256d inv_d = _mm256_div_pd(one, d);
  const __m256d abs_inv_d = _mm256_andnot_pd(_mm256_set1_pd(-0.0), inv_d);
  const __m256d ta = _mm256_blendv_pd(
      inf, _mm256_max_pd(_mm256_mul_pd(_mm256_sub_pd(face, xs), inv_d), zero), moving);
  const __m256d delta = _mm256_blendv_pd(inf, _mm256_mul_pd(h, abs_inv_d), moving);
  const __m256d c = _mm256_cmp_pd(ta, stop, _CMP_LT_OQ);
  const __m256d second = _mm256_cmp_pd(_mm256_add_pd(ta, delta), stop, _CMP_LT_OQ);
  _mm256_storeu_pd(f.t, _mm256_blendv_pd(inf, ta, c));  // +inf sorts an axis without a face last
  _mm256_storeu_pd(f.delta, delta);
  f.up = _mm256_movemask_pd(up);
  const __m256d step = _mm256_blendv_pd(_mm256_set1_pd(-1.0), one, up);
  const __m128i end = _mm256_cvtpd_epi32(_mm256_add_pd(c0, _mm256_and_pd(c, step)));
  int e[4];
  _mm_storeu_si128(reinterpret_cast<__m128i*>(e), end);
  end_cell[0] = e[0], end_cell[1] = e[1], end_cell[2] = e[2];
  count = __builtin_popcount(static_cast<unsigned>(_mm256_movemask_pd(c)));
  return _mm256_movemask_pd(second) == 0;
}
#endif

/// The faces of one axis-by-axis stage, in the fastest form this build has.
inline bool axis_faces(const LabelVolume& vol, const Vec3& x, const Vec3& dir, const int cell[3],
                       double s_stop, AxisFaces& f, int end_cell[3], int& count) {
#if defined(__AVX2__) && defined(__FMA__)
  return axis_faces_avx2(vol, x, dir, cell, s_stop, f, end_cell, count);
#else
  return axis_faces_scalar(vol, x, dir, cell, s_stop, f, end_cell, count);
#endif
}

/// One compare-exchange of a sorting network over faces (distance t, axis ax): minsd, maxsd and an
/// integer blend, no branch (std::min and std::max became jumps); equal distances stay in order.
inline void exchange_faces(double t[], int ax[], int i, int j) {
  const double ti = t[i], tj = t[j];
  const int flip = (ax[i] ^ ax[j]) & -int{tj < ti};
  t[i] = select_min(ti, tj), t[j] = select_max(tj, ti);  // (tj < ti ? tj : ti), the other
  ax[i] ^= flip, ax[j] ^= flip;
}

/// The voxel faces crossed by the piece x + dir s, s in [0, s_stop), in closed form when it
/// crosses at most one face per axis; every voxel on the way must have the label of `cell` (a
/// safe box). Returns false, with `crossed` untouched, when an axis has two or more faces before
/// s_stop; `f` then holds what the later stages need.
inline bool crossings_closed_form(const LabelVolume& vol, const Vec3& x, const Vec3& dir,
                                  const int cell[3], double s_stop, int end_cell[3],
                                  VoxelCrossings& crossed, AxisFaces& f) {
  int count = 0;
  if (!axis_faces(vol, x, dir, cell, s_stop, f, end_cell, count)) return false;
  double* t = f.t;
  // Sort (t, axis) by t: three compare-exchanges; ties keep the lower axis first.
  int ax[3] = {0, 1, 2};
  exchange_faces(t, ax, 0, 1), exchange_faces(t, ax, 1, 2), exchange_faces(t, ax, 0, 1);
  for (int q = 0; q < 3; ++q) crossed.s[q] = t[q], crossed.axis[q] = static_cast<int8_t>(ax[q]);
  crossed.count = count;
  return true;
}

/// The faces crossed by a step that crossings_closed_form declined, from its per-axis stage, when
/// no axis has a third face before s_stop (most such steps): each axis's first and second faces,
/// six distances (+inf where none) sorted by a fixed network, so no branch waits on the data.
/// Returns false, with `crossed` untouched, when an axis has a third face.
inline bool crossings_two_per_axis(const AxisFaces& f, const int cell[3], double s_stop,
                                   int end_cell[3], VoxelCrossings& crossed) {
  double u[6];
  int ax[6] = {0, 1, 2, 0, 1, 2};
  bool fits = true;
  int count = 0;
  for (int a = 0; a < 3; ++a) {
    const double ta = f.t[a], tb = ta + f.delta[a];  // ta is +inf where the axis has no face
    const bool c1 = ta < s_stop, c2 = tb < s_stop;
    fits &= !(tb + f.delta[a] < s_stop);
    u[a] = ta;
    u[3 + a] = select_if(c2, tb, kInf);
    count += int{c1} + int{c2};
    end_cell[a] = cell[a] + (int{c1} + int{c2}) * f.step(a);
  }
  if (!fits) return false;
  // An optimal sorting network for six (12 compare-exchanges, depth 5).
  exchange_faces(u, ax, 0, 5), exchange_faces(u, ax, 1, 3), exchange_faces(u, ax, 2, 4);
  exchange_faces(u, ax, 1, 2), exchange_faces(u, ax, 3, 4);
  exchange_faces(u, ax, 0, 3), exchange_faces(u, ax, 2, 5);
  exchange_faces(u, ax, 0, 1), exchange_faces(u, ax, 2, 3), exchange_faces(u, ax, 4, 5);
  exchange_faces(u, ax, 1, 2), exchange_faces(u, ax, 3, 4);
  for (int q = 0; q < 6; ++q) crossed.s[q] = u[q], crossed.axis[q] = static_cast<int8_t>(ax[q]);
  crossed.count = count;
  return true;
}

/// The faces crossed by a step with three or more faces on an axis (both stages above declined),
/// merged from its per-axis stage: the next face is the nearest of the three axes' next ones,
/// chosen by compares and selects, not by branches (for a predictor the choice is a coin flip,
/// missed about once per face); each axis's faces follow at its spacing. Every voxel on the way
/// must have the label of `cell` (a safe box).
inline void crossings_from_axis_faces(const AxisFaces& f, const int cell[3], double s_stop,
                                      int end_cell[3], VoxelCrossings& crossed) {
  // In registers: an array indexed by the axis would chain each face through a store and a load.
  double tx = f.t[0], ty = f.t[1], tz = f.t[2];
  const double dx = f.delta[0], dy = f.delta[1], dz = f.delta[2];
  const int sx = f.step(0), sy = f.step(1), sz = f.step(2);
  int cx = cell[0], cy = cell[1], cz = cell[2];
  int count = 0;
  while (true) {
    // The march's choice (VoxelDda::axis()): x if tx < ty and tx < tz, else y if ty < tz, else z.
    const bool x_first = (tx < ty) & (tx < tz);
    const bool y_first = !(tx < ty) & (ty < tz);
    const bool z_first = !x_first & !y_first;
    const int a = 2 - 2 * int{x_first} - int{y_first};
    const double s = select_min(select_min(tx, ty), tz);  // t of axis a: ties have one value
    if (s >= s_stop) break;
    if (count < VoxelCrossings::kMax)
      crossed.s[count] = s, crossed.axis[count] = static_cast<int8_t>(a);
    ++count;
    tx = select_if(x_first, tx + dx, tx), cx += int{x_first} * sx;
    ty = select_if(y_first, ty + dy, ty), cy += int{y_first} * sy;
    tz = select_if(z_first, tz + dz, tz), cz += int{z_first} * sz;
  }
  crossed.count = count;
  end_cell[0] = cx, end_cell[1] = cy, end_cell[2] = cz;
}

/// All voxel faces crossed by the piece x + dir s, s in [0, s_stop), inside a safe box (every
/// voxel on the way has the label of `cell`), by the cheapest of the stages above that holds.
inline void crossings_in_safe_box(const LabelVolume& vol, const Vec3& x, const Vec3& dir,
                                  const int cell[3], double s_stop, int end_cell[3],
                                  VoxelCrossings& crossed) {
  AxisFaces f;
  if (!crossings_closed_form(vol, x, dir, cell, s_stop, end_cell, crossed, f) &&
      !crossings_two_per_axis(f, cell, s_stop, end_cell, crossed))
    crossings_from_axis_faces(f, cell, s_stop, end_cell, crossed);
}

}  // namespace femto
