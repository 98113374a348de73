#include "core/checkpoint.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "core/error.h"
#include "core/io/atomic_file.h"
#include "core/io/sha256.h"

namespace femto {

namespace {
constexpr char kMagic[8] = {'F', 'E', 'M', 'T', 'O', 'C', 'K', 'P'};
constexpr uint32_t kFormat = 1;

const char* kind_name(IntegratorKind k) {
  switch (k) {
    case IntegratorKind::Path: return "path";
    case IntegratorKind::Light: return "light";
    case IntegratorKind::Photons: return "photons";
    default: return "auto";
  }
}

nlohmann::json stats_json(const PathStats& s) {
  return {{"paths", s.paths},
          {"medium_events", s.medium_events},
          {"surface_events", s.surface_events},
          {"null_crossings", s.null_crossings},
          {"max_depth_hits", s.max_depth_hits},
          {"roulette_ends", s.roulette_ends},
          {"nonfinite_dropped", s.nonfinite_dropped},
          {"light_paths", s.light_paths},
          {"photons_stored", s.photons_stored},
          {"photon_gathers", s.photon_gathers},
          {"beams_stored", s.beams_stored},
          {"beam_gathers", s.beam_gathers}};
}

PathStats stats_of(const nlohmann::json& j) {
  PathStats s;
  s.paths = j.at("paths").get<uint64_t>();
  s.medium_events = j.at("medium_events").get<uint64_t>();
  s.surface_events = j.at("surface_events").get<uint64_t>();
  s.null_crossings = j.at("null_crossings").get<uint64_t>();
  s.max_depth_hits = j.at("max_depth_hits").get<uint64_t>();
  s.roulette_ends = j.value("roulette_ends", uint64_t{0});  // absent in checkpoints before it
  s.nonfinite_dropped = j.at("nonfinite_dropped").get<uint64_t>();
  s.light_paths = j.at("light_paths").get<uint64_t>();
  s.photons_stored = j.at("photons_stored").get<uint64_t>();
  s.photon_gathers = j.at("photon_gathers").get<uint64_t>();
  s.beams_stored = j.at("beams_stored").get<uint64_t>();
  s.beam_gathers = j.at("beam_gathers").get<uint64_t>();
  return s;
}

struct Writer {
  std::FILE* f;
  Sha256 hash;
  bool ok = true;
  void put(const void* p, size_t n) {
    if (n == 0) return;
    hash.update(p, n);
    ok = ok && std::fwrite(p, 1, n, f) == n;
  }
  void put_u64(uint64_t v) { put(&v, sizeof v); }
};

struct Reader {
  std::FILE* f;
  const std::string& path;
  uint64_t left;
  Sha256 hash;
  [[noreturn]] void fail(const std::string& why) const {
    throw InputError(path + ": not a usable femto checkpoint: " + why);
  }
  void get(void* p, size_t n) {
    if (n > left) fail("the file is truncated");
    if (n > 0 && std::fread(p, 1, n, f) != n) fail("the file is truncated");
    left -= n;
    hash.update(p, n);
  }
  uint64_t get_u64() {
    uint64_t v = 0;
    get(&v, sizeof v);
    return v;
  }
};
}  // namespace

void write_checkpoint(const std::string& path, const nlohmann::json& fingerprint, const RenderState& s) {
  nlohmann::json meta = {{"fingerprint", fingerprint},
                         {"state",
                          {{"integrator", kind_name(s.integrator)},
                           {"kernel", s.kernel},
                           {"units_done", s.units_done},
                           {"units_total", s.units_total},
                           {"stride", s.stride},
                           {"stats", stats_json(s.stats)},
                           {"seconds", s.seconds},
                           {"sessions", s.sessions},
                           {"photon_radius_last", s.photon_radius_last},
                           {"photon_bandwidth_last_ps", s.photon_bandwidth_last_ps},
                           {"photon_max_stored", s.photon_max_stored},
                           {"photon_peak_bytes", s.photon_peak_bytes}}}};
  const std::string text = meta.dump();
  write_atomically(path, [&](const std::string& tmp) {
    std::FILE* f = std::fopen(tmp.c_str(), "wb");
    if (!f) throw RuntimeError("cannot write '" + path + "': " + std::strerror(errno));
    Writer w{f, {}};
    w.put(kMagic, sizeof kMagic);
    const uint32_t head[2] = {kFormat, 0};
    w.put(head, sizeof head);
    w.put_u64(text.size());
    w.put(text.data(), text.size());
    w.put_u64(s.sums.size());
    w.put(s.sums.data(), s.sums.size() * sizeof(double));
    w.put_u64(s.bandwidth_ps.size());
    w.put(s.bandwidth_ps.data(), s.bandwidth_ps.size() * sizeof(float));
    uint8_t digest[32];
    w.hash.finish(digest);
    w.ok = w.ok && std::fwrite(digest, 1, 32, f) == 32;
    const int err = errno;
    if (std::fclose(f) != 0 || !w.ok)
      throw RuntimeError("cannot write '" + path + "': " + std::strerror(w.ok ? errno : err));
  });
}

bool looks_like_checkpoint(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return false;
  char m[8] = {};
  const bool ok = std::fread(m, 1, 8, f) == 8 && std::memcmp(m, kMagic, 8) == 0;
  std::fclose(f);
  return ok;
}

Checkpoint read_checkpoint(const std::string& path) {
  std::error_code ec;
  const uint64_t size = std::filesystem::file_size(path, ec);
  if (ec) throw InputError(path + ": cannot read the checkpoint: " + ec.message());
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) throw InputError(path + ": cannot read the checkpoint: " + std::strerror(errno));
  struct Closer {
    std::FILE* f;
    ~Closer() { std::fclose(f); }
  } closer{f};
  if (size < 32) throw InputError(path + ": not a usable femto checkpoint: the file is truncated");
  Reader r{f, path, size - 32, {}};
  char m[8];
  r.get(m, 8);
  if (std::memcmp(m, kMagic, 8) != 0) r.fail("it does not start with FEMTOCKP");
  uint32_t head[2];
  r.get(head, sizeof head);
  if (head[0] != kFormat) r.fail("format " + std::to_string(head[0]) + ", this femto reads format 1");
  const uint64_t text_len = r.get_u64();
  if (text_len > r.left) r.fail("the file is truncated");
  std::string text(text_len, '\0');
  r.get(text.data(), text.size());
  const uint64_t n_sums = r.get_u64();
  if (n_sums > r.left / sizeof(double)) r.fail("the file is truncated");
  Checkpoint c;
  c.state.sums.resize(n_sums);
  r.get(c.state.sums.data(), n_sums * sizeof(double));
  const uint64_t n_bw = r.get_u64();
  if (n_bw > r.left / sizeof(float)) r.fail("the file is truncated");
  c.state.bandwidth_ps.resize(n_bw);
  r.get(c.state.bandwidth_ps.data(), n_bw * sizeof(float));
  if (r.left != 0) r.fail("unexpected bytes after the data");
  uint8_t want[32], got[32];
  r.hash.finish(want);
  if (std::fread(got, 1, 32, f) != 32 || std::memcmp(want, got, 32) != 0)
    r.fail("its SHA-256 does not match (the file is corrupt)");
  try {
    const nlohmann::json meta = nlohmann::json::parse(text);
    c.fingerprint = meta.at("fingerprint");
    const nlohmann::json& s = meta.at("state");
    const std::string kind = s.at("integrator").get<std::string>();
    c.state.integrator = kind == "light"     ? IntegratorKind::Light
                         : kind == "photons" ? IntegratorKind::Photons
                                             : IntegratorKind::Path;
    c.state.kernel = s.at("kernel").get<bool>();
    c.state.units_done = s.at("units_done").get<int64_t>();
    c.state.units_total = s.at("units_total").get<int64_t>();
    c.state.stride = s.at("stride").get<int>();
    c.state.stats = stats_of(s.at("stats"));
    c.state.seconds = s.at("seconds").get<double>();
    c.state.sessions = s.at("sessions").get<int>();
    c.state.photon_radius_last = s.at("photon_radius_last").get<double>();
    c.state.photon_bandwidth_last_ps = s.at("photon_bandwidth_last_ps").get<double>();
    c.state.photon_max_stored = s.at("photon_max_stored").get<uint64_t>();
    c.state.photon_peak_bytes = s.at("photon_peak_bytes").get<uint64_t>();
  } catch (const nlohmann::json::exception& e) {
    r.fail(std::string("bad header (") + clip(e.what(), 120) + ")");
  }
  return c;
}

namespace {
std::string short_dump(const nlohmann::json& j) { return clip(j.dump(), 80); }

bool first_difference(const nlohmann::json& a, const nlohmann::json& b, const std::string& at, std::string& out) {
  if (a.is_object() && b.is_object()) {
    for (auto it = a.begin(); it != a.end(); ++it) {
      const std::string key = at + "/" + it.key();
      if (!b.contains(it.key())) {
        out = key + ": checkpoint has " + short_dump(it.value()) + ", this run has none";
        return true;
      }
      if (first_difference(it.value(), b.at(it.key()), key, out)) return true;
    }
    for (auto it = b.begin(); it != b.end(); ++it)
      if (!a.contains(it.key())) {
        out = at + "/" + it.key() + ": checkpoint has none, this run has " + short_dump(it.value());
        return true;
      }
    return false;
  }
  if (a == b) return false;
  out = (at.empty() ? "/" : at) + ": checkpoint has " + short_dump(a) + ", this run has " + short_dump(b);
  return true;
}
}  // namespace

std::string fingerprint_difference(const nlohmann::json& saved, const nlohmann::json& now) {
  std::string out;
  first_difference(saved, now, "", out);
  return out;
}

}  // namespace femto
