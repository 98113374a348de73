#include "core/tissue/outputs.h"

#include <cmath>
#include <cstdio>

#include "core/io/atomic_file.h"
#include "core/io/nifti.h"
#include "core/io/npy.h"
#include "core/tissue/pulse.h"
#include "core/zeroed_array.h"

namespace femto::tissue {

namespace {
const char* kFaceNames[6] = {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};
}

nlohmann::json summary_json(const Setup& s, const Result& r) {
  using J = nlohmann::json;
  const Balance& b = r.balance;
  const double N = static_cast<double>(r.photons);
  J faces = J::object();
  for (size_t f = 0; f < 6; ++f) faces[kFaceNames[f]] = b.escaped_faces[f] / N;
  J labels = J::array();
  for (size_t l = 1; l < r.absorbed_per_label.size(); ++l)
    if (r.absorbed_per_label[l] != 0 || l < s.volume.optics.size())
      labels.push_back({{"label", l}, {"absorbed_fraction", r.absorbed_per_label[l] / N}});
  J dets = J::array();
  const size_t T = static_cast<size_t>(r.gates), D = s.detectors.size();
  auto num = [](double x) { return std::isfinite(x) ? J(x) : J(nullptr); };
  for (size_t d = 0; d < D; ++d) {
    std::vector<std::vector<double>> batches(static_cast<size_t>(r.batches),
                                             std::vector<double>(T));
    for (size_t k = 0; k < batches.size(); ++k)
      for (size_t g = 0; g < T; ++g) batches[k][g] = r.tpsf_batches[(k * D + d) * T + g];
    const PulseStats ps = pulse_stats(s.time, batches);
    auto stat = [&](const PulseStat& st) {
      return J{{"value_ps", num(st.value)},
               {"jackknife_se_ps", num(st.se)},
               {"ci95_ps", {num(st.ci_lo), num(st.ci_hi)}}};
    };
    J pulse =
        ps.defined
            ? J{{"mean_time", stat(ps.mean)},
                {"rms_width", stat(ps.rms)},
                {"peak_time", stat(ps.peak)},
                {"peak_noise_limited", ps.peak_noise_limited},
                {"width_noise_limited", ps.width_noise_limited},
                {"gaussian_distance",
                 {{"value", num(ps.gaussian_distance.value)},
                  {"jackknife_se", num(ps.gaussian_distance.se)},
                  {"ci95", {num(ps.gaussian_distance.ci_lo), num(ps.gaussian_distance.ci_hi)}},
                  {"noise_floor", num(ps.gaussian_noise)},
                  {"noise_limited", ps.gaussian_noise_limited}}}}
            : J(nullptr);
    dets.push_back({{"index", d},
                    {"position_mm",
                     {s.detectors[d].center.x, s.detectors[d].center.y, s.detectors[d].center.z}},
                    {"radius_mm", s.detectors[d].radius},
                    {"na", s.detectors[d].na},
                    {"detected_fraction", r.detected_weight[d] / N},
                    {"pulse", pulse}});
  }
  const double ms = r.seconds * 1e3;
  return J{{"photons", r.photons},
           {"absorbed_fraction", b.absorbed / N},
           {"absorbed_per_label", labels},
           {"energy_balance",
            {{"launched", b.launched / N},
             {"absorbed", b.absorbed / N},
             {"escaped", b.escaped() / N},
             {"escaped_per_face", faces},
             {"escaped_into_label0_inside_grid", b.escaped_inside / N},
             {"specular_reflection_at_source", b.specular / N},
             {"missed_tissue", b.missed / N},
             {"alive_at_window_end", b.alive / N},
             {"residual", b.residual() / N},
             {"note",
              "fractions of the launched energy; launched = absorbed + escaped + specular + missed "
              "+ alive"}}},
           {"detectors", dets},
           {"detected_photons_recorded", r.detected.size()},
           {"detected_photons_dropped", r.detected.dropped},
           {"counters", {{"scattering_events", r.scatterings}, {"walk_steps", r.segments}}},
           {"timing",
            {{"seconds", r.seconds},
             {"threads", r.threads},
             {"photons_per_ms", ms > 0 ? N / ms : 0.0},
             {"scattering_events_per_second",
              r.seconds > 0 ? static_cast<double>(r.scatterings) / r.seconds : 0.0}}},
           {"batches", r.batches},
           {"fixed_point_quantum_mm", r.fixed_point_quantum}};
}

std::vector<std::string> write_outputs(const std::string& dir, const Setup& s, const Result& r,
                                       nlohmann::json record) {
  std::vector<std::string> files;
  auto path = [&](const std::string& name) {
    files.push_back(name);
    return dir + "/" + name;
  };
  const size_t T = static_cast<size_t>(r.gates);
  if (s.fluence) {
    const FluenceGrid& fg = s.fluence_grid;
    const std::vector<size_t> shape{static_cast<size_t>(fg.n[0]), static_cast<size_t>(fg.n[1]),
                                    static_cast<size_t>(fg.n[2]), T};
    write_npy_float32(path("fluence.npy"), shape, r.fluence.data());
    std::vector<float> buf;
    resize_in_huge_pages(buf, r.fluence.size());
    const float per_ps = static_cast<float>(1.0 / s.time.bin_width_ps);
    for (size_t i = 0; i < buf.size(); ++i) buf[i] = r.fluence[i] * per_ps;
    write_npy_float32(path("fluence_rate.npy"), shape, buf.data());
    if (s.fluence_stderr)
      write_npy_float32(path("fluence_stderr.npy"), shape, r.fluence_err.data());
    // NIfTI order: x fastest, then y, z, t.
    const size_t nx = shape[0], ny = shape[1], nz = shape[2];
    for (size_t i = 0; i < nx; ++i)
      for (size_t j = 0; j < ny; ++j)
        for (size_t k = 0; k < nz; ++k)
          for (size_t g = 0; g < T; ++g)
            buf[((g * nz + k) * ny + j) * nx + i] = r.fluence[((i * ny + j) * nz + k) * T + g];
    const Vec3 h = fg.spacing();
    write_nifti_float32(path("fluence.nii"), {fg.n[0], fg.n[1], fg.n[2], r.gates},
                        {h.x, h.y, h.z, s.time.bin_width_ps * 1e-6}, buf.data(),
                        {fg.origin.x, fg.origin.y, fg.origin.z});
  }
  if (!s.detectors.empty()) {
    const size_t D = s.detectors.size();
    std::vector<float> tpsf(r.tpsf.begin(), r.tpsf.end());
    write_npy_float32(path("tpsf.npy"), {D, T}, tpsf.data());
    std::string csv = "t_ps";
    for (size_t d = 0; d < D; ++d)
      csv += ",exitance_" + std::to_string(d) + ",stderr_" + std::to_string(d);
    csv += "\n";
    for (size_t g = 0; g < T; ++g) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%.9g", s.time.bin_center_ps(static_cast<int>(g)));
      csv += buf;
      for (size_t d = 0; d < D; ++d) {
        std::snprintf(buf, sizeof buf, ",%.9g,%.9g", r.tpsf[d * T + g], r.tpsf_err[d * T + g]);
        csv += buf;
      }
      csv += "\n";
    }
    write_text_atomically(path("tpsf.csv"), csv);
    if (s.save_detected) {
      const DetectedPhotons& dp = r.detected;
      const size_t n = dp.size(), L = static_cast<size_t>(dp.labels);
      std::vector<float> info(n * 4), pp(dp.ppath.begin(), dp.ppath.end());
      for (size_t i = 0; i < n; ++i) {
        info[4 * i] = static_cast<float>(dp.detector[i]);
        info[4 * i + 1] = static_cast<float>(dp.scatterings[i]);
        info[4 * i + 2] = static_cast<float>(dp.weight[i]);
        info[4 * i + 3] = static_cast<float>(dp.time_ps[i]);
      }
      write_npy_float32(path("detected_photons.npy"), {n, 4}, info.data());
      write_npy_float32(path("detected_ppath.npy"), {n, L}, pp.data());
      const std::vector<float> exit(dp.exit.begin(), dp.exit.end());
      write_npy_float32(path("detected_exit.npy"), {n, 6}, exit.data());
    }
  }
  if (s.faces)
    for (size_t f = 0; f < 6; ++f)
      write_npy_float32(
          path(std::string("exitance_") + kFaceNames[f] + ".npy"),
          {static_cast<size_t>(r.face_shape[f][0]), static_cast<size_t>(r.face_shape[f][1]), T},
          r.face_exitance[f].data());
  const nlohmann::json summary = summary_json(s, r);
  write_text_atomically(path("summary.json"), summary.dump(2) + "\n");
  files.push_back("render.json");
  record["tissue_summary"] = summary;
  record["outputs"] = files;  // what an output folder may hold (core/output_folder.h)
  write_text_atomically(dir + "/render.json", record.dump(2) + "\n");
  return files;
}

}  // namespace femto::tissue
