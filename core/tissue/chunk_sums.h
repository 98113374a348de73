#pragma once
// The small sums of one chunk of photons of a tissue run (energy balance, absorbed energy per
// label, TPSFs, detected photons): kept per chunk and reduced in chunk order, so that they do
// not depend on which thread traced which chunk; and their byte form for other MPI ranks.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/distributed/bytes.h"
#include "core/tissue/simulate.h"

namespace femto::tissue {

/// Sums of one chunk of photons, reduced in chunk order (small: independent of the volume size).
struct ChunkSums {
  Balance balance;
  std::vector<double> absorbed;  // per label
  std::vector<double> tpsf;      // det * gates + gate: detected weight
  std::vector<double> detected;  // per detector
  DetectedPhotons records;
  uint64_t scatterings = 0, segments = 0;
  void reset(int labels, size_t tpsf_size, size_t detectors) {
    balance = Balance{};
    absorbed.assign(static_cast<size_t>(labels), 0.0);
    tpsf.assign(tpsf_size, 0.0);
    detected.assign(detectors, 0.0);
    records = DetectedPhotons{};
    scatterings = segments = 0;
  }
};

/// Puts the records in increasing order of `key` (one distinct key per record).
void sort_records(DetectedPhotons& r, const std::vector<uint32_t>& key);

/// A chunk's sums as bytes, bit for bit (for rank 0, core/distributed/comm.h), and back.
void write_chunk(distributed::ByteWriter& w, const ChunkSums& c);
void read_chunk(distributed::ByteReader& in, ChunkSums& c);

}  // namespace femto::tissue
