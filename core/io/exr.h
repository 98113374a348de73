#pragma once
// OpenEXR writers (float32, ZIP compression, atomic replace) and small readers for tests.
// OpenEXR headers stay in exr.cpp so users of this header need not see them.
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace femto {

/// (name, value) pairs stored as string attributes in every part's header.
/// Names must not clash with standard EXR attributes ("channels", "compression", ...).
using ExrAttributes = std::vector<std::pair<std::string, std::string>>;

/// Writes interleaved RGB float32 (rgb[(y*width + x)*3 + c], top row first) as channels R, G, B.
void write_exr_rgb(const std::string& path, int width, int height, const float* rgb,
                   const ExrAttributes& string_attributes = {});

/// Writes arbitrary float32 channels, one contiguous width*height plane each (e.g. {"Y"} for a
/// peak-time map in ps). channel_names and planes must have the same, non-zero length.
void write_exr_channels(const std::string& path, int width, int height,
                        const std::vector<std::string>& channel_names,
                        const std::vector<const float*>& planes,
                        const ExrAttributes& string_attributes = {});

/// Writes a multi-part EXR with one RGB part per time bin, reading the film layout (H,W,T,3):
/// pixel (y,x), bin t, channel c is hwtc[((y*width + x)*parts + t)*3 + c]. part_names must hold
/// `parts` unique non-empty names, or be empty to get "t00000", "t00001", ...
void write_exr_multipart_rgb(const std::string& path, int width, int height, int parts,
                             const std::vector<std::string>& part_names, const float* hwtc,
                             const ExrAttributes& string_attributes = {});

/// Sets OpenEXR's global worker-thread count for (de)compression (0 = compress on the calling
/// thread, OpenEXR's default). Worth setting before writing large multi-part files.
void set_exr_thread_count(int threads);

/// Reads R, G, B of a (single-part, or first part of a multi-part) EXR as interleaved floats;
/// absent channels read as 0.
void read_exr_rgb(const std::string& path, int& width, int& height, std::vector<float>& rgb);

/// Names of all parts (an unnamed single-part file yields one empty name).
std::vector<std::string> exr_part_names(const std::string& path);

/// Reads one channel of one part as a width*height plane; throws if the channel is absent.
void read_exr_channel(const std::string& path, int part, const std::string& channel, int& width,
                      int& height, std::vector<float>& plane);

/// A string attribute of one part's header, or nullopt if absent or not a string.
std::optional<std::string> read_exr_string_attribute(const std::string& path,
                                                     const std::string& name, int part = 0);

}  // namespace femto
