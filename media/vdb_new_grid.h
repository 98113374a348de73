#pragma once
// New OpenVDB grids made by OpenVDB's grid registry. Constructing a grid type in a file compiles
// all of that type's virtual functions (reading, writing, merging, statistics) into it; the
// registry's grids use the copies already compiled in OpenVDB's library. vdb_writer.cpp's three
// grid types took 72 s of g++ -O3 (150 s of clang with ASan) that way, and take 18 s (24 s) now.
#include "media/openvdb_headers.h"

namespace femto {

/// An empty grid of type GridT with the given background. vdb_load::init_openvdb() must have run
/// (it registers the grid types).
template <typename GridT>
typename GridT::Ptr new_vdb_grid(const typename GridT::ValueType& background) {
  const auto grid = openvdb::gridPtrCast<GridT>(openvdb::GridBase::createGrid(GridT::gridType()));
  grid->tree().root().setBackground(background, /*updateChildNodes=*/false);  // the tree is empty
  return grid;
}

}  // namespace femto
