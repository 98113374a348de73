#include "core/tissue/chunk_sums.h"

#include <algorithm>
#include <numeric>

namespace femto::tissue {

void sort_records(DetectedPhotons& r, const std::vector<uint32_t>& key) {
  const size_t n = r.size();
  if (n == 0 || std::is_sorted(key.begin(), key.end())) return;
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), size_t{0});
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return key[a] < key[b]; });
  auto permute = [&](auto& v, size_t width) {
    auto out = v;
    for (size_t i = 0; i < n; ++i)
      std::copy_n(v.begin() + static_cast<std::ptrdiff_t>(order[i] * width), width,
                  out.begin() + static_cast<std::ptrdiff_t>(i * width));
    v.swap(out);
  };
  permute(r.detector, 1);
  permute(r.scatterings, 1);
  permute(r.weight, 1);
  permute(r.time_ps, 1);
  permute(r.ppath, r.ppath.size() / n);  // labels 1.. per record
  permute(r.exit, 6);
}

void write_chunk(distributed::ByteWriter& w, const ChunkSums& c) {
  w.put(c.balance);
  w.put_vector(c.absorbed);
  w.put_vector(c.tpsf);
  w.put_vector(c.detected);
  const DetectedPhotons& r = c.records;
  w.put(r.labels);
  w.put_vector(r.detector);
  w.put_vector(r.scatterings);
  w.put_vector(r.weight);
  w.put_vector(r.time_ps);
  w.put_vector(r.ppath);
  w.put_vector(r.exit);
  w.put(r.dropped);
  w.put(c.scatterings);
  w.put(c.segments);
}
void read_chunk(distributed::ByteReader& in, ChunkSums& c) {
  c.balance = in.get<Balance>();
  c.absorbed = in.get_vector<double>();
  c.tpsf = in.get_vector<double>();
  c.detected = in.get_vector<double>();
  DetectedPhotons& r = c.records;
  r.labels = in.get<int>();
  r.detector = in.get_vector<int32_t>();
  r.scatterings = in.get_vector<int32_t>();
  r.weight = in.get_vector<double>();
  r.time_ps = in.get_vector<double>();
  r.ppath = in.get_vector<double>();
  r.exit = in.get_vector<double>();
  r.dropped = in.get<uint64_t>();
  c.scatterings = in.get<uint64_t>();
  c.segments = in.get<uint64_t>();
}

}  // namespace femto::tissue
