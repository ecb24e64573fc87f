#include "core/scene/scene_warnings.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/scene/messages.h"

namespace eikon {

namespace {

/// Warnings of one kind past the 10th are counted in one line (as the scene parser's others).
class Capped {
 public:
  Capped(Scene& scene, std::string file, std::string kind)
      : scene_(scene), file_(std::move(file)), kind_(std::move(kind)) {}
  void add(const std::string& text) {
    if (++count_ <= 10) scene_.warnings.push_back(printable(file_ + ": " + text));
  }
  ~Capped() {
    if (count_ > 10)
      scene_.warnings.push_back(printable(file_ + ": ... and " + std::to_string(count_ - 10) +
                                          " more such warnings (" + kind_ + ")"));
  }

 private:
  Scene& scene_;
  std::string file_, kind_;
  size_t count_ = 0;
};

std::string objectName(const Scene& scene, const std::vector<size_t>& json_index, size_t k) {
  return "/objects/" + std::to_string(json_index[k]) + " ('" + excerpt(scene.objects[k].material) +
         "')";
}

double voxelEdge(const VolumeSpec& v) {
  const glm::dvec3 ext = v.bounds_max - v.bounds_min;
  return std::max(ext.x, std::max(ext.y, ext.z)) / v.resolution;
}

bool hasAlbedo(const Material& m) {
  return float(m.albedo.x) != 0.0f || float(m.albedo.y) != 0.0f || float(m.albedo.z) != 0.0f;
}

/// Objects with an albedo show only the simulated light of /lights.
void warnUnlit(Scene& scene, const std::vector<size_t>& json_index, const std::string& file) {
  if (!scene.lights.empty()) return;
  Capped warn(scene, file, "objects with an albedo in a scene without lights");
  for (size_t k = 0; k < scene.objects.size(); ++k) {
    const Material& m = scene.materials.at(scene.objects[k].material);
    // One that emits shows its emission: not black, and maybe meant so.
    if (!hasAlbedo(m) || m.emission != glm::dvec3(0.0)) continue;
    warn.add(objectName(scene, json_index, k) +
             ": its material has an albedo, which shows only "
             "the light of the scene's lights, and the scene has none (no \"lights\"): " +
             (m.opacity >= 0.5 ? std::string("the surface renders black")
                               : std::string("it scatters no light into the view")) +
             "; add a light under /lights, or give the material emission instead");
  }
}

/// Objects wholly inside one voxel, or inside one pixel's footprint at their distance.
void warnTiny(Scene& scene, const std::vector<size_t>& json_index, const std::string& file) {
  const double h = voxelEdge(scene.volume);
  const Camera& cam = scene.camera;
  const double pixel_rad = cam.fov_deg * std::numbers::pi / 180.0 / std::max(cam.height, 1);
  Capped warn(scene, file, "objects smaller than a voxel or a pixel");
  for (size_t k = 0; k < scene.objects.size(); ++k) {
    const Shape& shape = scene.objects[k].shape;
    const auto [lo, hi] = shape.bounds();
    const double across = hi.x - lo.x;  // the bounding sphere's diameter: at least the object's
    const double distance = glm::length(shape.center() - cam.position);
    const double footprint = distance * pixel_rad;  // a pixel's width at the object's distance
    if (across < h)
      warn.add(objectName(scene, json_index, k) + ": the object is at most " +
               formatNumber(across) + " mm across, smaller than a voxel of the volume (" +
               formatNumber(h) +
               " mm), so it is not seen; lengths are millimetres (enlarge it, or shrink the "
               "volume or raise its resolution)");
    else if (distance > 0.5 * across && across < footprint)
      warn.add(objectName(scene, json_index, k) + ": the object is at most " +
               formatNumber(across) +
               " mm across, smaller than a pixel of the camera at its distance (" +
               formatNumber(footprint) + " mm at " + formatNumber(distance) +
               " mm), so it is barely seen; lengths are millimetres");
  }
}

/// The distance of `c` from the line x = p + t·d (t ∈ ℝ, d unit).
double distanceToLine(const glm::dvec3& p, const glm::dvec3& d, const glm::dvec3& c) {
  const glm::dvec3 v = c - p;
  return glm::length(v - glm::dot(v, d) * d);
}

}  // namespace

bool lightReachesAnObject(const Scene& scene, const Light& light) {
  const bool beam = light.type == Light::Type::Directional && light.beam_radius > 0.0;
  const bool spot = light.type == Light::Type::Spot;
  if (!beam && !spot) return !scene.objects.empty();
  const glm::dvec3 d = glm::normalize(light.direction);
  for (const SceneObject& o : scene.objects) {
    const auto [lo, hi] = o.shape.bounds();
    const double r = 0.5 * (hi.x - lo.x);
    const glm::dvec3 c = o.shape.center();
    if (beam) {  // a cylinder about the axis through `position`, light on both sides of it
      if (distanceToLine(light.position, d, c) <= light.beam_radius + r) return true;
      continue;
    }
    const glm::dvec3 v = c - light.position;  // a cone about d from `position`
    const double dist = glm::length(v);
    if (dist <= r) return true;
    const double to_centre = std::acos(std::clamp(glm::dot(v / dist, d), -1.0, 1.0));
    const double half = light.cone_half_angle_deg * std::numbers::pi / 180.0;
    if (to_centre <= half + std::asin(std::min(1.0, r / dist)) + 1e-12) return true;
  }
  return false;
}

bool anyLightReachesAnObject(const Scene& scene) {
  return std::any_of(scene.lights.begin(), scene.lights.end(),
                     [&](const Light& l) { return lightReachesAnObject(scene, l); });
}

void warnUnseenScene(Scene& scene, const std::vector<size_t>& json_index, const std::string& file) {
  warnUnlit(scene, json_index, file);
  warnTiny(scene, json_index, file);
  const bool none = !anyLightReachesAnObject(scene);
  for (size_t i = 0; i < scene.lights.size(); ++i)
    if (!lightReachesAnObject(scene, scene.lights[i]))
      scene.warnings.push_back(printable(
          file + ": /lights/" + std::to_string(i) + ": the light's " +
          (scene.lights[i].type == Light::Type::Spot ? "cone" : "beam") +
          " misses every object, so it lights nothing" +
          (none ? " (no light reaches an object: eikon render does not simulate them)" : "") +
          "; aim it at an object (direction, position) or widen it"));
}

}  // namespace eikon
