#pragma once
// Selections between doubles that never become branches. GCC may compile std::min, std::max or
// c ? a : b on data-dependent values into a compare and a jump, which a predictor misses half the
// time (a sort network's exchanges, whether a deposit starts a new entry); these are one SSE2
// instruction each (minsd, maxsd, and / andnot / or).
#include <cstdint>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace femto {

/// b < a ? b : a (as std::min(a, b); a when either is NaN).
inline double select_min(double a, double b) {
#if defined(__SSE2__)
  return _mm_cvtsd_f64(_mm_min_sd(_mm_set_sd(b), _mm_set_sd(a)));  // b < a ? b : a
#else
  return b < a ? b : a;
#endif
}

/// a < b ? b : a (as std::max(a, b); a when either is NaN).
inline double select_max(double a, double b) {
#if defined(__SSE2__)
  return _mm_cvtsd_f64(_mm_max_sd(_mm_set_sd(b), _mm_set_sd(a)));  // b > a ? b : a
#else
  return a < b ? b : a;
#endif
}

/// c ? a : b.
inline double select_if(bool c, double a, double b) {
#if defined(__SSE2__)
  const __m128d mask = _mm_castsi128_pd(_mm_set1_epi64x(-static_cast<int64_t>(c)));
  return _mm_cvtsd_f64(
      _mm_or_pd(_mm_and_pd(mask, _mm_set_sd(a)), _mm_andnot_pd(mask, _mm_set_sd(b))));
#else
  return c ? a : b;
#endif
}

}  // namespace femto
