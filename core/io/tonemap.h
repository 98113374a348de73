#pragma once
// Display conversion: exposure, sRGB 8-bit encoding, auto exposure and labelled contact sheets.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace femto {

/// Scales linear RGB (3 floats per pixel) by exposure_scale, clamps to [0,1], applies the sRGB
/// OETF and rounds to 8 bits. NaN and negative values give 0, +inf gives 255.
std::vector<uint8_t> tonemap_srgb8(const float* rgb, size_t pixels, double exposure_scale);

/// Exposure scale mapping the 99th percentile of the Rec. 709 luminance of pixels with finite,
/// positive luminance to 0.9; 1 when there are no such pixels.
double auto_exposure(const float* rgb, size_t pixels);

/// Tiles the frames frame_indices[i] of a film in layout (H,W,T,3) (pixel (y,x) bin t channel c
/// at hwtc[((y*width + x)*bins + t)*3 + c]) into a grid of `columns` tiles (<= 0: about square)
/// separated and framed by a dark gap, all with the same exposure so brightness compares over
/// time (exposure_scale <= 0: auto_exposure over all chosen frames together). labels[i], if
/// present and non-empty, is drawn in the tile's top-left corner with a built-in 5x7 font
/// (digits, a-z (A-Z drawn lower case), space and . , - + = : / ( ) _ % ; others draw '?';
/// '\n' starts a new line), doubled in size on tiles at least 256x128. Returns
/// sheet_width*sheet_height*3 bytes, sRGB.
/// Throws RuntimeError on an empty selection, an out-of-range frame index or bad dimensions.
std::vector<uint8_t> contact_sheet_rgb8(int width, int height, int bins, const float* hwtc,
                                        const std::vector<int>& frame_indices,
                                        const std::vector<std::string>& labels, int columns,
                                        double exposure_scale, int& sheet_width, int& sheet_height);

/// The layout of contact_sheet_rgb8 for frames already mapped to sRGB 8-bit (tiles[i]: width *
/// height * 3 bytes each). Throws RuntimeError on no tiles or a tile of the wrong size.
std::vector<uint8_t> tile_sheet_rgb8(int width, int height,
                                     const std::vector<std::vector<uint8_t>>& tiles,
                                     const std::vector<std::string>& labels, int columns,
                                     int& sheet_width, int& sheet_height);

/// Draws `text` (the label of contact_sheet_rgb8, at `scale` times the font) in the top-left
/// corner of an sRGB 8-bit image of width x height pixels.
void draw_stamp(std::vector<uint8_t>& rgb8, int width, int height, const std::string& text, int scale);

}  // namespace femto
