#pragma once
/// A 64-bit FNV-1a hash of bytes fed in order: the key of the on-disk caches (meshes, FEM
/// solutions). Not cryptographic; a cache entry also stores its full key or checksum, so a
/// collision is detected, not trusted.
#include <cstdint>
#include <string>
#include <string_view>

namespace vessel {

class ContentHash {
 public:
  ContentHash& bytes(const void* data, std::size_t size);
  ContentHash& text(std::string_view s);  ///< the length, then the characters
  ContentHash& real(double x);            ///< the exact bit pattern (−0 and 0 differ)
  ContentHash& integer(std::int64_t i);

  [[nodiscard]] std::uint64_t value() const { return h_; }
  [[nodiscard]] std::string hex() const;  ///< 16 lower-case hex digits

 private:
  std::uint64_t h_ = 1469598103934665603ull;  // FNV-1a 64-bit offset basis
};

/// FNV-1a 64 of a string (ContentHash().bytes(s) without a length prefix).
std::uint64_t fnv1a(std::string_view s);

}  // namespace vessel
