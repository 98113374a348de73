#include "core/io/exr.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfInputPart.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfMultiPartOutputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfOutputPart.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfThreading.h>

#include <cstdio>
#include <set>

#include "core/error.h"
#include "core/io/atomic_file.h"

namespace femto {
namespace {

// One float channel to write: its name and where pixel (0,0) lives, with byte strides.
struct ChannelSource {
  std::string name;
  const float* base;
  size_t x_stride, y_stride;
};

// Runs fn, turning OpenEXR/std exceptions into RuntimeError naming the user-visible path.
template <class Fn>
void guarded(const std::string& path, const char* what, Fn&& fn) {
  try {
    fn();
  } catch (const RuntimeError&) {
    throw;
  } catch (const std::exception& e) {
    throw RuntimeError(std::string("cannot ") + what + " EXR '" + path + "': " + e.what());
  }
}

void check_size(const std::string& path, int width, int height) {
  if (width <= 0 || height <= 0)
    throw RuntimeError("cannot write EXR '" + path + "': invalid size " + std::to_string(width) +
                       "x" + std::to_string(height));
}

Imf::Header make_header(int width, int height, const std::vector<ChannelSource>& channels,
                        const ExrAttributes& attrs) {
  Imf::Header header(width, height);
  header.compression() = Imf::ZIP_COMPRESSION;
  for (const auto& c : channels) header.channels().insert(c.name, Imf::Channel(Imf::FLOAT));
  for (const auto& [name, value] : attrs) header.insert(name, Imf::StringAttribute(value));
  return header;
}

Imf::FrameBuffer make_framebuffer(const std::vector<ChannelSource>& channels) {
  Imf::FrameBuffer fb;
  for (const auto& c : channels)
    // OpenEXR's Slice takes char* even for output; it only reads through it here.
    fb.insert(c.name, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(const_cast<float*>(c.base)),
                                 c.x_stride, c.y_stride));
  return fb;
}

void write_single_part(const std::string& path, int width, int height,
                       const std::vector<ChannelSource>& channels, const ExrAttributes& attrs) {
  check_size(path, width, height);
  guarded(path, "write", [&] {
    const Imf::Header header = make_header(width, height, channels, attrs);
    const Imf::FrameBuffer fb = make_framebuffer(channels);
    write_atomically(path, [&](const std::string& tmp) {
      Imf::OutputFile file(tmp.c_str(), header);  // closed (and flushed) by its destructor
      file.setFrameBuffer(fb);
      file.writePixels(height);
    });
  });
}

}  // namespace

void write_exr_rgb(const std::string& path, int width, int height, const float* rgb,
                   const ExrAttributes& string_attributes) {
  if (!rgb) throw RuntimeError("cannot write EXR '" + path + "': null data");
  const size_t xs = 3 * sizeof(float), ys = xs * static_cast<size_t>(width > 0 ? width : 0);
  write_single_part(path, width, height,
                    {{"R", rgb, xs, ys}, {"G", rgb + 1, xs, ys}, {"B", rgb + 2, xs, ys}},
                    string_attributes);
}

void write_exr_channels(const std::string& path, int width, int height,
                        const std::vector<std::string>& channel_names,
                        const std::vector<const float*>& planes,
                        const ExrAttributes& string_attributes) {
  if (channel_names.empty() || channel_names.size() != planes.size())
    throw RuntimeError("cannot write EXR '" + path + "': " + std::to_string(channel_names.size()) +
                       " channel names for " + std::to_string(planes.size()) + " planes");
  std::vector<ChannelSource> channels;
  const size_t ys = sizeof(float) * static_cast<size_t>(width > 0 ? width : 0);
  for (size_t i = 0; i < planes.size(); ++i) {
    if (!planes[i]) throw RuntimeError("cannot write EXR '" + path + "': null plane " + channel_names[i]);
    channels.push_back({channel_names[i], planes[i], sizeof(float), ys});
  }
  write_single_part(path, width, height, channels, string_attributes);
}

void write_exr_multipart_rgb(const std::string& path, int width, int height, int parts,
                             const std::vector<std::string>& part_names, const float* hwtc,
                             const ExrAttributes& string_attributes) {
  check_size(path, width, height);
  if (parts <= 0 || !hwtc) throw RuntimeError("cannot write EXR '" + path + "': no parts or null data");
  std::vector<std::string> names = part_names;
  if (names.empty()) {
    for (int t = 0; t < parts; ++t) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "t%05d", t);
      names.emplace_back(buf);
    }
  }
  // Readers address parts by name, so EXR requires them present and unique.
  const std::set<std::string> unique(names.begin(), names.end());
  if (names.size() != static_cast<size_t>(parts) || unique.size() != names.size() || unique.count(""))
    throw RuntimeError("cannot write EXR '" + path + "': need " + std::to_string(parts) +
                       " unique non-empty part names, got " + std::to_string(names.size()));

  const size_t xs = static_cast<size_t>(parts) * 3 * sizeof(float);
  const size_t ys = xs * static_cast<size_t>(width);
  auto channels_of = [&](int t) {
    const float* p = hwtc + static_cast<size_t>(t) * 3;
    return std::vector<ChannelSource>{{"R", p, xs, ys}, {"G", p + 1, xs, ys}, {"B", p + 2, xs, ys}};
  };
  guarded(path, "write", [&] {
    std::vector<Imf::Header> headers;
    headers.reserve(static_cast<size_t>(parts));
    for (int t = 0; t < parts; ++t) {
      headers.push_back(make_header(width, height, channels_of(t), string_attributes));
      headers.back().setName(names[static_cast<size_t>(t)]);
      headers.back().setType(Imf::SCANLINEIMAGE);
    }
    write_atomically(path, [&](const std::string& tmp) {
      Imf::MultiPartOutputFile file(tmp.c_str(), headers.data(), parts);
      for (int t = 0; t < parts; ++t) {
        Imf::OutputPart part(file, t);
        part.setFrameBuffer(make_framebuffer(channels_of(t)));
        part.writePixels(height);
      }
    });
  });
}

void set_exr_thread_count(int threads) { Imf::setGlobalThreadCount(threads > 0 ? threads : 0); }

void read_exr_rgb(const std::string& path, int& width, int& height, std::vector<float>& rgb) {
  guarded(path, "read", [&] {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i dw = file.header().dataWindow();
    const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
    std::vector<float> data(static_cast<size_t>(w) * static_cast<size_t>(h) * 3);
    Imf::FrameBuffer fb;
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c)
      fb.insert(names[c], Imf::Slice::Make(Imf::FLOAT, data.data() + c, dw, 3 * sizeof(float)));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    width = w;
    height = h;
    rgb = std::move(data);
  });
}

std::vector<std::string> exr_part_names(const std::string& path) {
  std::vector<std::string> names;
  guarded(path, "read", [&] {
    Imf::MultiPartInputFile file(path.c_str());
    for (int i = 0; i < file.parts(); ++i)
      names.push_back(file.header(i).hasName() ? file.header(i).name() : std::string());
  });
  return names;
}

void read_exr_channel(const std::string& path, int part, const std::string& channel, int& width,
                      int& height, std::vector<float>& plane) {
  guarded(path, "read", [&] {
    Imf::MultiPartInputFile file(path.c_str());
    if (part < 0 || part >= file.parts())
      throw RuntimeError("cannot read EXR '" + path + "': no part " + std::to_string(part));
    Imf::InputPart in(file, part);
    if (!in.header().channels().findChannel(channel))
      throw RuntimeError("cannot read EXR '" + path + "': no channel '" + channel + "'");
    const Imath::Box2i dw = in.header().dataWindow();
    const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
    std::vector<float> data(static_cast<size_t>(w) * static_cast<size_t>(h));
    Imf::FrameBuffer fb;
    fb.insert(channel, Imf::Slice::Make(Imf::FLOAT, data.data(), dw));
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
    width = w;
    height = h;
    plane = std::move(data);
  });
}

std::optional<std::string> read_exr_string_attribute(const std::string& path,
                                                     const std::string& name, int part) {
  std::optional<std::string> value;
  guarded(path, "read", [&] {
    Imf::MultiPartInputFile file(path.c_str());
    if (part < 0 || part >= file.parts())
      throw RuntimeError("cannot read EXR '" + path + "': no part " + std::to_string(part));
    if (const auto* a = file.header(part).findTypedAttribute<Imf::StringAttribute>(name))
      value = a->value();
  });
  return value;
}

}  // namespace femto
