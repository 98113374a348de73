#pragma once
// Flat byte buffers for partial results sent between ranks: values are copied bit for bit, so a
// sum folded on rank 0 equals the one a single process computes.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <type_traits>
#include <vector>

namespace femto::distributed {

class ByteWriter {
 public:
  template <class T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable<T>::value, "plain values only");
    append(&v, sizeof(T));
  }
  template <class T>
  void put_vector(const std::vector<T>& v) {
    put<uint64_t>(v.size());
    put_array(v.data(), v.size());
  }
  template <class T>
  void put_array(const T* p, size_t n) {
    static_assert(std::is_trivially_copyable<T>::value, "plain values only");
    append(p, n * sizeof(T));
  }
  std::vector<char>& bytes() { return bytes_; }

 private:
  void append(const void* p, size_t n) {
    const size_t at = bytes_.size();
    bytes_.resize(at + n);
    if (n) std::memcpy(bytes_.data() + at, p, n);
  }
  std::vector<char> bytes_;
};

class ByteReader {
 public:
  explicit ByteReader(const std::vector<char>& bytes) : bytes_(bytes) {}
  template <class T>
  T get() {
    T v;
    take(&v, sizeof(T));
    return v;
  }
  template <class T>
  std::vector<T> get_vector() {
    std::vector<T> v(static_cast<size_t>(get<uint64_t>()));
    get_array(v.data(), v.size());
    return v;
  }
  template <class T>
  void get_array(T* p, size_t n) {
    take(p, n * sizeof(T));
  }
  bool done() const { return at_ == bytes_.size(); }

 private:
  void take(void* p, size_t n) {
    if (n > bytes_.size() - at_) throw std::runtime_error("distributed: short message from a rank");
    if (n) std::memcpy(p, bytes_.data() + at_, n);
    at_ += n;
  }
  const std::vector<char>& bytes_;
  size_t at_ = 0;
};

}  // namespace femto::distributed
