#pragma once
// The voxel faces a short step crosses, in closed form (most steps of the tissue walk: a mean free
// path is about a voxel): per axis, the distance to the voxel's face ahead and whether the step
// reaches it, then the up to three faces sorted by a fixed network. No branch on the data: for a
// predictor, which axes have a face is a coin flip.
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

/// The per-axis part, one axis at a time: t[a] = the distance along dir from x to the face of
/// voxel `cell` ahead on axis a if it comes before s_stop, else +inf (t has room for 4 doubles:
/// the AVX form stores a fourth lane); end_cell = the voxel at s_stop; count = the faces before
/// s_stop. Returns false when an axis has a second face before s_stop (the march's case; t,
/// end_cell and count are then unspecified).
inline bool axis_faces_scalar(const LabelVolume& vol, const Vec3& x, const Vec3& dir,
                              const int cell[3], double s_stop, double t[4], int end_cell[3],
                              int& count) {
  static constexpr double kBeyond[2] = {kInf, 0.0};  // added to a face distance: no face, a face
  bool single = true;
  count = 0;
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
    t[a] = ta + kBeyond[c];  // +inf sorts an axis without a face last
    end_cell[a] = cell[a] + int{c} * (2 * int{up} - 1);
  }
  return single;
}

#if defined(__AVX2__) && defined(__FMA__)
/// axis_faces_scalar with the three axes in the lanes of one AVX register (one division instead
/// of three); the same operations per lane, so the same results where the scalar code's
/// face = o + (cell + up) h is compiled as a fused multiply-add.
inline bool axis_faces_avx2(const LabelVolume& vol, const Vec3& x, const Vec3& dir,
                            const int cell[3], double s_stop, double t[4], int end_cell[3],
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
  _mm256_storeu_pd(t, _mm256_blendv_pd(inf, ta, c));  // +inf sorts an axis without a face last
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
                       double s_stop, double t[4], int end_cell[3], int& count) {
#if defined(__AVX2__) && defined(__FMA__)
  return axis_faces_avx2(vol, x, dir, cell, s_stop, t, end_cell, count);
#else
  return axis_faces_scalar(vol, x, dir, cell, s_stop, t, end_cell, count);
#endif
}

/// The voxel faces crossed by the piece x + dir s, s in [0, s_stop), in closed form when it
/// crosses at most one face per axis; every voxel on the way must have the label of `cell` (a
/// safe box). Returns false, with `crossed` untouched, when an axis has two or more faces before
/// s_stop (the march's case).
inline bool crossings_closed_form(const LabelVolume& vol, const Vec3& x, const Vec3& dir,
                                  const int cell[3], double s_stop, int end_cell[3],
                                  VoxelCrossings& crossed) {
  double t[4];  // a fourth slot for the AVX stage's padding lane
  int count = 0;
  if (!axis_faces(vol, x, dir, cell, s_stop, t, end_cell, count)) return false;
  // Sort (t, axis) by t: three compare-exchanges (minsd, maxsd and an integer blend: no branch,
  // where std::min and std::max became jumps); ties keep the lower axis first.
  int ax[3] = {0, 1, 2};
  auto exchange = [&](int i, int j) {
    const double ti = t[i], tj = t[j];
    const int flip = (ax[i] ^ ax[j]) & -int{tj < ti};
    // (tj < ti ? tj : ti), (tj < ti ? ti : tj)
    t[i] = select_min(ti, tj), t[j] = select_max(tj, ti);
    ax[i] ^= flip, ax[j] ^= flip;
  };
  exchange(0, 1), exchange(1, 2), exchange(0, 1);
  for (int q = 0; q < 3; ++q) crossed.s[q] = t[q], crossed.axis[q] = static_cast<int8_t>(ax[q]);
  crossed.count = count;
  return true;
}

}  // namespace femto
