#include "meshes/foundation/content_store.hpp"

#include <chrono>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iostream>
#include <iterator>
#include <sstream>

#include "meshes/foundation/atomic_file.hpp"
#include "meshes/foundation/content_hash.hpp"

namespace vessel {

namespace fs = std::filesystem;

namespace {

// The entry file: magic, format version (uint32), key and payload (each a uint64 length then
// the bytes), FNV-1a of the payload (uint64); native byte order: a store is a machine's own.
// (The magic predates the other caches; kept so that existing stores stay readable.)
constexpr std::string_view kMagic = "vesselverify-fem-solution\n";
constexpr std::uint32_t kFormatVersion = 1;

template <class T>
void append(std::string& out, const T& x) {
  out.append(reinterpret_cast<const char*>(&x), sizeof x);
}
void append_text(std::string& out, std::string_view s) {
  append(out, static_cast<std::uint64_t>(s.size()));
  out.append(s);
}

std::string entry_file(const std::string& key, const std::string& payload) {
  std::string out(kMagic);
  append(out, kFormatVersion);
  append_text(out, key);
  append_text(out, payload);
  append(out, fnv1a(payload));
  return out;
}

/// Reads fixed-size values and length-prefixed texts off a byte string; false once it runs out.
class EntryReader {
 public:
  explicit EntryReader(std::string_view in) : in_(in) {}
  template <class T>
  bool value(T& x) {
    if (in_.size() < sizeof x) return false;
    std::memcpy(&x, in_.data(), sizeof x);
    in_.remove_prefix(sizeof x);
    return true;
  }
  bool text(std::string& s) {
    std::uint64_t n = 0;
    if (!value(n) || n > in_.size()) return false;
    s.assign(in_.substr(0, n));
    in_.remove_prefix(n);
    return true;
  }
  [[nodiscard]] bool done() const { return in_.empty(); }

 private:
  std::string_view in_;
};

enum class EntryState { missing, ok, corrupt, other_key };

/// Reads the entry at `path` for `key`; `why` says what is wrong with a corrupt one.
EntryState read_entry(const fs::path& path, const std::string& key, std::string& payload,
                      std::string& why) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return EntryState::missing;
  const std::string file((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  if (file.compare(0, kMagic.size(), kMagic) != 0) {
    why = "not a vesselverify cache entry";
    return EntryState::corrupt;
  }
  EntryReader in(std::string_view(file).substr(kMagic.size()));
  std::uint32_t version = 0;
  std::string stored_key;
  if (!in.value(version)) {
    why = "truncated";
    return EntryState::corrupt;
  }
  if (version != kFormatVersion) return EntryState::other_key;
  if (!in.text(stored_key)) {
    why = "truncated";
    return EntryState::corrupt;
  }
  if (stored_key != key) return EntryState::other_key;  // a hash collision: never trusted
  std::uint64_t checksum = 0;
  if (!in.text(payload) || !in.value(checksum)) {
    why = "truncated";
    return EntryState::corrupt;
  }
  if (checksum != fnv1a(payload) || !in.done()) {
    why = "checksum mismatch";
    return EntryState::corrupt;
  }
  return EntryState::ok;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

ContentStore::ContentStore(fs::path dir, std::ostream* log, std::string name)
    : dir_(std::move(dir)), log_(log), name_(std::move(name)) {}

void ContentStore::lookup(const std::string& key,
                          const std::function<double(std::string_view)>& use,
                          const std::function<std::string()>& compute, bool refresh) {
  const fs::path path = entry_path(key);
  const auto t0 = std::chrono::steady_clock::now();
  std::string payload, why;
  const EntryState state = refresh ? EntryState::missing : read_entry(path, key, payload, why);
  if (state == EntryState::ok) {
    try {
      const double original_seconds = use(payload);
      const std::lock_guard lock(mutex_);
      ++stats_.hits;
      stats_.seconds_saved += original_seconds - seconds_since(t0);
      return;
    } catch (const std::exception& e) {  // a payload its owner cannot read
      why = e.what();
    }
  }
  const bool corrupt = state == EntryState::corrupt || state == EntryState::ok;
  if (corrupt) {
    (log_ ? *log_ : std::cerr) << name_ << ": entry " << path.string() << " is corrupt ("
                               << why << "); computing it again and replacing it\n";
  }
  const std::string file = entry_file(key, compute());
  try {
    write_file_atomically(path, [&](std::ostream& out) { out << file; }, true);
  } catch (const std::exception& e) {  // a read-only store costs time, not the result
    (log_ ? *log_ : std::cerr) << name_ << ": cannot store " << path.string() << " ("
                               << e.what() << "); continuing without it\n";
  }
  const std::lock_guard lock(mutex_);
  ++stats_.misses;
  if (corrupt) ++stats_.corrupt;
}

std::string ContentStore::payload(const std::string& key,
                                  const std::function<std::string()>& compute,
                                  const std::function<double(std::string_view)>& original_seconds,
                                  bool refresh) {
  if (!enabled()) return compute();
  std::string out;
  lookup(
      key,
      [&](std::string_view stored) {
        const double seconds = original_seconds(stored);
        out = std::string(stored);
        return seconds;
      },
      [&] {
        out = compute();
        return out;
      },
      refresh);
  return out;
}

fs::path ContentStore::entry_path(const std::string& key) const {
  return dir_ / ("entry-" + ContentHash().text(key).hex() + ".bin");
}

void ContentStore::count_uncacheable() {
  const std::lock_guard lock(mutex_);
  ++stats_.uncacheable;
}

ContentStoreStatistics ContentStore::statistics() const {
  const std::lock_guard lock(mutex_);
  return stats_;
}

std::string ContentStore::summary() const {
  if (!enabled()) return name_ + ": off (--no-cache)";
  const ContentStoreStatistics s = statistics();
  std::ostringstream o;
  o.precision(3);
  o << name_ << " (" << dir_.string() << "): " << s.hits << " hits, " << s.misses << " misses";
  if (s.corrupt > 0) o << " (" << s.corrupt << " corrupt entries recomputed)";
  if (s.uncacheable > 0) o << ", " << s.uncacheable << " problems not cacheable";
  o << ", " << s.seconds_saved << " s of computing saved";
  return o.str();
}

}  // namespace vessel
