#pragma once
// Tissue-optics Monte Carlo (docs/tissue.md): photons from a pulsed source walk a labelled volume
// (core/transport/tissue_walk.h) and tallies integrate their segments: time-gated fluence
// (track-length estimator), absorbed energy per label, exitance per face, detector TPSFs and
// per-photon partial path lengths. Everything is per unit launched energy. Bit-identical for any
// thread count: photon i uses Rng::for_sample(seed, i, 0); volume tallies are summed in fixed
// point (integer sums do not depend on order); per-chunk sums are reduced in chunk order.
#include <array>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "core/tissue/setup.h"

namespace femto::tissue {

/// Where the launched energy went (per unit launched energy, summed over photons).
struct Balance {
  double launched = 0;
  double absorbed = 0;
  std::array<double, 6> escaped_faces{};  ///< through the grid's faces -x, +x, -y, +y, -z, +z
  double escaped_inside = 0;              ///< into label-0 voxels inside the grid
  double specular = 0;  ///< reflected at the source's entry surface (source.specular)
  double missed = 0;    ///< source photons that never reached tissue
  double alive = 0;     ///< still in the tissue at the window end
  double escaped() const;
  /// launched - (absorbed + escaped + specular + missed + alive)
  double residual() const;
};

/// Detected photons, in photon order (deterministic), at most Setup::max_detected of them.
struct DetectedPhotons {
  int labels = 0;  ///< columns of `ppath`: labels 1 .. labels (label 0 is outside)
  std::vector<int32_t> detector, scatterings;
  std::vector<double> weight, time_ps;  ///< exit weight (launch weight 1) and exit time
  std::vector<double> ppath;  ///< row-major (photon, label - 1): path length per label, mm
  /// Row-major (photon, 6): exit point x, y, z (mm, on the detector's face) and the direction
  /// leaving the volume (after refraction), the inputs of a fibre or lens model.
  std::vector<double> exit;
  uint64_t dropped = 0;       ///< detected beyond max_detected (counted in the TPSF)
  size_t size() const { return weight.size(); }
};

struct Result {
  int gates = 0, labels = 0;  ///< labels: size of the optics table (label 0 included)
  uint64_t photons = 0, scatterings = 0,
           segments = 0;  ///< segments: walk steps (one per straight piece within a label)
  int threads = 0, batches = 0;
  double seconds = 0;              ///< the whole run
  double trace_seconds = 0;        ///< tracing photons only (no allocation, reductions, results)
  double fixed_point_quantum = 0;  ///< mm per unit of the integer volume sums
  /// Fluence per gate, 1/mm^2, index cell * gates + gate (cell = (i ny + j) nz + k): (X,Y,Z,T).
  std::vector<float> fluence, fluence_err;
  std::vector<double> absorbed_per_label;
  Balance balance;
  /// Exitance through each detector, 1/(mm^2 ps), gate-averaged: index det * gates + gate.
  std::vector<double> tpsf, tpsf_err;
  /// The same per batch (batch * detectors * gates): for confidence intervals of derived values.
  std::vector<double> tpsf_batches;
  std::vector<double> detected_weight;  ///< total detected weight per detector
  /// Exitance images of the faces, 1/(mm^2 ps): face f over its two other axes (in increasing
  /// axis order) and the gates.
  std::array<std::vector<float>, 6> face_exitance;
  std::array<std::array<int, 2>, 6> face_shape{};
  DetectedPhotons detected;
};

/// Memory the run allocates (tallies per thread, sums, results), bytes.
uint64_t memory_bytes(const Setup& setup, int threads);
/// Of which the fluence sums of one thread (cells padded to whole 4^3 bricks x gates x 8 bytes).
uint64_t fluence_bytes_per_thread(const Setup& setup);
/// Threads the run will use for setup.threads.
int threads_for(const Setup& setup);

/// Thrown by simulate() when Setup::stop is set (after the batch that was running).
struct Stopped : std::runtime_error {
  Stopped() : std::runtime_error("the tissue run was stopped") {}
};

Result simulate(const Setup& setup);

}  // namespace femto::tissue
