// The camera moves of `eikon view` (orbit, zoom and pan about the camera's look_at, a light
// dragged across the view) and the
// camera as the scene file spells it, so that a view found interactively can be pasted into the
// scene ("camera": {...}). Pure functions of eikon::Camera, tested without a window
// (tests/apps/view_camera_test.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/glm.hpp>
#include <numbers>
#include <string>

#include "core/scene/scene.h"

namespace eikon::cli {

/// Orbit the camera about look_at: `yaw` radians about the camera's up axis, then `pitch` radians
/// about its right axis (positive: the camera rises). The distance to look_at is kept; the pitch
/// stops 1° short of the poles, where up and the view direction would be parallel.
inline void orbitCamera(Camera& cam, double yaw, double pitch) {
  const glm::dvec3 up = glm::normalize(cam.up);
  glm::dvec3 offset = cam.position - cam.look_at;
  const double r = glm::length(offset);
  if (!(r > 0)) return;
  auto rotate = [](glm::dvec3 v, glm::dvec3 axis, double a) {  // Rodrigues
    return v * std::cos(a) + glm::cross(axis, v) * std::sin(a) +
           axis * glm::dot(axis, v) * (1.0 - std::cos(a));
  };
  offset = rotate(offset, up, yaw);
  const double kLimit = 1.0 * std::numbers::pi / 180.0;
  const double elevation = std::asin(std::clamp(glm::dot(offset / r, up), -1.0, 1.0));
  const double half_pi = 0.5 * std::numbers::pi;
  pitch = std::clamp(elevation + pitch, -half_pi + kLimit, half_pi - kLimit) - elevation;
  glm::dvec3 right = glm::cross(up, offset);  // horizontal, perpendicular to the view
  if (glm::length(right) > 1e-12) offset = rotate(offset, glm::normalize(right), -pitch);
  cam.position = cam.look_at + offset * (r / glm::length(offset));
}

/// Move the camera towards look_at (factor < 1) or away (> 1); look_at stays. The distance stays
/// in [1e-6, 1e9] mm, so that no number of wheel steps makes a camera the scene checks refuse
/// (position and look_at closer than 1e-9 mm, or a position beyond ±1e12 mm).
inline void zoomCamera(Camera& cam, double factor) {
  const glm::dvec3 offset = cam.position - cam.look_at;
  const double r = glm::length(offset);
  const double to = std::clamp(r * std::clamp(factor, 1e-3, 1e3), 1e-6, 1e9);
  cam.position = cam.look_at + offset * (to / r);
}

/// Move camera and look_at together in the image plane: `dx`, `dy` in fractions of the image
/// height (dx to the right, dy up) at the distance of look_at, so the point under the cursor
/// follows it.
inline void panCamera(Camera& cam, double dx, double dy) {
  const glm::dvec3 fwd = glm::normalize(cam.look_at - cam.position);
  const glm::dvec3 right = glm::normalize(glm::cross(fwd, cam.up));
  const glm::dvec3 up = glm::cross(right, fwd);
  const double height = 2.0 * glm::length(cam.look_at - cam.position) *
                        std::tan(0.5 * cam.fov_deg * std::numbers::pi / 180.0);
  const glm::dvec3 move = (right * dx + up * dy) * height;
  cam.position += move;
  cam.look_at += move;
}

/// Move a light with the mouse as seen through `cam`: a point or spot light (or a directional
/// beam's axis point) follows the cursor in the plane through the light parallel to the image;
/// a directional light's direction turns as an orbit would turn the camera (dx about the camera's
/// up axis, dy about its right axis, a window height of drag: 3 rad).
inline void moveLight(Light& light, const Camera& cam, double dx, double dy) {
  const glm::dvec3 fwd = glm::normalize(cam.look_at - cam.position);
  const glm::dvec3 right = glm::normalize(glm::cross(fwd, cam.up));
  const glm::dvec3 up = glm::cross(right, fwd);
  if (light.type == Light::Type::Directional && light.beam_radius <= 0) {
    auto rotate = [](glm::dvec3 v, glm::dvec3 axis, double a) {  // Rodrigues
      return v * std::cos(a) + glm::cross(axis, v) * std::sin(a) +
             axis * glm::dot(axis, v) * (1.0 - std::cos(a));
    };
    light.direction =
        glm::normalize(rotate(rotate(light.direction, up, 3.0 * dx), right, -3.0 * dy));
    return;
  }
  const double depth = std::max(glm::dot(light.position - cam.position, fwd), 1e-6);
  const double height = 2.0 * depth * std::tan(0.5 * cam.fov_deg * std::numbers::pi / 180.0);
  light.position += (right * dx + up * dy) * height;
}

/// {"position": [...], "look_at": [...], "up": [...], "fov_deg": F, "width": W, "height": H}: the
/// scene file's camera object (9 significant digits: the renderer's float32 camera exactly).
inline std::string vectorJson(const glm::dvec3& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "[%.9g, %.9g, %.9g]", v.x, v.y, v.z);
  return buf;
}

inline std::string cameraJson(const Camera& cam, int width, int height) {
  const auto vec = vectorJson;
  char tail[96];
  std::snprintf(tail, sizeof tail, ", \"fov_deg\": %.9g, \"width\": %d, \"height\": %d}",
                cam.fov_deg, width, height);
  return "{\"position\": " + vec(cam.position) + ", \"look_at\": " + vec(cam.look_at) +
         ", \"up\": " + vec(cam.up) + tail;
}

}  // namespace eikon::cli
