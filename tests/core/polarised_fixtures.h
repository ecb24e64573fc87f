// Scenes shared by the polarised-trace tests of both twins (tests/core/reference and
// tests/core/render): the same plates and spheres, so that both are held to the same closed forms.
#pragma once

#include <string>

namespace eikon::test {

constexpr double kPolPi = 3.14159265358979323846;
inline double rad(double deg) { return deg * kPolPi / 180.0; }

/// A scene of `objects` (JSON objects, comma-separated) in a 16 mm cube at 64³ under a constant
/// unit environment, with a glass of n = 1.5 and the given ambient index.
inline std::string polarisedSceneJson(const std::string& objects, double ambient = 1.0) {
  return R"({"environment": {"type": "constant", "radiance": 1}, "ambient_index": )" +
         std::to_string(ambient) +
         R"(, "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 64},
         "materials": {"glass": {"n": 1.5}}, "objects": [)" +
         objects + "]}";
}

/// A 14 × 14 mm plate of `material`, `thickness` mm thick across z, optic axis `axis` (JSON).
inline std::string plate(const std::string& material, double thickness, const std::string& axis) {
  return R"({"shape": "box", "center": [0, 0, 0], "size": [14, 14, )" + std::to_string(thickness) +
         R"(], "material": ")" + material + R"(", "optic_axis": )" + axis + "}";
}

/// A small glass sphere off the beam's path (a scene needs an object to have sharp boundaries).
inline const char* const kAside =
    R"({"shape": "sphere", "center": [5, 5, 5], "radius": 1, "material": "glass"})";

}  // namespace eikon::test
