#include "core/film.h"

#include <cmath>
#include <limits>

#include "core/zeroed_array.h"

namespace femto {

TransientFilm::TransientFilm(int width, int height, const TimeAxis& axis)
    : width_(width), height_(height), axis_(axis) {
  const size_t pixels = static_cast<size_t>(width) * static_cast<size_t>(height);
  resize_in_huge_pages(transient_, pixels * static_cast<size_t>(axis.bins) * 3);
  steady_.assign(pixels * 3, 0.0f);
  before_.assign(pixels * 3, 0.0f);
  after_.assign(pixels * 3, 0.0f);
}

uint64_t TransientFilm::memory_bytes(int width, int height, int bins) {
  const uint64_t pixels = static_cast<uint64_t>(width) * static_cast<uint64_t>(height);
  return pixels * (static_cast<uint64_t>(bins) + 3) * 3 * sizeof(float);
}

void TransientFilm::set_pixel(int x, int y, const double* bins, const RGB& before,
                              const RGB& after, int spp) {
  const size_t p = static_cast<size_t>(y) * static_cast<size_t>(width_) + static_cast<size_t>(x);
  const double inv = 1.0 / spp;
  float* dst = transient_.data() + p * static_cast<size_t>(axis_.bins) * 3;
  double sum[3] = {0, 0, 0};
  for (int i = 0; i < axis_.bins * 3; ++i) {
    dst[i] = static_cast<float>(bins[i] * inv);
    sum[i % 3] += bins[i];
  }
  for (int c = 0; c < 3; ++c) {
    steady_[p * 3 + c] = static_cast<float>(sum[c] * inv);
    before_[p * 3 + c] = static_cast<float>(before[c] * inv);
    after_[p * 3 + c] = static_cast<float>(after[c] * inv);
  }
}

static uint64_t zero_nonfinite_in(std::vector<float>& v) {
  uint64_t n = 0;
  for (float& x : v)
    if (!std::isfinite(x)) {
      x = 0.0f;
      ++n;
    }
  return n;
}

uint64_t TransientFilm::zero_nonfinite() {
  return zero_nonfinite_in(transient_) + zero_nonfinite_in(steady_) + zero_nonfinite_in(before_) +
         zero_nonfinite_in(after_);
}

std::vector<float> TransientFilm::peak_time() const {
  const size_t pixels = static_cast<size_t>(width_) * static_cast<size_t>(height_);
  std::vector<float> out(pixels, std::numeric_limits<float>::quiet_NaN());
  for (size_t p = 0; p < pixels; ++p) {
    const float* px = transient_.data() + p * static_cast<size_t>(axis_.bins) * 3;
    double best = 0.0;
    for (int i = 0; i < axis_.bins; ++i) {
      const double lum = 0.2126 * px[3 * i] + 0.7152 * px[3 * i + 1] + 0.0722 * px[3 * i + 2];
      if (lum > best) {
        best = lum;
        out[p] = static_cast<float>(axis_.bin_center_ps(i));
      }
    }
  }
  return out;
}

std::vector<float> TransientFilm::frame(int t) const {
  const size_t pixels = static_cast<size_t>(width_) * static_cast<size_t>(height_);
  std::vector<float> out(pixels * 3);
  for (size_t p = 0; p < pixels; ++p)
    for (int c = 0; c < 3; ++c)
      out[p * 3 + c] = transient_[(p * static_cast<size_t>(axis_.bins) + static_cast<size_t>(t)) * 3 + c];
  return out;
}

static RGB total_of(const std::vector<float>& img) {
  double s[3] = {0, 0, 0};
  for (size_t i = 0; i < img.size(); ++i) s[i % 3] += img[i];
  return {s[0], s[1], s[2]};
}
RGB TransientFilm::total_steady() const { return total_of(steady_); }
RGB TransientFilm::total_before() const { return total_of(before_); }
RGB TransientFilm::total_after() const { return total_of(after_); }

}  // namespace femto
