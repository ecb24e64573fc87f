// eikon trace SCENE.json --origin x,y,z --dir x,y,z --wavelength NM [--json] [--reference]
// Traces one ray through the voxelised scene and prints, per mode, exit point, exit direction,
// wave normal, optical path, transmittance, interfaces crossed, total internal reflections and
// steps (docs/design.md §3). Isotropic scenes print one mode, marked "o=e" (--json gives both,
// identical). Transmittance is the mode's own (Fresnel for its polarisation × attenuation);
// unpolarised light gives each mode half of the incident power.
//
// Polarisation (docs/polarisation.md): in a scene with sharp interfaces the ray is also followed
// with its field (the polarised trace of the chosen twin) for the input Stokes vector --stokes
// S0,S1,S2,S3 (default 1,0,0,0, unpolarised; in Mitsuba 3's stokesBasis of --dir), and the Stokes
// vector of the light leaving along the traced path is printed: "stokes_out" (the strongest
// beam, in the stokesBasis of its direction) and "polarised_beams" (every exit direction).
//
// --tree prints the light tree of the ray as JSON instead (core/contract/light_tree.h, on the
// CPU twin): every Fresnel split followed both ways, per mode (docs/design.md §3 "The light
// tree"), within --tree-min-weight and --tree-max-depth.
#include <array>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

#include "apps/commands.h"
#include "apps/progress.h"
#include "core/session/front_end.h"
#include "core/session/light_tree_json.h"
#include "core/session/session.h"

namespace eikon::cli {
namespace {

glm::dvec3 parseVec(const std::string& s, const char* what) {
  const std::vector<double> v = parseNumberList(s, what, 3, "x,y,z");
  return {v[0], v[1], v[2]};
}

/// --stokes: four finite numbers with S0 > 0 and a degree of polarisation ≤ 1.
Stokes parseStokes(const std::string& s) {
  auto bad = [&](const std::string& why) {
    return CliError("--stokes " + why + ", got '" + s + "'");
  };
  const std::vector<double> v = parseNumberList(s, "--stokes", 4, "S0,S1,S2,S3");
  const Stokes st(v[0], v[1], v[2], v[3]);
  if (!(st[0] > 0)) throw bad("needs S0 > 0");
  if (degreeOfPolarisation(st) > 1.0 + 1e-9)
    throw bad("has a degree of polarisation sqrt(S1² + S2² + S3²)/S0 above 1");
  return st;
}

struct TraceArgs {
  std::string scene, origin, dir, stokes;
  bool stokes_given = false;  ///< --stokes was given, with any value (an empty one is refused)
  double wavelength = 0, step = 0;  ///< the settings table's defaults (addSettingOption)
  bool json = false, reference = false, quiet = false, strict = false, tree = false;
  double tree_min_weight = 0;  ///< the settings table's defaults (addSettingOption)
  int tree_max_depth = 0;
  bool tree_limits_given = false;  ///< --tree-min-weight or --tree-max-depth was given
  std::string integrator = "rk4", progress = "auto";
};

/// The trace as JSON (--json) or as text: per mode, where and how the ray left.
/// The polarised trace's beams as JSON: direction, exit point, frame, Stokes vector, branches.
nlohmann::json beamsJson(const PolarisedTrace& t) {
  auto vec = [](const glm::dvec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); };
  nlohmann::json beams = nlohmann::json::array();
  for (const PolarisedBeam& b : t.beams)
    beams.push_back({{"direction", vec(b.direction)},
                     {"exit_point", vec(b.exit_point)},
                     {"frame_x", vec(b.frame_x)},
                     {"stokes", {b.stokes[0], b.stokes[1], b.stokes[2], b.stokes[3]}},
                     {"branches", b.branches},
                     {"coherent_groups", b.coherent_groups},
                     {"modes", b.modes}});
  return beams;
}

/// stokes_out in the text output: the strongest beam, then the others.
void printPolarised(const Stokes& in, const std::optional<PolarisedTrace>& pol,
                    const std::string& why_not) {
  if (!pol) {
    std::printf("  stokes_out: not traced (%s)\n", why_not.c_str());
    return;
  }
  std::printf("  stokes in (%g, %g, %g, %g)%s\n", in[0], in[1], in[2], in[3],
              pol->truncated ? " (ray tree cut: max branches or events)" : "");
  if (pol->beams.empty()) std::printf("  stokes_out: nothing leaves (absorbed)\n");
  for (size_t k = 0; k < pol->beams.size(); ++k) {
    const PolarisedBeam& b = pol->beams[k];
    std::printf(
        "  %s (%.9f, %.9f, %.9f, %.9f) dir (%.6f, %.6f, %.6f) frame x (%.6f, %.6f, %.6f), "
        "%d branch%s (%s), %d coherent group%s\n",
        k == 0 ? "stokes_out" : "     other", b.stokes[0], b.stokes[1], b.stokes[2], b.stokes[3],
        b.direction.x, b.direction.y, b.direction.z, b.frame_x.x, b.frame_x.y, b.frame_x.z,
        b.branches, b.branches == 1 ? "" : "es", b.modes.c_str(), b.coherent_groups,
        b.coherent_groups == 1 ? "" : "s");
  }
}

void printTrace(const TraceArgs& a, const Scene& scene, const std::array<TraceOutcome, 2>& modes,
                const std::string& device, const Stokes& in,
                const std::optional<PolarisedTrace>& pol, const std::string& why_not) {
  auto vec = [](const glm::dvec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); };
  if (a.json) {
    nlohmann::json j;
    j["wavelength_nm"] = a.wavelength;
    j["modes"] = nlohmann::json::array();
    for (int mi = 0; mi < 2; ++mi) {
      const TraceOutcome& t = modes[size_t(mi)];
      j["modes"].push_back({{"mode", modeName(mi, scene.fastSlowModes())},
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
    j["stokes_in"] = {in[0], in[1], in[2], in[3]};
    if (pol) {
      const Stokes o = pol->beams.empty() ? Stokes(0.0) : pol->beams[0].stokes;
      j["stokes_out"] = {o[0], o[1], o[2], o[3]};
      j["polarised_beams"] = beamsJson(*pol);
      j["polarised_truncated"] = pol->truncated;
    } else {
      j["stokes_out"] = nullptr;
      j["stokes_out_note"] = why_not;
    }
    j["device"] = device;
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  // The text carries what --json carries. An isotropic scene has one mode: the o and e traces
  // coincide, so it is printed once and said so.
  const bool isotropic = !scene.anyUniaxial() && !scene.anyBiaxial();
  std::printf("wavelength %.4f nm on %s%s\n", a.wavelength, device.c_str(),
              isotropic ? " (isotropic scene: the o and e modes coincide)" : "");
  for (int mi = 0; mi < (isotropic ? 1 : 2); ++mi) {
    const TraceOutcome& t = modes[size_t(mi)];
    std::printf(
        "  %s: exit (%.6f, %.6f, %.6f) dir (%.6f, %.6f, %.6f) wave normal (%.6f, %.6f, %.6f) OPL "
        "%.6f mm T %.6f%s\n",
        isotropic ? "o=e" : modeName(mi, scene.fastSlowModes()), t.exit_point.x, t.exit_point.y,
        t.exit_point.z, t.exit_direction.x, t.exit_direction.y, t.exit_direction.z, t.wave_normal.x,
        t.wave_normal.y, t.wave_normal.z, t.optical_path_mm, t.transmittance,
        t.left_volume ? "" : " (stopped inside)");
    std::printf("  %*s  %d interfaces crossed, %d total internal reflections, %d steps\n",
                isotropic ? 3 : 1, "", t.interfaces, t.total_internal_reflections, t.steps);
  }
  printPolarised(in, pol, why_not);
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
  addSettingOption(sub, "wavelength", SettingFront::TraceCli, a->wavelength);  // the table's
  addSettingOption(sub, "step", SettingFront::TraceCli, a->step);
  CLI::Option* stokes = sub->add_option(
      "--stokes", a->stokes,
      "Input Stokes vector S0,S1,S2,S3 of the polarised trace, in Mitsuba 3's "
      "stokesBasis of --dir (default 1,0,0,0: unpolarised); needs sharp interfaces");
  sub->add_flag("--json", a->json, "Print JSON");
  sub->add_flag("--tree", a->tree,
                "Print the ray's light tree as JSON: every Fresnel split followed both ways, per "
                "mode, on the CPU twin (docs/design.md §3)");
  CLI::Option* min_weight =
      addSettingOption(sub, "tree-min-weight", SettingFront::TraceCli, a->tree_min_weight);
  CLI::Option* max_depth =
      addSettingOption(sub, "tree-max-depth", SettingFront::TraceCli, a->tree_max_depth);
  sub->add_flag("--reference", a->reference,
                "Use the double-precision CPU reference instead of the GPU");
  sub->add_flag("-q,--quiet", a->quiet, "No progress lines (same as --progress never)");
  sub->add_flag("--strict", a->strict, "Treat the scene's warnings as errors (as render --strict)");
  sub->add_option("--progress", a->progress,
                  "auto (default: voxelising progress with ETA on stderr when it is a terminal), "
                  "always or never");
  sub->callback([a, stokes, min_weight, max_depth] {
    a->stokes_given = stokes->count() > 0;
    a->tree_limits_given = min_weight->count() + max_depth->count() > 0;
    runTrace(*a);
  });
}

namespace {
constexpr const char* kNeedsSharp = "the polarised trace needs \"interfaces\": \"sharp\"";

void runTrace(const TraceArgs& a) {
  TraceRequest req{parseVec(a.origin, "--origin"), parseVec(a.dir, "--dir"), a.wavelength};
  // The range checks are the session's, as Python's (core/session/session.h).
  checkTraceRequest(req);
  checkMarchStep(a.step);
  const Stokes stokes_in = a.stokes_given ? parseStokes(a.stokes) : Stokes(1, 0, 0, 0);
  if (a.tree_limits_given && !a.tree)
    throw CliError("--tree-min-weight and --tree-max-depth need --tree");
  if (a.tree && a.stokes_given) throw CliError("--tree and --stokes: one at a time");
  LightTreeSettings tree;
  if (a.tree) {
    checkSettingValue(setting("tree-min-weight"), a.tree_min_weight);
    checkSettingValue(setting("tree-max-depth"), a.tree_max_depth);
    tree.min_weight = a.tree_min_weight;
    tree.max_depth = a.tree_max_depth;
  }
  req.direction = glm::normalize(req.direction);
  const ProgressMode progress_mode = progressMode(a.progress, a.quiet);
  auto scene = std::make_shared<Scene>(loadScene(a.scene));
  checkIndicesAt(*scene, req.wavelength_nm);  // before anything is voxelised
  timings::mark("scene parsed");
  if (a.stokes_given && scene->interfaces != Scene::Interfaces::Sharp)
    throw CliError(std::string("--stokes: ") + kNeedsSharp);  // before any voxelising or warning
  // An explicit --stokes on the GPU: a scene with more polariser sheets than its polarised trace
  // takes is refused before voxelising (without --stokes the trace runs and says why not).
  if (a.stokes_given && !a.reference) checkPolariserSheetsOnGpu(*scene);
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
  if (a.tree) {  // the CPU twin's alone
    session.prepare(false);
    timings::mark("voxelised");
    const std::vector<LightTree> trees = session.lightTrees(req, ms, tree);
    progress.finish();
    timings::mark("traced");
    const nlohmann::json j = lightTreesJson(req, tree, trees, session.deviceName(false));
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  session.prepare(!a.reference);
  timings::mark("voxelised");
  const std::array<TraceOutcome, 2> modes = session.trace({req}, ms, !a.reference).front();
  // The polarised trace: an explicit --stokes must be honoured (its failure is the error); by
  // default a scene it does not support prints why instead of stokes_out.
  std::optional<PolarisedTrace> pol;
  std::string why_not;
  if (scene->interfaces != Scene::Interfaces::Sharp) {
    why_not = kNeedsSharp;
  } else {
    try {
      pol = session.tracePolarised(req, stokes_in, {}, !a.reference);
    } catch (const std::runtime_error& e) {
      if (a.stokes_given) throw CliError(std::string("--stokes: ") + e.what());
      why_not = e.what();
    }
  }
  progress.finish();
  timings::mark("traced");
  const std::string device = session.deviceName(!a.reference);
  printTrace(a, *scene, modes, device, stokes_in, pol, why_not);
}
}  // namespace

}  // namespace eikon::cli
