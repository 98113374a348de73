#pragma once
// SHA-256 (FIPS 180-4) for the file list in render.json and the integrity of checkpoints.
#include <cstddef>
#include <cstdint>
#include <string>

namespace femto {

class Sha256 {
 public:
  Sha256() : Sha256(true) {}
  /// hardware: use the CPU's SHA instructions when it has them (x86-64 SHA extensions); false
  /// forces the portable code. Both give the same digests.
  explicit Sha256(bool hardware);
  void reset();
  void update(const void* data, size_t bytes);
  /// Finishes the hash (the object must be reset before reuse) and returns the 32-byte digest.
  void finish(uint8_t digest[32]);
  /// Finishes and returns the digest as 64 lowercase hex digits.
  std::string hex();

 private:
  void blocks(const uint8_t* p, size_t n);  ///< n whole 64-byte blocks
  void block(const uint8_t* p);
  bool hardware_;
  uint32_t h_[8];
  uint8_t buf_[64];
  size_t used_ = 0;
  uint64_t length_ = 0;  ///< bytes hashed so far
};

/// Whether this CPU has the SHA instructions the hardware path uses.
bool sha256_hardware_available();

std::string sha256_hex(const std::string& bytes);
/// Hash of a file's bytes, streamed. Throws RuntimeError naming the file when it cannot be read.
std::string sha256_file(const std::string& path);

}  // namespace femto
