#include "core/scene/material_library.h"

#include <algorithm>
#include <cctype>
#include <set>
#include <system_error>

#include "core/scene/messages.h"
#include "core/scene/scene.h"

namespace eikon {

namespace fs = std::filesystem;

namespace {
/// Names listed in full up to this many; a larger library is named by its folders only.
constexpr size_t kListedNames = 24;

/// The *.json files directly in `dir` (none when it cannot be read).
std::vector<fs::path> jsonFilesIn(const fs::path& dir) {
  std::vector<fs::path> out;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    if (it->path().extension() == ".json" && it->is_regular_file(ec)) out.push_back(it->path());
  std::sort(out.begin(), out.end());
  return out;
}
}  // namespace

std::string normalisedMaterialName(const std::string& name) {
  std::string n = name;
  for (char& c : n) {
    if (c == ' ' || c == '_') c = '-';
    if (c >= 'A' && c <= 'Z') c = char(c - 'A' + 'a');
  }
  return n;
}

std::vector<std::string> libraryMaterialNames() {
  std::set<std::string> names;
  for (const fs::path& dir : materialSearchPath())
    for (const fs::path& f : jsonFilesIn(dir)) names.insert(f.stem().string());
  return {names.begin(), names.end()};
}

std::optional<fs::path> findLibraryMaterial(const std::string& name) {
  const std::vector<fs::path> dirs = materialSearchPath();
  for (const fs::path& dir : dirs) {
    const fs::path p = dir / (name + ".json");
    std::error_code ec;
    const fs::file_status st = fs::status(p, ec);  // not found is no error
    if (ec && ec != std::errc::no_such_file_or_directory && ec != std::errc::not_a_directory)
      throw fs::filesystem_error("cannot look up a library material", p, ec);
    if (fs::exists(st)) return p;
  }
  // Forgiving: the same name up to case, spaces and underscores (docs/scene-format.md).
  const std::string wanted = normalisedMaterialName(name);
  for (const fs::path& dir : dirs)
    for (const fs::path& f : jsonFilesIn(dir))
      if (normalisedMaterialName(f.stem().string()) == wanted) return f;
  return std::nullopt;
}

size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1])});
      diagonal = above;
    }
  }
  return row[b.size()];
}

std::string unknownMaterialHint(const std::string& name, const std::vector<std::string>& defined) {
  const std::vector<std::string> library = libraryMaterialNames();
  // Close: at most a third of the longer name's letters differ (at least 1, at most 3), compared
  // as the lookup compares (case, spaces and underscores aside). Long user input is not compared.
  std::vector<std::pair<size_t, std::string>> close;
  const std::string wanted = normalisedMaterialName(name);
  if (wanted.size() <= 256) {
    std::set<std::string> candidates(library.begin(), library.end());
    candidates.insert(defined.begin(), defined.end());
    for (const std::string& c : candidates) {
      const std::string n = normalisedMaterialName(c);
      const size_t limit = std::clamp<size_t>(std::max(n.size(), wanted.size()) / 3, 1, 3);
      const size_t d = editDistance(wanted, n);
      if (d <= limit) close.emplace_back(d, c);
    }
  }
  std::sort(close.begin(), close.end());
  if (close.size() > 3) close.resize(3);
  std::string hint;
  for (size_t i = 0; i < close.size(); ++i)
    hint += (i == 0                  ? "did you mean '"
             : i + 1 == close.size() ? "' or '"
                                     : "', '") +
            excerpt(close[i].second);
  if (!close.empty()) hint += "'? ";
  std::string folders;  // as EIKON_MATERIALS_PATH lists them
  for (const fs::path& dir : materialSearchPath())
    folders += (folders.empty() ? "" : ":") + printable(dir.string(), 200);
  if (library.size() <= kListedNames) {
    std::string names;
    for (const std::string& n : library) names += (names.empty() ? "" : ", ") + excerpt(n);
    return hint + "(library materials, the *.json files in " + folders + ": " +
           (names.empty() ? "none" : names) + ")";
  }
  return hint + "(library materials: the " + std::to_string(library.size()) + " *.json files in " +
         folders + ")";
}

}  // namespace eikon
