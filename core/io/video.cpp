#include "core/io/video.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>

#include "core/error.h"
#include "core/io/atomic_file.h"

#ifdef FEMTO_HAVE_LIBAV
extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}
#endif

extern char** environ;

namespace femto {

namespace {

// Even size for yuv420p (chroma is subsampled by 2 both ways).
int even(int n) {
  return n + (n & 1);
}

void check_spec(const std::string& path, const VideoSpec& spec, int frames) {
  if (spec.width <= 0 || spec.height <= 0 || spec.width > 16384 || spec.height > 16384 ||
      frames <= 0 || spec.fps < 1 || spec.fps > 240)
    throw RuntimeError(path + ": cannot write a video of " + std::to_string(frames) +
                       " frames of " + std::to_string(spec.width) + " x " +
                       std::to_string(spec.height) + " at " + std::to_string(spec.fps) + " fps");
}

// Frame i from the caller, padded to the even size by repeating the last column and row (black
// would bleed into the subsampled chroma of the edge pixels).
void padded_frame(const VideoSpec& spec, int i,
                  const std::function<void(int, std::vector<uint8_t>&)>& frame,
                  std::vector<uint8_t>& rgb, std::vector<uint8_t>& padded) {
  const size_t w = static_cast<size_t>(spec.width), h = static_cast<size_t>(spec.height);
  const size_t wp = static_cast<size_t>(even(spec.width)),
               hp = static_cast<size_t>(even(spec.height));
  rgb.assign(w * h * 3, 0);
  frame(i, rgb);
  if (rgb.size() != w * h * 3)
    throw RuntimeError("video frame " + std::to_string(i) + " has the wrong size");
  padded.resize(wp * hp * 3);
  for (size_t y = 0; y < hp; ++y) {
    const size_t sy = std::min(y, h - 1);
    std::copy_n(&rgb[sy * w * 3], w * 3, &padded[y * wp * 3]);
    if (wp > w) std::copy_n(&rgb[(sy * w + w - 1) * 3], 3, &padded[(y * wp + w) * 3]);
  }
}

// The `ffmpeg` program on PATH, or "".
std::string find_ffmpeg_program() {
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "/usr/bin:/bin";
  size_t start = 0;
  while (start <= dirs.size()) {
    size_t end = dirs.find(':', start);
    if (end == std::string::npos) end = dirs.size();
    std::string dir = dirs.substr(start, end - start);
    if (dir.empty()) dir = ".";
    const std::string candidate = dir + "/ffmpeg";
    struct stat st {};
    if (::stat(candidate.c_str(), &st) == 0 && S_ISREG(st.st_mode) &&
        ::access(candidate.c_str(), X_OK) == 0)
      return candidate;
    start = end + 1;
  }
  return "";
}

// Last non-empty line of a text file (ffmpeg's error), clipped.
std::string last_line(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return clip(last, 200);
}

std::string write_with_program(const std::string& path, const std::string& tmp,
                               const VideoSpec& spec, int frames,
                               const std::function<void(int, std::vector<uint8_t>&)>& frame) {
  const std::string program = find_ffmpeg_program();
  if (program.empty()) throw InputError("--video: no `ffmpeg` program on PATH");
  const std::string encoder = spec.encoder.empty() ? "libx264" : spec.encoder;
  const std::string size =
      std::to_string(even(spec.width)) + "x" + std::to_string(even(spec.height));
  const std::string log = tmp + ".log";
  // clang-format off
  std::vector<std::string> args = {
      "ffmpeg", "-nostdin", "-hide_banner", "-loglevel", "error",
      "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", size, "-framerate", std::to_string(spec.fps), "-i", "pipe:0",
      // BT.709 limited range, as the stream is tagged (swscale's default matrix is BT.601).
      "-vf", "scale=out_color_matrix=bt709:out_range=tv", "-c:v", encoder, "-threads", "1",
      "-pix_fmt", "yuv420p", "-color_primaries", "bt709", "-color_trc", "iec61966-2-1",
      "-colorspace", "bt709", "-color_range", "tv"};
  // clang-format on
  if (encoder == "libx264") args.insert(args.end(), {"-crf", "18", "-preset", "medium"});
  args.insert(args.end(), {"-f", "mp4", "-y", tmp});
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  // ffmpeg's messages go to a file beside the output (a pipe could fill and block it).
  const int log_fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (log_fd < 0) throw RuntimeError(path + ": cannot create the file: " + std::strerror(errno));
  int pipe_fd[2];
  if (::pipe2(pipe_fd, O_CLOEXEC) != 0) {
    const int err = errno;
    ::close(log_fd);
    ::unlink(log.c_str());
    throw RuntimeError(path + ": cannot start ffmpeg: " + std::strerror(err));
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, pipe_fd[0], 0);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_adddup2(&actions, log_fd, 2);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t none, defaults;
  sigemptyset(&none);
  sigemptyset(&defaults);
  sigaddset(&defaults, SIGPIPE);
  sigaddset(&defaults, SIGINT);
  sigaddset(&defaults, SIGTERM);
  // femto blocks SIGINT/SIGTERM in its threads (apps/stop_signals.h): ffmpeg gets the defaults.
  posix_spawnattr_setsigmask(&attr, &none);
  posix_spawnattr_setsigdefault(&attr, &defaults);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, program.c_str(), &actions, &attr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  ::close(pipe_fd[0]);
  ::close(log_fd);
  if (spawned != 0) {
    ::close(pipe_fd[1]);
    ::unlink(log.c_str());
    throw RuntimeError(path + ": cannot start " + program + ": " + std::strerror(spawned));
  }
  // A dead ffmpeg must give an error, not kill femto with SIGPIPE.
  struct sigaction ignore {
  }, previous{};
  ignore.sa_handler = SIG_IGN;
  ::sigaction(SIGPIPE, &ignore, &previous);
  std::string failure;
  try {
    std::vector<uint8_t> rgb, padded;
    for (int i = 0; i < frames && failure.empty(); ++i) {
      padded_frame(spec, i, frame, rgb, padded);
      size_t done = 0;
      while (done < padded.size()) {
        const ssize_t n = ::write(pipe_fd[1], padded.data() + done, padded.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
          failure = "ffmpeg stopped reading frames";
          break;
        }
        done += static_cast<size_t>(n);
      }
    }
  } catch (...) {
    ::close(pipe_fd[1]);
    int status = 0;
    ::waitpid(pid, &status, 0);
    ::sigaction(SIGPIPE, &previous, nullptr);
    ::unlink(log.c_str());
    throw;
  }
  ::close(pipe_fd[1]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  ::sigaction(SIGPIPE, &previous, nullptr);
  const std::string message = last_line(log);
  ::unlink(log.c_str());
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || !failure.empty())
    throw RuntimeError(path + ": ffmpeg (encoder " + encoder + ") failed" +
                       (message.empty() ? std::string() : ": " + message));
  return encoder;
}

#ifdef FEMTO_HAVE_LIBAV
std::string av_error(int code) {
  char buf[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, buf, sizeof buf);
  return buf;
}

const AVCodec* find_encoder(const std::string& name) {
  if (!name.empty()) return avcodec_find_encoder_by_name(name.c_str());
  const AVCodec* codec = avcodec_find_encoder_by_name("libx264");
  return codec ? codec : avcodec_find_encoder(AV_CODEC_ID_H264);
}

struct CodecContextFree {
  void operator()(AVCodecContext* c) const { avcodec_free_context(&c); }
};
struct FrameFree {
  void operator()(AVFrame* f) const { av_frame_free(&f); }
};
struct PacketFree {
  void operator()(AVPacket* p) const { av_packet_free(&p); }
};
struct SwsFree {
  void operator()(SwsContext* s) const { sws_freeContext(s); }
};
// The muxer with its file: closed and freed together.
struct FormatFree {
  void operator()(AVFormatContext* f) const {
    if (f->pb) avio_closep(&f->pb);
    avformat_free_context(f);
  }
};

std::string write_with_libraries(const std::string& path, const std::string& tmp,
                                 const VideoSpec& spec, int frames,
                                 const std::function<void(int, std::vector<uint8_t>&)>& frame) {
  av_log_set_level(AV_LOG_ERROR);  // no encoder statistics on stderr
  const AVCodec* codec = find_encoder(spec.encoder);
  if (!codec)
    throw InputError("--video-encoder " + clip(spec.encoder) + ": no such FFmpeg encoder");
  const int W = even(spec.width), H = even(spec.height);
  auto fail = [&](const std::string& what, int code) {
    return RuntimeError(path + ": " + what + ": " + av_error(code));
  };

  AVFormatContext* raw_format = nullptr;
  int err = avformat_alloc_output_context2(&raw_format, nullptr, "mp4", tmp.c_str());
  if (err < 0 || !raw_format) throw fail("cannot start the MP4 muxer", err);
  std::unique_ptr<AVFormatContext, FormatFree> format(raw_format);
  AVStream* stream = avformat_new_stream(format.get(), nullptr);
  std::unique_ptr<AVCodecContext, CodecContextFree> ctx(avcodec_alloc_context3(codec));
  if (!stream || !ctx) throw RuntimeError(path + ": out of memory starting the encoder");
  ctx->width = W;
  ctx->height = H;
  ctx->time_base = AVRational{1, spec.fps};
  ctx->framerate = AVRational{spec.fps, 1};
  ctx->pix_fmt = AV_PIX_FMT_YUV420P;
  ctx->color_primaries = AVCOL_PRI_BT709;
  ctx->color_trc = AVCOL_TRC_IEC61966_2_1;
  ctx->colorspace = AVCOL_SPC_BT709;
  ctx->color_range = AVCOL_RANGE_MPEG;
  ctx->thread_count = 1;  // bytes independent of the machine
  if (format->oformat->flags & AVFMT_GLOBALHEADER) ctx->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
  if (std::strcmp(codec->name, "libx264") == 0) {
    av_opt_set(ctx->priv_data, "crf", "18", 0);  // visually lossless for previews
    av_opt_set(ctx->priv_data, "preset", "medium", 0);
  }
  if ((err = avcodec_open2(ctx.get(), codec, nullptr)) < 0)
    throw fail(std::string("cannot open the encoder ") + codec->name, err);
  if ((err = avcodec_parameters_from_context(stream->codecpar, ctx.get())) < 0)
    throw fail("cannot set the stream parameters", err);
  stream->time_base = ctx->time_base;
  if ((err = avio_open(&format->pb, tmp.c_str(), AVIO_FLAG_WRITE)) < 0)
    throw fail("cannot create the file", err);
  if ((err = avformat_write_header(format.get(), nullptr)) < 0)
    throw fail("cannot write the MP4 header", err);

  std::unique_ptr<SwsContext, SwsFree> sws(sws_getContext(
      W, H, AV_PIX_FMT_RGB24, W, H, AV_PIX_FMT_YUV420P, SWS_BICUBIC, nullptr, nullptr, nullptr));
  std::unique_ptr<AVFrame, FrameFree> yuv(av_frame_alloc());
  std::unique_ptr<AVPacket, PacketFree> packet(av_packet_alloc());
  if (!sws || !yuv || !packet) throw RuntimeError(path + ": out of memory starting the encoder");
  // sRGB values to BT.709 limited-range YCbCr, as the stream is tagged.
  const int* bt709 = sws_getCoefficients(SWS_CS_ITU709);
  sws_setColorspaceDetails(sws.get(), bt709, 1, bt709, 0, 0, 1 << 16, 1 << 16);
  yuv->format = AV_PIX_FMT_YUV420P;
  yuv->width = W;
  yuv->height = H;
  if ((err = av_frame_get_buffer(yuv.get(), 0)) < 0) throw fail("cannot allocate a frame", err);

  // Sends one frame (nullptr: flush) and writes the packets it completes.
  auto encode = [&](AVFrame* f) {
    if ((err = avcodec_send_frame(ctx.get(), f)) < 0) throw fail("encoding failed", err);
    while ((err = avcodec_receive_packet(ctx.get(), packet.get())) >= 0) {
      // One frame long: the MP4 edit list ends at the last frame's pts + duration, so a
      // missing duration would cut the last frame from playback.
      if (packet->duration == 0) packet->duration = 1;
      av_packet_rescale_ts(packet.get(), ctx->time_base, stream->time_base);
      packet->stream_index = stream->index;
      err = av_interleaved_write_frame(format.get(), packet.get());  // takes the packet's data
      if (err < 0) throw fail("cannot write to the file", err);
    }
    if (err != AVERROR(EAGAIN) && err != AVERROR_EOF) throw fail("encoding failed", err);
  };
  std::vector<uint8_t> rgb, padded;
  for (int i = 0; i < frames; ++i) {
    padded_frame(spec, i, frame, rgb, padded);
    if ((err = av_frame_make_writable(yuv.get())) < 0) throw fail("cannot write a frame", err);
    const uint8_t* src[1] = {padded.data()};
    const int stride[1] = {3 * W};
    sws_scale(sws.get(), src, stride, 0, H, yuv->data, yuv->linesize);
    yuv->pts = i;
    encode(yuv.get());
  }
  encode(nullptr);
  if ((err = av_write_trailer(format.get())) < 0) throw fail("cannot finish the MP4 file", err);
  if ((err = avio_closep(&format->pb)) < 0) throw fail("cannot close the file", err);
  return codec->name;
}
#endif

}  // namespace

bool video_libraries_built_in() {
#ifdef FEMTO_HAVE_LIBAV
  return true;
#else
  return false;
#endif
}

VideoBackend default_video_backend() {
  return video_libraries_built_in() ? VideoBackend::Libraries : VideoBackend::Program;
}

const char* video_backend_name(VideoBackend backend) {
  return backend == VideoBackend::Libraries ? "ffmpeg libraries" : "ffmpeg program";
}

std::string check_h264_encoder(const std::string& encoder, VideoBackend backend) {
  if (backend == VideoBackend::Program) {
    if (find_ffmpeg_program().empty())
      throw InputError(std::string("--video: no H.264 encoder: ") +
                       (video_libraries_built_in()
                            ? "the ffmpeg program was asked for"
                            : "femto is built without the FFmpeg libraries (FEMTO_VIDEO)") +
                       " and there is no `ffmpeg` program on PATH; install ffmpeg (Debian: apt-get "
                       "install ffmpeg)");
    const std::string name = encoder.empty() ? "libx264" : encoder;
    if (name.find_first_not_of(
            "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-") !=
        std::string::npos)
      throw InputError("--video-encoder " + clip(encoder) + ": not an FFmpeg encoder name");
    // "Encoder libx264 [libx264 H.264 / AVC / ...]:" for an H.264 encoder.
    std::string help;
    if (FILE* p = ::popen(
            (find_ffmpeg_program() + " -hide_banner -h encoder=" + name + " 2>&1").c_str(), "r")) {
      char buf[512];
      if (std::fgets(buf, sizeof buf, p)) help = buf;
      while (std::fgets(buf, sizeof buf, p)) {
      }
      ::pclose(p);
    }
    if (help.rfind("Encoder ", 0) != 0)
      throw InputError("--video-encoder " + clip(name) +
                       ": the ffmpeg program has no such encoder (see ffmpeg -encoders)");
    if (help.find("H.264") == std::string::npos)
      throw InputError("--video-encoder " + clip(name) + ": not an H.264 encoder (e.g. libx264)");
    return name;
  }
#ifdef FEMTO_HAVE_LIBAV
  const AVCodec* codec = find_encoder(encoder);
  if (!codec) {
    if (encoder.empty())
      throw InputError("--video: this FFmpeg has no H.264 encoder (libx264 or another)");
    throw InputError("--video-encoder " + clip(encoder) +
                     ": no such FFmpeg encoder (see ffmpeg -encoders)");
  }
  if (codec->id != AV_CODEC_ID_H264 || !av_codec_is_encoder(codec))
    throw InputError("--video-encoder " + clip(encoder) + ": not an H.264 encoder (e.g. libx264)");
  return codec->name;
#else
  throw InputError("--video: femto is built without the FFmpeg libraries (FEMTO_VIDEO)");
#endif
}

std::string write_mp4_h264(const std::string& path, const VideoSpec& spec, int frames,
                           const std::function<void(int, std::vector<uint8_t>&)>& frame,
                           VideoBackend backend) {
  check_spec(path, spec, frames);
  VideoSpec checked = spec;
  checked.encoder = check_h264_encoder(spec.encoder, backend);  // H.264 only, never another codec
  std::string used;
  write_atomically(path, [&](const std::string& tmp) {
#ifdef FEMTO_HAVE_LIBAV
    if (backend == VideoBackend::Libraries) {
      used = write_with_libraries(path, tmp, checked, frames, frame);
      return;
    }
#endif
    used = write_with_program(path, tmp, checked, frames, frame);
  });
  return used;
}

}  // namespace femto
