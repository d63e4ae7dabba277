#pragma once
/// The checksummed store every cache of the project keeps its entries in (FEM solutions and
/// transients, finite-strain continuations, the harness's model outcomes): one file per key,
/// named by a hash of the key and holding the key itself, so a collision of names is a miss,
/// never a wrong answer. Each file carries a checksum of its payload: a corrupt or truncated
/// entry is reported and computed again. Entries are written atomically (write, then rename), so
/// concurrent writers never leave a partial file, and a read-only store costs time, not results.
#include <filesystem>
#include <functional>
#include <mutex>
#include <ostream>
#include <string>
#include <string_view>

namespace vessel {

/// What a store did over its life.
struct ContentStoreStatistics {
  int hits = 0;
  int misses = 0;   ///< computed and stored (including the corrupt entries below)
  int corrupt = 0;  ///< entries found unreadable or failing their checksum, computed again
  int uncacheable = 0;  ///< requests its owner could not key (counted by count_uncacheable)
  double seconds_saved = 0.0;  ///< the hits' original computing time, less their reading
};

class ContentStore {
 public:
  /// Entries live in `dir` (created on the first write); an empty path disables the store.
  /// `log` receives a line per corrupt or unwritable entry (nullptr: std::cerr); `name` starts
  /// those lines and summary().
  ContentStore(std::filesystem::path dir, std::ostream* log, std::string name);

  /// The entry for `key`: `use(payload)` restores a good one and returns the seconds its
  /// computation took (throwing std::exception for a payload it cannot read, which then counts
  /// as corrupt); otherwise `compute()` computes the payload, which is stored. `refresh`: compute
  /// and replace without reading (a miss). Call only when enabled().
  void lookup(const std::string& key, const std::function<double(std::string_view)>& use,
              const std::function<std::string()>& compute, bool refresh = false);

  /// The stored payload of `key` when `original_seconds` accepts it (see lookup), else
  /// compute()'s, stored. With the store disabled, compute()'s.
  std::string payload(const std::string& key, const std::function<std::string()>& compute,
                      const std::function<double(std::string_view)>& original_seconds,
                      bool refresh = false);

  /// Counts a request the owner could not key (a problem given as a function, say).
  void count_uncacheable();

  [[nodiscard]] bool enabled() const { return !dir_.empty(); }
  /// The file that holds (or would hold) the entry of `key`.
  [[nodiscard]] std::filesystem::path entry_path(const std::string& key) const;
  [[nodiscard]] const std::filesystem::path& directory() const { return dir_; }
  [[nodiscard]] ContentStoreStatistics statistics() const;
  /// One line: "<name> (DIR): H hits, M misses, C corrupt entries recomputed, S s saved".
  [[nodiscard]] std::string summary() const;

 private:
  std::filesystem::path dir_;
  std::ostream* log_;
  std::string name_;
  mutable std::mutex mutex_;  // statistics only: entries are files written atomically
  ContentStoreStatistics stats_;
};

}  // namespace vessel
