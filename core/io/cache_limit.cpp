#include "core/io/cache_limit.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <system_error>
#include <utility>
#include <vector>

namespace eikon {

namespace fs = std::filesystem;

std::optional<uint64_t> cacheMaxBytesSetting(std::string* error) {
  const char* v = std::getenv("EIKON_CACHE_MAX_MB");
  if (!v || !*v) return kDefaultCacheMaxBytes;
  const std::string s(v);
  uint64_t mb = 0;
  bool ok = s.size() <= 10 &&
            std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
  for (char c : ok ? s : std::string()) mb = mb * 10 + uint64_t(c - '0');
  ok = ok && mb <= (uint64_t(1) << 30);
  if (!ok) {
    if (error)
      *error = "EIKON_CACHE_MAX_MB must be a whole number of MiB in [0, 1073741824], got '" +
               s.substr(0, 40) + (s.size() > 40 ? "...'" : "'");
    return std::nullopt;
  }
  return mb << 20;
}

uint64_t cacheMaxBytes() { return cacheMaxBytesSetting().value_or(kDefaultCacheMaxBytes); }

bool isCacheEntryName(const std::string& name) {
  auto ends = [&](const char* e) {
    const std::string s(e);
    return name.size() > s.size() && name.compare(name.size() - s.size(), s.size(), s) == 0;
  };
  if (!ends(".bin") || name.find(".tmp-") != std::string::npos) return false;
  for (const char* prefix : {"light-", "volume-", "spirv-", "pipelines-"})
    if (name.rfind(prefix, 0) == 0) return true;
  return false;
}

void touchCacheEntry(const fs::path& entry) {
  std::error_code ec;
  fs::last_write_time(entry, fs::file_time_type::clock::now(), ec);
}

uint64_t trimCacheDir(const fs::path& dir, const fs::path& keep, uint64_t max_bytes) {
  if (dir.empty()) return 0;
  // One trimmer at a time; one that finds the lock taken leaves it to the holder. A symbolic link
  // in the lock's place is not followed (it would create a file at its target): no trim then.
  const int lock =
      ::open((dir / ".trim.lock").c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0666);
  if (lock < 0) return 0;
  if (::flock(lock, LOCK_EX | LOCK_NB) != 0) {
    ::close(lock);
    return 0;
  }
  const uint64_t removed = removeLeastRecentlyUsed(dir, keep, max_bytes);
  ::flock(lock, LOCK_UN);
  ::close(lock);
  return removed;
}

uint64_t removeLeastRecentlyUsed(const fs::path& dir, const fs::path& keep, uint64_t max_bytes) {
  std::error_code ec;
  std::vector<std::pair<fs::file_time_type, std::pair<fs::path, uint64_t>>> entries;
  uint64_t total = 0;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    std::error_code e;
    const std::string name = it->path().filename().string();
    if (!isCacheEntryName(name) || !it->is_regular_file(e)) continue;
    const uint64_t size = it->file_size(e);
    const fs::file_time_type time = it->last_write_time(e);
    if (e) continue;  // removed meanwhile
    total += size;
    entries.push_back({time, {it->path(), size}});
  }
  std::sort(entries.begin(), entries.end());
  uint64_t removed = 0;
  for (const auto& [time, entry] : entries) {
    if (total <= max_bytes) break;
    if (!keep.empty() && entry.first == keep) continue;
    std::error_code e;
    if (fs::remove(entry.first, e))
      removed += entry.second;
    else if (fs::exists(entry.first, e))
      continue;             // cannot be removed (permissions): it stays counted
    total -= entry.second;  // gone: removed here or by another process
  }
  return removed;
}

}  // namespace eikon
