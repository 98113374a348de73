#pragma once
// 8-bit sRGB PNG writer (libpng), atomic replace.
#include <cstdint>
#include <string>

namespace femto {

/// Writes width*height interleaved 8-bit RGB (rgb[(y*width + x)*3 + c], top row first), tagged
/// as sRGB. Throws RuntimeError naming path on invalid size or I/O failure.
void write_png_rgb8(const std::string& path, int width, int height, const uint8_t* rgb);

}  // namespace femto
