// eikon::Session (core/session/session.h): the range checks both front ends share, the settings a
// request turns into, and one straight ray through air marched by the CPU twin of a session.
#include "core/session/session.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>

#include "core/render/view_pipeline_start.h"
#include "core/render/view_renderer.h"
#include "core/volume/field.h"
#include "shaders/eikon_shared.h"
#include "tests/core/scene_support.h"

namespace eikon {
namespace {

/// The SettingError a check raises: "setting|complaint", or "" (a test failure) when it passes.
template <class F>
std::string settingErrorOf(F&& check) {
  try {
    check();
  } catch (const SettingError& e) {
    EXPECT_EQ(std::string(e.what()), e.setting() + " " + e.complaint());
    return e.setting() + "|" + e.complaint();
  }
  ADD_FAILURE() << "expected a SettingError";
  return {};
}

TEST(Session, ViewRangesAreTheCliWords) {
  ViewRequest v;
  v.width = 0;
  EXPECT_EQ(settingErrorOf([&] { checkViewRequest(v); }), "width|must be in [1, 16384], got 0");
  v.width = 16384;
  v.height = 16385;
  EXPECT_EQ(settingErrorOf([&] { checkViewRequest(v); }),
            "height|must be in [1, 16384], got 16385");
  v.height.reset();
  v.spp = 4097;
  EXPECT_EQ(settingErrorOf([&] { checkViewRequest(v); }), "spp|must be in [1, 4096], got 4097");
  v.spp = 1;
  v.wavelengths = -1;
  EXPECT_EQ(settingErrorOf([&] { checkViewRequest(v); }),
            "wavelengths|must be in [0, 256], got -1");
  v.wavelengths = 0;
  v.march = MarchSettings{};
  v.march->step_voxels = 0.0;
  EXPECT_EQ(settingErrorOf([&] { checkViewRequest(v); }), "step|must be in (0, 4] voxels");
  v.march->step_voxels = 4.0;
  EXPECT_NO_THROW(checkViewRequest(v));
  EXPECT_EQ(settingErrorOf([] { parseIntegrator("verlet"); }),
            "integrator|must be euler, midpoint or rk4");
  EXPECT_EQ(parseIntegrator("midpoint"), Integrator::Midpoint);
}

TEST(Session, LightAndTraceRangesAreTheCliWords) {
  LightRequest l;
  EXPECT_NO_THROW(checkLightRequest(l));
  l.splat = "max";
  EXPECT_EQ(settingErrorOf([&] { checkLightRequest(l); }),
            "light-splat|must be accumulate or highest, got 'max'");
  l.splat = "highest";
  l.caustics = "stop";
  EXPECT_EQ(settingErrorOf([&] { checkLightRequest(l); }),
            "caustics|must be pass or kill, got 'stop'");
  l.caustics = "kill";
  l.max_patches = 1023;
  EXPECT_EQ(settingErrorOf([&] { checkLightRequest(l); }),
            "max-patches|must be in [1024, 16777216]");
  l.max_patches = 1024;
  l.step_voxels = 2.5;
  EXPECT_EQ(settingErrorOf([&] { checkLightRequest(l); }),
            "light-step|must be in (0, 2] voxels, or 0 for the default (0.5)");
  l.step_voxels = 0.0;  // the default
  l.bands = 65;
  EXPECT_EQ(settingErrorOf([&] { checkLightRequest(l); }),
            "light-bands|must be in [1, 64], or 0 for the scene's default");
  l.bands = 0;
  l.threads = -7;
  EXPECT_EQ(settingErrorOf([&] { checkLightRequest(l); }),
            "threads|must be in [1, 1024], or 0 for all cores");
  l.threads = 0;
  EXPECT_NO_THROW(checkLightRequest(l));

  TraceRequest ray{{0, 0, 0}, {0, 0, 0}, 587.56};
  EXPECT_EQ(settingErrorOf([&] { checkTraceRequest(ray); }), "dir|must be a non-zero vector");
  ray.direction = {0, 0, 2};
  ray.wavelength_nm = 99.0;
  EXPECT_EQ(settingErrorOf([&] { checkTraceRequest(ray); }),
            "wavelength|must be in [100, 10000] nm");
  // The origin is bounded as a scene's positions are (±1e12 mm): at z = −1e300 the trace printed
  // an exit at −inf and NaN Stokes with exit code 0.
  ray.wavelength_nm = 550.0;
  ray.origin = {0, 2, -1e300};
  EXPECT_EQ(settingErrorOf([&] { checkTraceRequest(ray); }),
            "origin|must be within ±1e12 mm on each axis, got -1e+300 on z");
  ray.origin = {1e12, -1e12, 0};
  EXPECT_NO_THROW(checkTraceRequest(ray));
  // A direction whose length overflows would normalise to zero.
  ray.direction = {1e300, 1e300, 0};
  EXPECT_EQ(settingErrorOf([&] { checkTraceRequest(ray); }),
            "dir|must have a finite length (scale it down)");
}

// A BK7-like sphere (Sellmeier: dispersive) in a 16 mm box; the ray along z at x = y = −6 mm never
// comes near it (closest 7 mm, the smoothing reach < 3 mm), so it crosses air: straight, OPL =
// the 15 mm from z = −7 to the face z = 8, no interface, and the e-mode is the o-mode.
const char* kScene = R"({
  "camera": {"position": [0, 0, -40], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 30,
             "width": 8, "height": 6},
  "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 16},
  "materials": {"glass": {"n": {"sellmeier": [1.03961212, 0.231792344, 1.01046945,
                                               0.00600069867, 0.0200179144, 103.560653]}}},
  "objects": [{"shape": "sphere", "center": [2, 2, 0], "radius": 3, "material": "glass"}]
})";

TEST(Session, RequestsTakeTheRenderDefaults) {
  const Scene scene = parseScene(kScene, "session.json");
  ViewRequest v;
  RenderSettings rs = renderSettings(scene, v);
  EXPECT_EQ(rs.width, 0);         // the camera's
  EXPECT_EQ(rs.wavelengths, 16);  // dispersive
  EXPECT_DOUBLE_EQ(rs.march.step_voxels, 0.5);
  v.width = 40;
  v.wavelengths = 0;
  rs = renderSettings(scene, v);
  EXPECT_EQ(rs.width, 40);
  EXPECT_EQ(rs.wavelengths, 0);
  // The default light options: dt = step · h.
  LightRequest l;
  l.step_voxels = 0.5;
  EXPECT_DOUBLE_EQ(lightingOptions(l, 2.0).wave.dt, 1.0);
}

TEST(Session, CpuTwinTracesBothModesAndVoxelisesOnce) {
  Session session(std::make_shared<Scene>(parseScene(kScene, "session.json")),
                  []() -> std::shared_ptr<vk::Context> {
                    ADD_FAILURE() << "a CPU session made a Vulkan context";
                    return nullptr;
                  });
  const VolumeSet* first = &session.prepare(false);
  EXPECT_EQ(&session.prepare(false), first);
  EXPECT_FALSE(session.hasContext());
  EXPECT_EQ(session.deviceName(false), "CPU reference (double)");
  const auto both = session.trace({{{-6, -6, -7}, {0, 0, 1}, 587.56}}, MarchSettings{}, false);
  ASSERT_EQ(both.size(), 1u);
  for (const TraceOutcome& t : both[0]) {
    EXPECT_TRUE(t.left_volume);
    EXPECT_NEAR(t.exit_point.x, -6.0, 1e-9);
    EXPECT_NEAR(t.exit_point.y, -6.0, 1e-9);
    EXPECT_NEAR(t.exit_point.z, 8.0, 1e-6);
    EXPECT_NEAR(t.exit_direction.z, 1.0, 1e-12);
    EXPECT_NEAR(t.optical_path_mm, 15.0, 1e-6);
    EXPECT_EQ(t.interfaces, 0);
  }
  EXPECT_FALSE(session.hasContext());
}

// A glass ball over a diffuse floor under a point light, small enough to simulate in a second.
constexpr const char* kLitScene = R"({
  "camera": {"position": [0, 12, -30], "look_at": [0, -2, 0], "up": [0, 1, 0], "fov_deg": 40, "width": 32, "height": 24},
  "environment": {"type": "constant", "radiance": [0.02, 0.02, 0.02]},
  "volume": {"bounds_min": [-8, -5, -8], "bounds_max": [8, 9, 8], "resolution": 16},
  "materials": {"glass": {"n": 1.5}, "floor": {"n": 1.0, "opacity": 1, "albedo": 0.8}},
  "objects": [{"shape": "box", "center": [0, -4, 0], "size": [15, 1, 15], "material": "floor"},
              {"shape": "sphere", "center": [0, 1, 0], "radius": 3, "material": "glass"}],
  "lights": [{"type": "point", "position": [0, 7, 0], "intensity": 40}]
})";

/// The viewer's moved light (docs/viewer.md "Moving a light"): light volumes simulated by another
/// session and swapped in render exactly what a session simulating the moved light itself
/// renders, through the same GPU renderer (its pipeline stays built: no compile).
TEST(Session, SwappedLightVolumesRenderAsASessionOfTheMovedLight) {
  auto scene = std::make_shared<Scene>(parseScene(kLitScene, "lit.json"));
  auto moved = std::make_shared<Scene>(*scene);
  moved->lights.front().position = {-4, 7, 0};
  Session session(scene), other(moved);
  RenderSettings rs = renderSettings(*scene, ViewRequest{});
  session.simulateLight(LightRequest{}, false, {});
  const RenderImage before = session.render(rs, true);
  other.simulateLight(LightRequest{}, false, {});
  const RenderImage expected = other.render(rs, true);
  const VolumeSet& v = other.prepare(true);
  session.setLightVolumes(v.light_fluence, v.light_flux);
  EXPECT_TRUE(session.renderReady(rs)) << "the renderer was made again";
  const RenderImage after = session.render(rs, true);
  ASSERT_EQ(after.rgb.size(), expected.rgb.size());
  double worst = 0, changed = 0;
  for (size_t i = 0; i < after.rgb.size(); ++i) {
    worst = std::max(worst, double(std::abs(after.rgb[i] - expected.rgb[i])));
    changed = std::max(changed, double(std::abs(after.rgb[i] - before.rgb[i])));
  }
  EXPECT_EQ(worst, 0.0);     // the same volumes through the same kernel
  EXPECT_GT(changed, 0.05);  // and the light did move
  EXPECT_THROW(session.setLightVolumes({}, {}), std::invalid_argument);
}

/// The viewer's first light (apps/view_command.cpp, docs/viewer.md "The first light"): the viewer's
/// session renders the scene unlit from its interfaces alone while a second session, on another
/// thread, voxelises the whole volume, simulates the light and makes the lit renderer on the
/// viewer's context (makeRendererFor); adopted, it renders what a session that simulated the
/// light itself renders, with its pipeline compiled already, and the viewer's session never
/// voxelised its fields. A moved light's volumes then go into that renderer in place.
TEST(Session, LitRendererMadeOnAnotherThreadIsAdoptedWithoutVoxelising) {
  auto scene = std::make_shared<Scene>(parseScene(kLitScene, "lit.json"));
  Session viewer(scene), mover(std::make_shared<Scene>(*scene)), alone(scene);
  const RenderSettings rs = renderSettings(*scene, ViewRequest{});
  ASSERT_FALSE(viewer.prepareGpuRender().fields);  // interfaces only
  const RenderImage unlit = viewer.render(rs, true);
  EXPECT_THROW(mover.makeRendererFor(viewer.context(), *scene, &rs), std::logic_error);

  // The mover's work on a thread of its own while the viewer keeps rendering on its context.
  std::unique_ptr<ViewRenderer> lit;
  std::string error;
  std::atomic<bool> done{false};
  std::thread worker([&] {
    try {
      mover.simulateLight(LightRequest{}, false, {});
      lit = mover.makeRendererFor(viewer.context(), *scene, &rs);
    } catch (const std::exception& e) {
      error = e.what();
    }
    done = true;
  });
  int renders = 0;
  do {
    viewer.render(rs, true);
    ++renders;
  } while (!done);
  worker.join();
  ASSERT_TRUE(error.empty()) << error;
  ASSERT_TRUE(lit);
  std::printf("%d unlit renders while the mover worked\n", renders);

  VolumeSet& m = mover.prepare(false);
  EXPECT_THROW(viewer.adoptRenderer(nullptr, m.light_fluence, m.light_flux), std::invalid_argument);
  EXPECT_THROW(
      viewer.adoptRenderer(mover.makeRendererFor(viewer.context(), *scene, nullptr), {}, {}),
      std::invalid_argument);
  viewer.adoptRenderer(std::move(lit), m.light_fluence, m.light_flux);
  // Its pipeline was asked for with it (`expected`): it becomes ready without a render asking.
  const auto asked = std::chrono::steady_clock::now();
  while (!viewer.renderReady(rs) &&
         std::chrono::steady_clock::now() - asked < std::chrono::minutes(2))
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_TRUE(viewer.renderReady(rs)) << "the lit pipeline was not compiled with the renderer";
  const RenderImage adopted = viewer.render(rs, true);
  EXPECT_FALSE(viewer.prepareGpuRender().fields) << "the viewer's session voxelised its fields";
  alone.simulateLight(LightRequest{}, false, {});
  const RenderImage expected = alone.render(rs, true);
  ASSERT_EQ(adopted.rgb.size(), expected.rgb.size());
  double worst = 0, lighter = 0;
  for (size_t i = 0; i < adopted.rgb.size(); ++i) {
    worst = std::max(worst, double(std::abs(adopted.rgb[i] - expected.rgb[i])));
    lighter = std::max(lighter, double(adopted.rgb[i] - unlit.rgb[i]));
  }
  EXPECT_EQ(worst, 0.0);     // the same volumes through the same kernel
  EXPECT_GT(lighter, 0.05);  // and the light is on

  // A moved light: its volumes into the adopted renderer, in place, still without voxelising.
  auto moved = std::make_shared<Scene>(*scene);
  moved->lights.front().position = {-4, 7, 0};
  Session other(moved);
  other.simulateLight(LightRequest{}, false, {});
  const VolumeSet& o = other.prepare(true);
  viewer.setLightVolumes(o.light_fluence, o.light_flux);
  EXPECT_TRUE(viewer.renderReady(rs)) << "the renderer was made again";
  const RenderImage after = viewer.render(rs, true), wanted = other.render(rs, true);
  EXPECT_FALSE(viewer.prepareGpuRender().fields);
  ASSERT_EQ(after.rgb.size(), wanted.rgb.size());
  for (size_t i = 0; i < after.rgb.size(); ++i) ASSERT_EQ(after.rgb[i], wanted.rgb[i]) << i;
  EXPECT_EQ(viewer.context().validationMessageCount(), 0u);

  // Whatever later needs the whole volume voxelises it, and keeps the light it was given.
  const VolumeSet& whole = viewer.prepare(false);
  EXPECT_TRUE(whole.whole());
  EXPECT_TRUE(whole.light_fluence == o.light_fluence && whole.light_flux == o.light_flux);
}

}  // namespace
}  // namespace eikon

namespace eikon {
namespace {

// A GPU render of sharp interfaces without light volumes voxelises only the interfaces
// (Session::prepareGpuRender, voxelizeInterfaces): no per-voxel field, and on the exact path no
// per-voxel boundary either. The kernels never read them there (kernel_bindings_test.cpp), so the
// image is the one rendered from the whole volume, bit for bit; anything else the session does
// afterwards voxelises the whole volume first.
std::string sharpScene(const std::string& object) {
  return R"({
  "camera": {"position": [0, 0, -40], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 30,
             "width": 16, "height": 12},
  "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 24},
  "materials": {"glass": {"n": 1.5, "attenuation_per_mm": [0.02, 0.01, 0.03]}},
  "objects": [)" +
         object + R"(]
})";
}

void checkInterfacesOnly(const std::string& object, bool exact) {  // else convex planes apart
  auto scene = std::make_shared<Scene>(parseScene(sharpScene(object), "lean.json"));
  ASSERT_EQ(scene->interfaces, Scene::Interfaces::Sharp);
  RenderSettings rs;
  Session lean(scene), whole(scene);
  const VolumeSet& v = lean.prepareGpuRender();
  EXPECT_FALSE(v.fields);
  EXPECT_TRUE(v.index[0][0].empty() && v.medium[0].empty() && v.emission.empty());
  EXPECT_EQ(v.attenuating, !object.empty());  // the flags are the used materials'
  EXPECT_EQ(v.boundary.exact, exact);
  EXPECT_EQ(v.boundary.convex_apart, !exact);
  EXPECT_TRUE(v.boundary.regionsOnShapes());
  EXPECT_FALSE(v.boundary.hasVoxels());  // every region and crossing on the shapes
  EXPECT_FALSE(v.boundary.empty());
  EXPECT_THROW(VolumeField{v}, std::invalid_argument);
  const VolumeSet& w = whole.prepare(true);
  EXPECT_TRUE(w.fields);
  EXPECT_EQ(w.boundary.exact, exact);
  const RenderImage a = lean.render(rs, true), b = whole.render(rs, true);
  ASSERT_EQ(a.rgb.size(), size_t(16 * 12 * 3));
  ASSERT_EQ(a.rgb.size(), b.rgb.size());
  int differ = 0, lit = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i) {
    differ += a.rgb[i] != b.rgb[i] ? 1 : 0;
    lit += a.rgb[i] != 0.0f ? 1 : 0;
  }
  EXPECT_EQ(differ, 0);
  EXPECT_GT(lit, 0);
  // The CPU twin needs the fields: prepare() voxelises them, and the GPU renderer made before
  // still renders the same image.
  const VolumeSet& full = lean.prepare(false);
  EXPECT_TRUE(full.fields);
  EXPECT_EQ(full.index[0][0].size(), full.grid.count());
  EXPECT_EQ(lean.render(rs, true).rgb, a.rgb);
  EXPECT_NO_THROW(lean.trace({{{-6, -6, -7}, {0, 0, 1}, 587.56}}, MarchSettings{}, false));
}

TEST(SessionGpu, SharpSphereRenderVoxelisesOnlyItsShape) {
  checkInterfacesOnly(
      R"({"shape": "sphere", "center": [0, 0, 0], "radius": 5, "material": "glass"})", true);
}

TEST(SessionGpu, LonePrismRenderVoxelisesOnlyItsShape) {
  checkInterfacesOnly(R"({"shape": "prism", "apex_deg": 60, "side": 8, "height": 10,
                          "material": "glass"})",
                      false);
}

// A scene without objects is on the exact path too: no voxel of the boundary is made or read,
// and its view pipeline is the specialised one of the exact path (kExact non-zero, EIKON_F_EXACT)
// where it took the general walk through the voxels (and cost 3x the sphere's start-up).
TEST(SessionGpu, SceneWithoutObjectsVoxelisesNothingAndTakesTheExactPipeline) {
  checkInterfacesOnly("", true);
  auto scene = std::make_shared<Scene>(parseScene(sharpScene(""), "empty.json"));
  Session s(scene);
  const VolumeSet& v = s.prepareGpuRender();
  EXPECT_TRUE(v.boundary.shapes.empty());
  EXPECT_NE(volumeFeatureFlags(v) & EIKON_F_EXACT, 0);
  EXPECT_NE(volumeExactConstant(v), 0);
  EXPECT_EQ(predictVolumeFeatureFlags(*scene, false), volumeFeatureFlags(v));
  // Nothing to cross: every pixel is the environment seen along its camera ray, on both twins.
  RenderSettings rs;
  const RenderImage gpu = s.render(rs, true), cpu = s.render(rs, false);
  ASSERT_EQ(gpu.rgb.size(), cpu.rgb.size());
  for (size_t i = 0; i < gpu.rgb.size(); ++i)
    EXPECT_NEAR(gpu.rgb[i], cpu.rgb[i], 1e-5 + 1e-5 * std::abs(cpu.rgb[i])) << i;
  EXPECT_EQ(gpu.mean_steps, 0.0);
}

TEST(SessionGpu, SmoothedInterfacesAreVoxelisedWhole) {
  std::string text =
      sharpScene(R"({"shape": "sphere", "center": [0, 0, 0], "radius": 5, "material": "glass"})");
  text.insert(text.rfind('}'), R"(, "interfaces": "smoothed")");
  Session s(std::make_shared<Scene>(parseScene(text, "smoothed.json")));
  EXPECT_TRUE(s.prepareGpuRender().fields);
  EXPECT_THROW(voxelizeInterfaces(*s.scene()), std::invalid_argument);
}

}  // namespace
}  // namespace eikon
