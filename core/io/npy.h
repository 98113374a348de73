#pragma once
// NumPy .npy arrays (format 1.0, or 2.0 when the header does not fit in 64 KiB).
#include <cstddef>
#include <string>
#include <vector>

namespace femto {

/// Atomically writes a little-endian float32 ('<f4'), C-order array of the given shape
/// (an empty shape is a 0-d scalar). data holds prod(shape) floats. Throws RuntimeError naming path.
void write_npy_float32(const std::string& path, const std::vector<size_t>& shape, const float* data);

/// Reads a file written by write_npy_float32 (or numpy.save of a C-order float32 array).
/// Throws RuntimeError naming path on I/O errors, a bad magic/version, a dtype other than
/// '<f4', Fortran order, a malformed header or a data size that does not match the shape.
void read_npy_float32(const std::string& path, std::vector<size_t>& shape, std::vector<float>& data);

}  // namespace femto
