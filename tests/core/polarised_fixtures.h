// Scenes shared by the polarised-trace tests of both twins (tests/core/reference and
// tests/core/render): the same plates and spheres, so that both are held to the same closed forms.
#pragma once

#include <numbers>
#include <string>

namespace eikon::test {
inline double rad(double deg) { return deg * std::numbers::pi / 180.0; }

/// A scene of `objects` (JSON objects, comma-separated) in a 16 mm cube at 64³ under a constant
/// unit environment, with a glass of n = 1.5 and the given ambient index; `extra`: more top-level
/// keys ("\"camera\": {...}, "), e.g. the camera of a polarised render.
inline std::string polarisedSceneJson(const std::string& objects, double ambient = 1.0,
                                      const std::string& extra = "") {
  return "{" + extra + R"("environment": {"type": "constant", "radiance": 1}, "ambient_index": )" +
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

/// A polariser sheet ⊥ z at `z`, its transmission axis at `angle_deg` from x towards y.
inline std::string sheetAt(double z, double angle_deg, double size = 60.0) {
  return R"({"shape": "polarizer", "center": [0, 0, )" + std::to_string(z) +
         R"(], "normal": [0, 0, 1], "transmission_axis": [)" +
         std::to_string(std::cos(rad(angle_deg))) + ", " +
         std::to_string(std::sin(rad(angle_deg))) + R"(, 0], "size": [)" + std::to_string(size) +
         ", " + std::to_string(size) + "]}";
}

/// The camera key of a polarised render: at z = −60 looking along +z with a narrow field (0.2°:
/// every ray within 0.12° of the axis, so that the closed forms of normal incidence hold to ~1e-5:
/// sheets seen obliquely at θ pass ~θ² more or less than Malus says),
/// `width` × `height` pixels; `analyzer`: a JSON vector or empty.
inline std::string renderCamera(int width = 24, int height = 16, const std::string& analyzer = "",
                                double fov_deg = 0.2) {
  return R"("camera": {"position": [0, 0, -60], "look_at": [0, 0, 0], "fov_deg": )" +
         std::to_string(fov_deg) + R"(, "width": )" + std::to_string(width) + R"(, "height": )" +
         std::to_string(height) +
         (analyzer.empty() ? std::string() : R"(, "analyzer": )" + analyzer) + "}, ";
}

/// A small glass sphere off the beam's path (a scene needs an object to have sharp boundaries).
inline const char* const kAside =
    R"({"shape": "sphere", "center": [5, 5, 5], "radius": 1, "material": "glass"})";

}  // namespace eikon::test
