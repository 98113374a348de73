#pragma once
// Rank 0 collects a camera-side render split by bands of pixel rows (band b rendered by rank
// b % size): every pixel is rendered whole by one rank, so its sums are those of a single process.
#include "core/distributed/comm.h"
#include "core/render.h"

namespace femto::distributed {

/// Collective. Rank 0's state.sums (and bandwidth_ps) receive the bands the other ranks rendered;
/// state.stats becomes the sum of all ranks' counters.
void gather_bands(const Comm& comm, RenderState& state, int width, int height, int band_rows);
/// Collective: rank 0's counters become the sums over all ranks.
void sum_stats(const Comm& comm, PathStats& stats);
/// Pixels in the bands this rank renders.
uint64_t own_band_pixels(const Comm& comm, int width, int height, int band_rows);

}  // namespace femto::distributed
