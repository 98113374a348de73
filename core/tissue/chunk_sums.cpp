#include "core/tissue/chunk_sums.h"

namespace femto::tissue {

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
