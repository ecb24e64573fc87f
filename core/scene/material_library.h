// The material library: the files `materials/<name>.json` (and those of the folders in
// EIKON_MATERIALS_PATH) that a scene's objects and Python's load_material name without defining
// the material themselves (docs/scene-format.md "materials").
//
// A name is looked up forgivingly where no other material could be meant: letter case is
// ignored and spaces and underscores count as hyphens, so "fused silica", "Fused_Silica" and
// "FUSED-SILICA" all find fused-silica.json, and "Diamond" finds diamond.json. A name that finds
// nothing gets the closest library names (edit distance) and where the library is:
//
//   auto file = eikon::findLibraryMaterial("N-BK8");          // std::nullopt
//   eikon::unknownMaterialHint("N-BK8", {});
//     → "did you mean 'N-BK7'? (library, /src/materials: N-BK7, N-SF11, calcite, ...)"
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace eikon {

/// The name as the library compares it: ASCII letters in lower case, ' ' and '_' as '-'.
std::string normalisedMaterialName(const std::string& name);

/// Every library material's name (the file stems of materialSearchPath()'s *.json files), each
/// once (the first folder that holds it wins), sorted.
std::vector<std::string> libraryMaterialNames();

/// The file of the library material `name`: `<dir>/<name>.json` in the first folder that holds
/// it, else the first file whose stem equals `name` after normalisedMaterialName. std::nullopt
/// when none does. `name` must be a plain name (no '/', '\\' or NUL; the caller checks).
/// Throws std::filesystem::filesystem_error (path1: the file looked for) when the system cannot
/// look the name up (a name too long for the file system).
std::optional<std::filesystem::path> findLibraryMaterial(const std::string& name);

/// Levenshtein distance between two strings (bytes).
size_t editDistance(const std::string& a, const std::string& b);

/// What to tell a user whose material `name` was not found: the closest of `defined` (the
/// scene's own materials) and the library's names ("did you mean 'N-BK7'?") when one is close,
/// and the library's folder with its names (all of them: the library is small) or, with none
/// close, where to look.
std::string unknownMaterialHint(const std::string& name, const std::vector<std::string>& defined);

}  // namespace eikon
