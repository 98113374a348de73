#include "core/io/nifti.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>

#include "core/error.h"
#include "core/io/atomic_file.h"

namespace femto {

namespace {
constexpr size_t kHeader = 348;
constexpr size_t kDataOffset = 352;  // header + 4-byte extension flag

// Header field offsets (NIfTI-1 standard).
constexpr size_t kDim = 40, kDatatype = 70, kBitpix = 72, kPixdim = 76, kVoxOffset = 108,
                 kSclSlope = 112, kSclInter = 116, kXyztUnits = 123, kDescrip = 148,
                 kQformCode = 252, kSformCode = 254, kSrowX = 280, kMagicAt = 344;

template <class T>
T get(const std::vector<char>& b, size_t at, bool swap) {
  T v;
  char tmp[sizeof(T)];
  std::memcpy(tmp, b.data() + at, sizeof(T));
  if (swap) std::reverse(tmp, tmp + sizeof(T));
  std::memcpy(&v, tmp, sizeof(T));
  return v;
}

template <class T>
void put(std::vector<char>& b, size_t at, T v) {
  std::memcpy(b.data() + at, &v, sizeof(T));
}

int bytes_of(int datatype) {
  switch (datatype) {
    case 2:
    case 256:
      return 1;  // uint8, int8
    case 4:
    case 512:
      return 2;  // int16, uint16
    case 8:
    case 768:
    case 16:
      return 4;  // int32, uint32, float32
    case 64:
    case 1024:
    case 1280:
      return 8;  // float64, int64, uint64
    default:
      return 0;
  }
}

double value_at(const char* p, int datatype, bool swap) {
  char tmp[8];
  const int n = bytes_of(datatype);
  std::memcpy(tmp, p, static_cast<size_t>(n));
  // Fixed lengths: with a variable one, GCC 12's AVX2 code raised a false -Wstringop-overflow.
  if (swap && n == 2) std::reverse(tmp, tmp + 2);
  if (swap && n == 4) std::reverse(tmp, tmp + 4);
  if (swap && n == 8) std::reverse(tmp, tmp + 8);
  auto as = [&](auto v) {
    std::memcpy(&v, tmp, sizeof v);
    return static_cast<double>(v);
  };
  switch (datatype) {
    case 2:
      return as(uint8_t{});
    case 256:
      return as(int8_t{});
    case 4:
      return as(int16_t{});
    case 512:
      return as(uint16_t{});
    case 8:
      return as(int32_t{});
    case 768:
      return as(uint32_t{});
    case 16:
      return as(float{});
    case 64:
      return as(double{});
    case 1024:
      return as(int64_t{});
    default:
      return as(uint64_t{});
  }
}
}  // namespace

NiftiVolume read_nifti(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open the NIfTI file");
  std::vector<char> hdr(kHeader);
  if (!in.read(hdr.data(), static_cast<std::streamsize>(kHeader)))
    throw InputError(path + ": not a NIfTI-1 file (shorter than its 348-byte header)");
  bool swap = false;
  if (get<int32_t>(hdr, 0, false) != 348) {
    if (get<int32_t>(hdr, 0, true) != 348)
      throw InputError(path + ": not a NIfTI-1 file (sizeof_hdr is not 348)");
    swap = true;
  }
  if (std::memcmp(hdr.data() + kMagicAt, "n+1\0", 4) != 0)
    throw InputError(path +
                     ": not a single-file NIfTI-1 volume (magic is not \"n+1\"; .hdr/.img pairs "
                     "and NIfTI-2 are not supported)");
  NiftiVolume v;
  const int ndim = get<int16_t>(hdr, kDim, swap);
  if (ndim < 1 || ndim > 4)
    throw InputError(path + ": dim[0] = " + std::to_string(ndim) +
                     ": only 1 to 4 dimensions are supported");
  uint64_t count = 1;
  for (int i = 0; i < 4; ++i) {
    const int d = i < ndim ? get<int16_t>(hdr, kDim + 2 * static_cast<size_t>(i + 1), swap) : 1;
    if (d < 1)
      throw InputError(path + ": dim[" + std::to_string(i + 1) + "] = " + std::to_string(d) +
                       ": must be >= 1");
    v.dim[static_cast<size_t>(i)] = d;
    v.pixdim[static_cast<size_t>(i)] =
        get<float>(hdr, kPixdim + 4 * static_cast<size_t>(i + 1), swap);
    count *= static_cast<uint64_t>(d);
  }
  if (count > (uint64_t{1} << 28))
    throw InputError(path + ": " + std::to_string(count) + " values, above the limit of 2^28");
  v.datatype = get<int16_t>(hdr, kDatatype, swap);
  const int nb = bytes_of(v.datatype);
  if (nb == 0)
    throw InputError(path + ": datatype " + std::to_string(v.datatype) +
                     " is not supported (integers of 8 to 64 bits, float32, float64)");
  const double offset = get<float>(hdr, kVoxOffset, swap);
  if (!(offset >= static_cast<double>(kHeader)) || offset > 1e9)
    throw InputError(path + ": vox_offset " + std::to_string(offset) +
                     " is not a valid data offset");
  in.seekg(0, std::ios::end);
  const uint64_t size = static_cast<uint64_t>(in.tellg());
  const uint64_t need = static_cast<uint64_t>(offset) + count * static_cast<uint64_t>(nb);
  if (size < need)
    throw InputError(path + ": truncated: the header promises " + std::to_string(need) +
                     " bytes, the file has " + std::to_string(size));
  std::vector<char> raw(count * static_cast<uint64_t>(nb));
  in.seekg(static_cast<std::streamoff>(offset));
  if (!in.read(raw.data(), static_cast<std::streamsize>(raw.size())))
    throw InputError(path + ": cannot read the data");
  double slope = get<float>(hdr, kSclSlope, swap), inter = get<float>(hdr, kSclInter, swap);
  if (!(slope != 0) || !std::isfinite(slope)) slope = 1, inter = 0;  // 0: no scaling (standard)
  if (!std::isfinite(inter)) inter = 0;
  v.data.resize(count);
  for (uint64_t i = 0; i < count; ++i)
    v.data[i] = static_cast<float>(
        slope * value_at(raw.data() + i * static_cast<uint64_t>(nb), v.datatype, swap) + inter);
  return v;
}

void write_nifti_float32(const std::string& path, const std::array<int, 4>& dim,
                         const std::array<double, 4>& pixdim, const float* data,
                         const std::array<double, 3>& origin) {
  std::vector<char> hdr(kDataOffset, 0);
  put<int32_t>(hdr, 0, 348);
  const int16_t ndim = dim[3] > 1 ? 4 : 3;
  put<int16_t>(hdr, kDim, ndim);
  uint64_t count = 1;
  for (size_t i = 0; i < 4; ++i) {
    put<int16_t>(hdr, kDim + 2 * (i + 1), static_cast<int16_t>(dim[i]));
    put<float>(hdr, kPixdim + 4 * (i + 1), static_cast<float>(pixdim[i]));
    count *= static_cast<uint64_t>(dim[i]);
  }
  for (size_t i = 5; i < 8; ++i) put<int16_t>(hdr, kDim + 2 * i, 1);
  put<float>(hdr, kPixdim, 1.0f);  // qfac
  put<int16_t>(hdr, kDatatype, 16);
  put<int16_t>(hdr, kBitpix, 32);
  put<float>(hdr, kVoxOffset, static_cast<float>(kDataOffset));
  put<float>(hdr, kSclSlope, 1.0f);
  put<float>(hdr, kSclInter, 0.0f);
  hdr[kXyztUnits] = static_cast<char>(2 | 24);  // mm, microseconds (pixdim[4] is dt in us)
  const char descrip[] = "femto tissue";
  std::memcpy(hdr.data() + kDescrip, descrip, sizeof descrip);
  // sform: voxel (i, j, k) has its centre at origin + ((i + 1/2) dx, (j + 1/2) dy, (k + 1/2) dz).
  put<int16_t>(hdr, kQformCode, 0);
  put<int16_t>(hdr, kSformCode, 1);
  for (size_t r = 0; r < 3; ++r) {
    put<float>(hdr, kSrowX + 16 * r + 4 * r, static_cast<float>(pixdim[r]));
    put<float>(hdr, kSrowX + 16 * r + 12, static_cast<float>(origin[r] + 0.5 * pixdim[r]));
  }
  std::memcpy(hdr.data() + kMagicAt, "n+1\0", 4);
  write_atomically(path, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    out.write(hdr.data(), static_cast<std::streamsize>(hdr.size()));
    out.write(reinterpret_cast<const char*>(data),
              static_cast<std::streamsize>(count * sizeof(float)));
    if (!out) throw RuntimeError("cannot write '" + path + "'");
  });
}

}  // namespace femto
