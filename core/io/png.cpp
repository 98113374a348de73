#include "core/io/png.h"

#include <png.h>

#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>

#include "core/error.h"
#include "core/io/atomic_file.h"

namespace femto {
namespace {

struct ErrorSink {
  char message[256];
};

void error_to_sink(png_structp png, png_const_charp msg) {
  auto* sink = static_cast<ErrorSink*>(png_get_error_ptr(png));
  std::snprintf(sink->message, sizeof sink->message, "%s", msg);
  png_longjmp(png, 1);
}

void ignore_warning(png_structp, png_const_charp) {}

// libpng reports errors by longjmp, which must not skip C++ destructors: this function holds
// only trivially destructible locals and returns false with sink->message set on failure.
bool encode(std::FILE* f, int width, int height, const uint8_t* rgb, ErrorSink* sink) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, sink, error_to_sink,
                                            ignore_warning);
  if (!png) {
    std::snprintf(sink->message, sizeof sink->message, "out of memory");
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (!info || setjmp(png_jmpbuf(png))) {
    if (!info) std::snprintf(sink->message, sizeof sink->message, "out of memory");
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_init_io(png, f);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8,
               PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);  // values are sRGB-encoded
  png_write_info(png, info);
  const size_t row = static_cast<size_t>(width) * 3;
  for (int y = 0; y < height; ++y) png_write_row(png, rgb + static_cast<size_t>(y) * row);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

}  // namespace

void write_png_rgb8(const std::string& path, int width, int height, const uint8_t* rgb) {
  // PNG caps dimensions at 2^31-1; libpng's default user limit is 1e6 per side.
  if (width <= 0 || height <= 0 || width > 1000000 || height > 1000000 || !rgb)
    throw RuntimeError("cannot write PNG '" + path + "': invalid size " + std::to_string(width) +
                       "x" + std::to_string(height) + " or null data");
  write_atomically(path, [&](const std::string& tmp) {
    std::FILE* f = std::fopen(tmp.c_str(), "wb");
    if (!f) throw RuntimeError("cannot write PNG '" + path + "': " + std::strerror(errno));
    ErrorSink sink{};
    errno = 0;  // so a stale errno is not reported as the cause of a libpng error
    const bool ok = encode(f, width, height, rgb, &sink);
    const int err = errno;
    const bool closed = std::fclose(f) == 0;  // flushes: a full disk shows up here
    if (!ok) throw RuntimeError("cannot write PNG '" + path + "': " + sink.message +
                                (err ? std::string(" (") + std::strerror(err) + ")" : ""));
    if (!closed) throw RuntimeError("cannot write PNG '" + path + "': " + std::strerror(errno));
  });
}

}  // namespace femto
