#pragma once
// H.264 video in an MP4 file from 8-bit sRGB frames, through FFmpeg: its libraries when femto is
// built with them (CMake option FEMTO_VIDEO), else the `ffmpeg` program found on PATH.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace femto {

enum class VideoBackend {
  Libraries,  ///< libavcodec / libavformat / libswscale linked into femto
  Program     ///< frames piped to the `ffmpeg` program
};

struct VideoSpec {
  int width = 0, height = 0;  ///< of the frames given; odd sizes are padded to even (edge repeated)
  int fps = 24;               ///< frames per second, 1..240
  std::string encoder;        ///< FFmpeg encoder name; empty: libx264, else any H.264 encoder
};

/// Whether the FFmpeg libraries are built in (FEMTO_VIDEO).
bool video_libraries_built_in();
/// Libraries when built in, else Program.
VideoBackend default_video_backend();
const char* video_backend_name(VideoBackend backend);

/// Checks, before anything is rendered, that `backend` can encode H.264 with `encoder` (empty:
/// the automatic choice); returns the encoder's name. Throws InputError naming the encoder (not
/// found, or not an H.264 encoder) or the missing `ffmpeg` program (the Program backend asks it
/// with `ffmpeg -h encoder=NAME`).
std::string check_h264_encoder(const std::string& encoder, VideoBackend backend);

/// Writes `frames` frames as H.264 (yuv420p, BT.709, sRGB transfer) in MP4 at `path`, atomically
/// (core/io/atomic_file.h): `frame(i, rgb)` fills rgb (spec.width * spec.height * 3 bytes, top
/// row first) with frame i. Single-threaded encoding, so the bytes do not depend on the machine's
/// core count. Returns the encoder used. Throws RuntimeError naming path on any failure (and
/// InputError as check_h264_encoder); no file is left at path or beside it on failure.
std::string write_mp4_h264(const std::string& path, const VideoSpec& spec, int frames,
                           const std::function<void(int, std::vector<uint8_t>&)>& frame,
                           VideoBackend backend);

}  // namespace femto
