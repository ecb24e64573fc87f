// eikon trace SCENE.json --origin x,y,z --dir x,y,z --wavelength NM [--json] [--reference]
// Traces one ray through the voxelised scene and prints, per mode, exit point, exit direction,
// wave normal, optical path, transmittance, interfaces crossed, total internal reflections and
// steps (docs/design.md §3). Isotropic scenes print one mode, marked "o=e" (--json gives both,
// identical). Transmittance is the mode's own (Fresnel for its polarisation × attenuation);
// unpolarised light gives each mode half of the incident power.
#include <array>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>

#include "apps/commands.h"
#include "apps/progress.h"
#include "core/session/session.h"
#include "core/vk/timings.h"

namespace eikon::cli {
namespace {

glm::dvec3 parseVec(const std::string& s, const char* what) {
  std::stringstream ss(s);
  std::string part;
  std::vector<double> v;
  while (std::getline(ss, part, ',')) {
    try {
      size_t used = 0;
      double x = std::stod(part, &used);
      if (used != part.size() || !std::isfinite(x)) throw std::invalid_argument("");
      v.push_back(x);
    } catch (...) {
      throw CliError(std::string(what) + " must be three finite numbers x,y,z, got '" + s + "'");
    }
  }
  if (v.size() != 3)
    throw CliError(std::string(what) + " must be three numbers x,y,z, got '" + s + "'");
  return {v[0], v[1], v[2]};
}

struct TraceArgs {
  std::string scene, origin, dir;
  double wavelength = 587.5618, step = 0.25;
  bool json = false, reference = false, quiet = false, strict = false;
  std::string integrator = "rk4", progress = "auto";
};

/// The trace as JSON (--json) or as text: per mode, where and how the ray left.
void printTrace(const TraceArgs& a, const Scene& scene, const std::array<TraceOutcome, 2>& modes,
                const std::string& device) {
  auto vec = [](const glm::dvec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); };
  if (a.json) {
    nlohmann::json j;
    j["wavelength_nm"] = a.wavelength;
    j["modes"] = nlohmann::json::array();
    for (int mi = 0; mi < 2; ++mi) {
      const TraceOutcome& t = modes[size_t(mi)];
      j["modes"].push_back({{"mode", mi == 0 ? "o" : "e"},
                            {"exit_point", vec(t.exit_point)},
                            {"exit_direction", vec(t.exit_direction)},
                            {"wave_normal", vec(t.wave_normal)},
                            {"optical_path_mm", t.optical_path_mm},
                            {"transmittance", t.transmittance},
                            {"left_volume", t.left_volume},
                            {"steps", t.steps},
                            {"interfaces", t.interfaces},
                            {"total_internal_reflections", t.total_internal_reflections}});
    }
    j["device"] = device;
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  // The text carries what --json carries. An isotropic scene has one mode: the o and e traces
  // coincide, so it is printed once and said so.
  const bool isotropic = !scene.anyUniaxial();
  std::printf("wavelength %.4f nm on %s%s\n", a.wavelength, device.c_str(),
              isotropic ? " (isotropic scene: the o and e modes coincide)" : "");
  for (int mi = 0; mi < (isotropic ? 1 : 2); ++mi) {
    const TraceOutcome& t = modes[size_t(mi)];
    std::printf(
        "  %s: exit (%.6f, %.6f, %.6f) dir (%.6f, %.6f, %.6f) wave normal (%.6f, %.6f, %.6f) OPL "
        "%.6f mm T %.6f%s\n",
        isotropic ? "o=e"
        : mi == 0 ? "o"
                  : "e",
        t.exit_point.x, t.exit_point.y, t.exit_point.z, t.exit_direction.x, t.exit_direction.y,
        t.exit_direction.z, t.wave_normal.x, t.wave_normal.y, t.wave_normal.z, t.optical_path_mm,
        t.transmittance, t.left_volume ? "" : " (stopped inside)");
    std::printf("  %*s  %d interfaces crossed, %d total internal reflections, %d steps\n",
                isotropic ? 3 : 1, "", t.interfaces, t.total_internal_reflections, t.steps);
  }
}
void runTrace(const TraceArgs& a);
}  // namespace

void addTraceCommand(CLI::App& app) {
  auto a = std::make_shared<TraceArgs>();
  auto* sub = app.add_subcommand(
      "trace", "Trace one ray through a scene and report where and how it leaves");
  sub->add_option("scene", a->scene, "Scene JSON file")->required();
  sub->add_option("--origin", a->origin, "Ray origin x,y,z (mm)")->required();
  sub->add_option("--dir", a->dir, "Ray direction x,y,z (any non-zero length)")->required();
  sub->add_option("--wavelength", a->wavelength, "Wavelength in nm (default 587.5618, the d line)");
  sub->add_option("--step", a->step, "Integration step in voxels (default 0.25)");
  sub->add_flag("--json", a->json, "Print JSON");
  sub->add_flag("--reference", a->reference,
                "Use the double-precision CPU reference instead of the GPU");
  sub->add_flag("-q,--quiet", a->quiet, "No progress lines (same as --progress never)");
  sub->add_flag("--strict", a->strict, "Treat the scene's warnings as errors (as render --strict)");
  sub->add_option("--progress", a->progress,
                  "auto (default: voxelising progress with ETA on stderr when it is a terminal), "
                  "always or never");
  sub->callback([a] { runTrace(*a); });
}

namespace {
void runTrace(const TraceArgs& a) {
  TraceRequest req{parseVec(a.origin, "--origin"), parseVec(a.dir, "--dir"), a.wavelength};
  // The range checks are the session's, as Python's (core/session/session.h).
  checkTraceRequest(req);
  checkMarchStep(a.step);
  req.direction = glm::normalize(req.direction);
  const ProgressMode progress_mode = progressMode(a.progress, a.quiet);
  auto scene = std::make_shared<Scene>(loadScene(a.scene));
  timings::mark("scene parsed");
  // Voxelising a 128³ scene takes seconds; the trace itself is instant.
  Progress progress(progress_mode);
  MarchSettings ms;
  ms.step_voxels = a.step;
  for (const std::string& w : scene->warnings) {
    if (a.strict) throw CliError(w + " (--strict)");
    std::fprintf(stderr, "eikon: warning: %s\n", w.c_str());
  }
  Session session(scene);
  session.setProgress({[&](const char* what, double f) { progress.update(what, f); },
                       [&](const char* what) { progress.working(what); }});
  session.prepare(!a.reference);
  timings::mark("voxelised");
  const std::array<TraceOutcome, 2> modes = session.trace({req}, ms, !a.reference).front();
  progress.finish();
  timings::mark("traced");
  const std::string device = session.deviceName(!a.reference);
  printTrace(a, *scene, modes, device);
}
}  // namespace

}  // namespace eikon::cli
