#pragma once
// NIfTI-1 single-file volumes (.nii): the 348-byte header, data from vox_offset. Enough for
// label volumes in and float32 results out; no compression (.nii.gz) and no extensions.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace femto {

struct NiftiVolume {
  std::array<int, 4> dim{1, 1, 1, 1};        ///< nx, ny, nz, nt (1 when absent)
  std::array<double, 4> pixdim{1, 1, 1, 1};  ///< voxel size (mm when xyzt_units says so) and dt
  int datatype = 0;                          ///< NIfTI datatype code of the file
  std::vector<float>
      data;  ///< values as float32, x fastest (NIfTI order), scaled by scl_slope/inter
};

/// Reads a .nii file (either byte order; integer and float datatypes). Throws InputError naming
/// the file and the problem (not NIfTI-1, unsupported datatype, truncated data, more than 4 dims,
/// more than 2^28 values).
NiftiVolume read_nifti(const std::string& path);

/// Writes a float32 NIfTI-1 file, atomically. `data` is x fastest (NIfTI order), dims up to 4;
/// pixdim: voxel size in mm and dt in microseconds (NIfTI has no picosecond unit); the sform
/// places voxel centres at origin + (index + 1/2) * pixdim (mm).
void write_nifti_float32(const std::string& path, const std::array<int, 4>& dim,
                         const std::array<double, 4>& pixdim, const float* data,
                         const std::array<double, 3>& origin = {0, 0, 0});

}  // namespace femto
