#pragma once
// The pictures of a render that people look at: the contact sheet (frames.png), the transient
// video (transient.mp4) and the peak-time picture with its colour bar (peak_time.png). Frames
// are tone mapped as ToneMapSettings say (core/io/tone_mapping.h).
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "core/film.h"
#include "core/io/tone_mapping.h"
#include "core/io/video.h"

namespace femto {

/// The tone curve of every bin of a film: Global and Log use the automatic exposure of the
/// contact sheet's frames (contact_sheet_frames) together, PerFrame that of each bin alone.
/// Log with automatic decades spans from white down to the dimmest bin's own white (over the
/// bins with light), plus one decade, within [1, 12].
std::vector<ToneCurve> frame_tone_curves(const TransientFilm& film,
                                         const ToneMapSettings& settings);

/// The bins the contact sheet shows: up to 16 evenly over the window, first and last included.
std::vector<int> contact_sheet_frames(int bins);

/// The label of bin t on the contact sheet and in the video: its start time, and with PerFrame
/// the radiance shown as white (so frames of different exposure stay comparable).
std::string frame_stamp(const TimeAxis& axis, int t, const ToneMapSettings& settings,
                        const ToneCurve& curve);

/// Writes frames.png at `path`. With Global and no exposure change the bytes are those femto
/// wrote before tone-mapping options existed.
void write_contact_sheet(const std::string& path, const TransientFilm& film,
                         const ToneMapSettings& settings, const std::vector<ToneCurve>& curves);

/// The enlargement of video frames: an integer factor (nearest neighbour, at most 8) bringing
/// the longer side to at least 512 pixels.
int video_upscale(int width, int height);

/// Writes the film as an H.264 MP4 at `path`: one frame per bin, enlarged by video_upscale,
/// each stamped with frame_stamp. Returns what render.json records under "video".
nlohmann::json write_transient_video(const std::string& path, const TransientFilm& film,
                                     const ToneMapSettings& settings,
                                     const std::vector<ToneCurve>& curves, const VideoSpec& spec,
                                     VideoBackend backend);

/// Writes peak_time.png: the peak time (TransientFilm::peak_time) in false colour over the range
/// of its finite values (the window when there are none; widened to a bin when flat), with a
/// colour bar labelled in ps. Returns what render.json records under "peak_time_png".
nlohmann::json write_peak_time_png(const std::string& path, const TransientFilm& film);

/// render.json's "tone_mapping": mode, exposure_stops, log_decades (log), and white_radiance:
/// one number (global, log) or one per bin (per-frame).
nlohmann::json tone_mapping_json(const ToneMapSettings& settings,
                                 const std::vector<ToneCurve>& curves);

}  // namespace femto
