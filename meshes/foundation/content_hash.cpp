#include "meshes/foundation/content_hash.hpp"

#include <cstdio>
#include <cstring>

namespace vessel {

ContentHash& ContentHash::bytes(const void* data, std::size_t size) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) {
    h_ ^= p[i];
    h_ *= 1099511628211ull;  // FNV-1a 64-bit prime
  }
  return *this;
}

ContentHash& ContentHash::text(std::string_view s) {
  integer(static_cast<std::int64_t>(s.size()));
  return bytes(s.data(), s.size());
}

ContentHash& ContentHash::real(double x) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &x, sizeof bits);
  return bytes(&bits, sizeof bits);
}

ContentHash& ContentHash::integer(std::int64_t i) { return bytes(&i, sizeof i); }

std::string ContentHash::hex() const {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h_));
  return buf;
}

std::uint64_t fnv1a(std::string_view s) { return ContentHash().bytes(s.data(), s.size()).value(); }

}  // namespace vessel
