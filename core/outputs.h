#pragma once
// Writes a finished render to its output folder: EXR images and frames, transient.npy, PNG
// previews and render.json. Every file is written to a temporary name and renamed into place,
// and render.json is written last, so its presence marks a complete output.
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "core/film.h"
#include "core/io/tone_mapping.h"
#include "core/io/video.h"

namespace femto {

struct OutputOptions {
  enum class Frames { Files, Multipart, None };
  std::string dir = "femto-out";
  Frames frames = Frames::Files;
  bool previews = true;  ///< steady.png, frames.png and peak_time.png
  ToneMapSettings tonemap;  ///< of frames.png and transient.mp4
  bool video = false;       ///< transient.mp4
  VideoSpec video_spec;     ///< fps and encoder (the size is the film's, enlarged)
  VideoBackend video_backend = default_video_backend();
  int threads = 0;  ///< threads that hash the files (0: all cores), as the render's --threads
};

/// File name of frame t inside the output folder, e.g. "frames/frame_0007_12.500ps.exr".
std::string frame_file_name(const TimeAxis& axis, int t);

/// Writes all outputs; `render_json` gets an "outputs" entry listing the files written, which are
/// also returned. A non-empty `bandwidth_ps` (H x W, the kernel film's last bandwidth per pixel)
/// is written as kernel_bandwidth.exr.
std::vector<std::string> write_outputs(const TransientFilm& film, const OutputOptions& options, nlohmann::json render_json,
                   const std::vector<float>& bandwidth_ps = {});

}  // namespace femto
