#pragma once
// False-colour pictures of scalar images (e.g. peak time in ps) with a labelled colour bar.
#include <string>

#include "core/io/plot.h"

namespace femto {

/// The viridis colour map at f (clamped to [0, 1]): matplotlib's viridis at 9 evenly spaced
/// points, interpolated linearly in sRGB between them. Dark purple at 0, yellow at 1.
Rgb8 viridis(double f);

/// A scalar image in false colour beside a vertical colour bar, and where things are in it.
struct ColourBarPicture {
  Canvas canvas{1, 1};
  int image_x = 0, image_y = 0,
      image_scale = 1;  ///< image pixel (x, y) covers scale x scale pixels
  int bar_x0 = 0, bar_x1 = 0, bar_y0 = 0, bar_y1 = 0;  ///< bar rectangle [x0, x1) x [y0, y1)
};

/// values[y * width + x] (top row first) mapped by viridis((v - lo) / (hi - lo)); NaN (no data)
/// is drawn black. The image is enlarged by an integer factor (nearest neighbour) to at least 256
/// pixels on its longer side (at most 8x). The bar shows hi at its top row and lo at its bottom,
/// row r of the bar at fraction 1 - (r + 0.5) / bar height, with ticks and labels at round values
/// and `title` written vertically beside it. Throws RuntimeError unless lo < hi (both finite)
/// and the size is positive.
ColourBarPicture false_colour_with_bar(const float* values, int width, int height, double lo,
                                       double hi, const std::string& title);

}  // namespace femto
