// eikon view SCENE.json [--width W --height H]: an interactive window on the scene, rendered by the
// GPU twin exactly as `eikon render` renders it (ViewRenderer through the session), shown through
// a Vulkan swapchain (ViewPresenter, core/session/viewer.h) in a GLFW window (X11). docs/viewer.md.
//
// Progressive refinement: after any change the view restarts with a coarse frame (a quarter of
// the resolution, one sample, few wavelengths), then the full resolution at few wavelengths
// (spectral scenes), then the full render (--spp samples at the scene's wavelengths), one frame
// per finished sample (RenderSettings::on_pass). Events are polled between bands of rows
// (RenderSettings::progress) and between samples; an event that changes the view throws
// Interrupted out of the render, which ends it (the renderer's resources are RAII) and restarts.
// The refined image is the mean of the same samples `eikon render --spp N` takes, so the two agree
// within the renderer's own noise (tests/apps/viewer_test.cpp).
#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "apps/commands.h"
#include "apps/view_camera.h"
#include "apps/view_save.h"
#include "core/io/exr.h"
#include "core/session/front_end.h"
#include "core/session/session.h"
#include "core/session/viewer.h"
#include "core/session/viewer_lighting.h"

namespace eikon::cli {

namespace {

using Clock = std::chrono::steady_clock;

struct ViewArgs {
  std::string scene, screenshot, save_dir;
  int width = 0, height = 0, spp = 0, wavelengths = -1, coarse = 4, exit_after_frames = 0;
  bool wait_for_input = false;
  double exposure = 0.0;
  std::string integrator, modes;  ///< spp, integrator, modes: the table's defaults
  bool no_light = false, no_prefetch = false;
};

void addViewOptions(CLI::App* sub, ViewArgs& a) {
  sub->add_option("scene", a.scene, "Scene JSON file")->required();
  // The settings of the table (core/session/settings.h), with its help and defaults.
  for (auto [name, variable] : {std::pair{"width", &a.width},
                                {"height", &a.height},
                                {"spp", &a.spp},
                                {"wavelengths", &a.wavelengths}})
    addSettingOption(sub, name, SettingFront::ViewCli, *variable);
  sub->add_option("--coarse", a.coarse,
                  "The first frame after a change has 1/N of the resolution per side, N in [1, "
                  "16] (default 4); N doubles while a coarse frame takes over 0.1 s");
  addSettingOption(sub, "integrator", SettingFront::ViewCli, a.integrator);
  addSettingOption(sub, "modes", SettingFront::ViewCli, a.modes);
  sub->add_flag("--no-prefetch", a.no_prefetch,
                "Do not compile the pipelines of the R and I keys ahead in the background (a key "
                "then shows 'compiling' while its pipeline compiles)");
  sub->add_option("--exposure", a.exposure,
                  "Exposure in stops, as eikon render's PNG (default: the scene's \"render\" "
                  "exposure, else 0)");
  sub->add_flag("--no-light", a.no_light, "Do not simulate the scene's lights");
  sub->add_option("--exit-after-frames", a.exit_after_frames,
                  "Exit after N frames of an unchanged view (or once it is fully refined, if that "
                  "takes fewer), for tests and scripts");
  sub->add_flag("--wait-for-input", a.wait_for_input,
                "With --exit-after-frames: do not exit before a mouse button is released or a "
                "key pressed (scripts that drive the window, whose view may refine before their "
                "input arrives)");
  sub->add_option("--screenshot", a.screenshot,
                  "On exit, write the image on screen (at its rendered size) to this PNG and print "
                  "the camera");
  sub->add_option("--save-dir", a.save_dir,
                  "Folder the S key saves the view into, as SCENE-view-N.exr and .png, never "
                  "over an existing file (default ~/Pictures/eikon)");
}

/// A light simulated in the background (LightMover): its light volumes, ready to be swapped in.
struct MovedLight {
  Light light;                           ///< the light simulated
  std::vector<glm::vec4> fluence, flux;  ///< its light volumes (VolumeSet's)
  /// The first light: the lit renderer made from them (LitRenderer::make), which replaces the
  /// viewer's unlit one.
  LitRenderer renderer;
  bool cached = false;                ///< they came from the light cache
  double seconds = 0;                 ///< the simulation's (or the cache lookup's) time, all told
  double voxelise_seconds = 0;        ///< the first light: the whole volume made meanwhile
  bool volume_copied = false;         ///< it was the viewer's copied (LitView::whole)
  std::vector<std::string> warnings;  ///< "light cache: ..."
  std::string error;                  ///< the simulation failed: why
};

/// What the first light's renderer is made for: the viewer's context and scene, and the render
/// that will follow (its pipeline compiles on the mover's thread too).
struct LitView {
  vk::Context* ctx = nullptr;
  const Scene* scene = nullptr;
  RenderSettings expected;
  /// The viewer's volume where it is whole already (smoothed interfaces: its first frame needed
  /// it), copied on the worker thread instead of voxelising the scene again (mesh_torus_caustic:
  /// 3.5 s of copying against 5–6 s of voxelising); the viewer leaves it unchanged meanwhile.
  const VolumeSet* whole = nullptr;
};

/// The scene's first light simulated in the background, and again whenever a drag moves it. A
/// Session of its own on a copy of the scene (voxelised whole at its first start, on the worker
/// thread, or a copy of the viewer's volume where that is whole; kept for the next moves) simulates
/// the light through the light cache (the key covers the medium, the lights and the simulator
/// settings, never the camera: a light put back where it was simulated before is only looked up),
/// while the viewer keeps rendering: unlit from a volume of interfaces only until the first light
/// arrives, then with the light volumes it has. The first light comes with the lit renderer, made
/// on the worker thread on the viewer's context (uploads and the pipeline's compile included),
/// which the viewer adopts (Session::adoptRenderer); a moved light's volumes are swapped into that
/// renderer in place (Session::setLightVolumes): no renderer or pipeline is made again.
class LightMover {
 public:
  /// What the worker is doing (the title says it).
  enum class Stage { Voxelising, Simulating, Preparing };
  /// `on_cpu`: the twin the viewer's own session chose (Session::lightOnCpuTwin), so that both
  /// look up the same light-cache entries.
  LightMover(const Scene& scene, bool on_cpu, std::filesystem::path cache)
      : scene_(std::make_shared<Scene>(scene)), on_cpu_(on_cpu), cache_(std::move(cache)) {}
  ~LightMover() { stop(); }
  /// Stop the work in flight at its next progress report, for good (the window closed):
  /// voxelising and simulating end there and nothing is cached; the lit renderer's compile, if
  /// begun, runs out.
  void stop() {
    cancel_ = true;
    if (worker_.joinable()) worker_.join();
  }
  bool busy() const { return worker_.joinable() && !done_; }
  /// A simulation has finished and finished() has not reported it yet.
  bool done() const { return worker_.joinable() && done_; }
  /// The fraction of the running stage done, [0, 1].
  double fraction() const { return fraction_; }
  Stage stage() const { return stage_; }
  /// The mover's volume is voxelised whole (its first start voxelised it).
  bool voxelised() const { return voxelised_; }
  /// Simulate the scene with its first light replaced by `light`, unless a simulation is running.
  /// `first`: the first light, whose lit renderer is made too, on the worker thread (the mover's
  /// volume is voxelised there first).
  bool start(const Light& light, const LitView* first = nullptr) {
    if (busy()) return false;
    if (worker_.joinable()) worker_.join();  // the scene and the session are this thread's now
    done_ = false;
    fraction_ = 0.0;
    stage_ = Stage::Simulating;
    scene_->lights.front() = light;
    result_ = MovedLight{};
    result_.light = light;
    std::optional<LitView> view;
    if (first) view = *first;
    worker_ = std::thread([this, view = std::move(view)] {
      const auto start = Clock::now();
      try {
        if (!session_) {
          session_ = std::make_unique<Session>(scene_);
          session_->setProgress({[this](const char* what, double f) {
                                   if (cancel_) throw Stopped();
                                   stage_ = std::strcmp(what, "voxelising") == 0
                                                ? Stage::Voxelising
                                                : Stage::Simulating;
                                   fraction_ = f;
                                 },
                                 [this](const char*) {
                                   if (cancel_) throw Stopped();
                                 }});
          stage_ = Stage::Voxelising;
          result_.volume_copied = view && view->whole;
          if (result_.volume_copied)
            session_->adoptVolume(*view->whole);
          else
            session_->prepare(false);
          voxelised_ = true;
          result_.voxelise_seconds = std::chrono::duration<double>(Clock::now() - start).count();
        }
        // The viewer's twin, named: "auto" would decide again, without a device. The GPU twin
        // makes a Vulkan device of the mover's own.
        LightRequest request;
        request.device = on_cpu_ ? "cpu" : "gpu";
        const LightOutcome o = session_->simulateLight(request, on_cpu_, cache_);
        result_.cached = o.cached;
        result_.warnings = o.warnings;
        if (view) {
          stage_ = Stage::Preparing;
          result_.renderer = LitRenderer::make(*session_, *view->ctx, *view->scene, view->expected);
        }
        VolumeSet& v = session_->prepare(false);  // made by simulateLight; refilled by the next
        result_.fluence = std::move(v.light_fluence);
        result_.flux = std::move(v.light_flux);
      } catch (const Stopped&) {
        result_.error = "stopped";
      } catch (const std::exception& e) {
        result_.error = e.what();
      }
      result_.seconds = std::chrono::duration<double>(Clock::now() - start).count();
      done_ = true;
    });
    return true;
  }
  /// True once, when a simulation has finished: what it made.
  bool finished(MovedLight& out) {
    if (!worker_.joinable() || !done_) return false;
    worker_.join();
    out = std::move(result_);
    return true;
  }

 private:
  const std::shared_ptr<Scene> scene_;
  const bool on_cpu_;
  const std::filesystem::path cache_;
  std::unique_ptr<Session> session_;
  std::thread worker_;
  /// Thrown out of the mover's progress callbacks by stop().
  struct Stopped {};
  std::atomic<bool> done_{false}, voxelised_{false}, cancel_{false};
  std::atomic<double> fraction_{0.0};
  std::atomic<Stage> stage_{Stage::Simulating};
  MovedLight result_;
};

/// Thrown out of a render by its callbacks when the view changed (restart) or the window closes.
struct Interrupted {};

/// One stage of the refinement.
struct Stage {
  int width, height, spp, wavelengths;
};

const char* integratorName(Integrator i) {
  return i == Integrator::Euler ? "euler" : i == Integrator::Midpoint ? "midpoint" : "rk4";
}

/// The interactive window: input, refinement, frames.
class Viewer {
 public:
  Viewer(const ViewArgs& a, Session& session, GLFWwindow* window, ViewPresenter& chain,
         RenderSettings base, LightMover* mover)
      : args_(a),
        session_(session),
        window_(window),
        chain_(chain),
        base_(std::move(base)),
        mover_(mover),
        lighting_(session),
        integrator_(base_.march.integrator),
        modes_(base_.modes) {
    if (mover_) wanted_light_ = session_.scene()->lights.front();
    full_wavelengths_ = base_.wavelengths > 0 ? base_.wavelengths : defaultSpectral();
    spectral_ = base_.wavelengths > 0;
    glfwSetWindowUserPointer(window_, this);
    glfwSetCursorPosCallback(window_, [](GLFWwindow* w, double x, double y) {
      static_cast<Viewer*>(glfwGetWindowUserPointer(w))->onCursor(x, y);
    });
    glfwSetMouseButtonCallback(window_, [](GLFWwindow* w, int button, int action, int mods) {
      static_cast<Viewer*>(glfwGetWindowUserPointer(w))->onButton(button, action, mods);
    });
    glfwSetScrollCallback(window_, [](GLFWwindow* w, double, double dy) {
      static_cast<Viewer*>(glfwGetWindowUserPointer(w))->onScroll(dy);
    });
    glfwSetKeyCallback(window_, [](GLFWwindow* w, int key, int, int action, int) {
      if (action == GLFW_PRESS) static_cast<Viewer*>(glfwGetWindowUserPointer(w))->onKey(key);
    });
    glfwSetFramebufferSizeCallback(window_, [](GLFWwindow* w, int, int) {
      static_cast<Viewer*>(glfwGetWindowUserPointer(w))->resized_ = true;
    });
  }

  /// Until the window closes or --exit-after-frames is reached.
  void run() {
    while (!glfwWindowShouldClose(window_) && !quit_) {
      if (resized_) resize();
      if (light_ready_) applyLight();
      changed_ = false;
      refined_ = false;
      frames_since_change_ = 0;
      few_frames_ = 0;
      change_time_ = Clock::now();
      try {
        refine();
      } catch (const Interrupted&) {
        continue;  // a change: start again with a coarse frame
      }
      // Fully refined in fewer frames; a light still being simulated is waited for.
      if (args_.exit_after_frames > 0 && !lightPending() && inputDone()) break;
      while (!changed_ && !resized_ && !quit_ && !glfwWindowShouldClose(window_)) {
        const bool simulating = mover_ && mover_->busy();
        glfwWaitEventsTimeout(simulating ? 0.1 : 0.25);
        handleRequests();
        // --wait-for-input: the input that ends it may come after the view it changed is refined.
        if (!changed_ && args_.exit_after_frames > 0 && !lightPending() && inputDone()) return;
        // The view is refined and a moved light is being simulated: the last image is presented
        // again about 10 times a second, its title saying so, until the new light arrives.
        if (simulating && !changed_) presentAgain();
      }
    }
  }

  /// "N frames; the first after X s; K coarse frames, T s each (median; F frames/s); the last
  /// view refined to S samples in T s". The first frame waits for the pipeline's compilation.
  std::string summary() const {
    std::vector<double> coarse(coarse_seconds_.begin() + (coarse_seconds_.empty() ? 0 : 1),
                               coarse_seconds_.end());
    std::sort(coarse.begin(), coarse.end());
    const double median = coarse.empty() ? 0.0 : coarse[coarse.size() / 2];
    char buf[480];
    std::snprintf(
        buf, sizeof buf,
        "eikon view: %lld frames, the first %.2f s after the window was ready; %zu more "
        "coarse frames, %.3f s each (median: %.1f frames/s; 1/%d size per side at the end); "
        "the last view: full quality "
        "(1 sample, eikon render's default) after %.2f s, %d samples after %.2f s",
        frames_, first_frame_seconds_, coarse.size(), median, median > 0 ? 1.0 / median : 0.0,
        coarse_, full_quality_seconds_, refined_spp_, refined_seconds_);
    char compiles[200];
    std::snprintf(compiles, sizeof compiles,
                  " (%d full-size frames at fewer wavelengths before); %lld frames presented "
                  "while a pipeline compiled (the longest wait %.2f s)",
                  few_frames_, compile_frames_, longest_compile_);
    return std::string(buf) + compiles;
  }

  /// The mover voxelises the whole volume, simulates the scene's own first light (or finds it in
  /// the light cache) and makes the lit renderer, started once the first frame is shown: the view
  /// shows the scene unlit, from a volume of interfaces only, until the lit renderer is swapped in.
  void awaitFirstLight() { first_light_ = light_moved_ = true; }

  const RenderImage& shown() const { return shown_; }
  /// The shown view's lighting and its live figures ("" under the scene's own lighting).
  const std::string& figures() const { return figures_; }
  int shownSamples() const { return shown_spp_; }
  int shownWavelengths() const { return shown_wavelengths_; }
  Modes shownModes() const { return shown_modes_; }

 private:
  int defaultSpectral() const {
    const int d = defaultWavelengths(*session_.scene());
    return d > 0 ? d : kDefaultDispersiveWavelengths;
  }

  /// Coarse (1/--coarse of the size, one sample, few wavelengths), then the full size at few
  /// wavelengths (spectral, stratified passes only), then the full render; stages the settings
  /// make equal are one. With hero wavelength sampling (docs/spectra.md) a pixel sample is one
  /// march that carries every wavelength, so few wavelengths at the full size cost nearly what
  /// the first full-quality sample costs (diamond_brilliant at 400×300: 5.39 s at 4 wavelengths,
  /// 5.87 s at 16, docs/performance.md "Viewer"): that stage is skipped.
  std::vector<Stage> stages() const {
    int w = 0, h = 0;
    glfwGetFramebufferSize(window_, &w, &h);
    const int full = spectral_ ? full_wavelengths_ : 0;
    const int few = std::min(full, 4);
    const int c = coarse_;
    std::vector<Stage> s;
    if (c > 1) s.push_back({std::max(1, w / c), std::max(1, h / c), 1, few});
    if (few != full && !heroSampling()) s.push_back({w, h, 1, few});
    // Unlit, while the first light is simulated: one sample, which leaves the cores to the
    // simulation (refining an unlit view to --spp delayed the light by half on 2 cores).
    s.push_back({w, h, firstLightPending() ? 1 : args_.spp, full});
    return s;
  }

  /// Whether spectral renders of this scene sample by hero wavelengths (the renderer decides by
  /// the same test: core/contract/march_types.h).
  bool heroSampling() const {
    const VolumeSet& v = session_.prepareGpuRender();  // made before the first render
    return useHeroSampling(base_.sampling, v.attenuating || v.emissive || v.opaque);
  }

  /// The render of one stage of the refinement, with the keys' choices.
  RenderSettings settingsOf(const Stage& st) const {
    RenderSettings rs = base_;
    rs.width = st.width;
    rs.height = st.height;
    rs.spp = st.spp;
    rs.wavelengths = st.wavelengths;
    rs.march.integrator = integrator_;
    rs.modes = modes_;
    rs.aov_layer = rs.aov_layer || lighting_.wantsAov();  // the live figures need the stone
    return rs;
  }

  void refine() {
    const int full_width = fullWidth();
    for (const Stage& st : stages()) {
      // The coarse frame is short: it is finished even when the view changes meanwhile, so that a
      // continuous drag still shows a frame per coarse render (a restart at every motion event
      // would show none).
      finish_stage_ = st.width < full_width;
      lighting_.update(!finish_stage_);  // a preset follows the camera once the view refines
      RenderSettings rs = settingsOf(st);
      stage_modes_ = modes_;
      if (st.width <= 0 || st.height <= 0) return;
      waitForPipeline(rs);
      const auto start = Clock::now();
      rs.progress = [this](double) { poll(); };
      rs.on_pass = [&](const RenderImage& so_far, int done, int) {
        show(so_far, done, st.wavelengths, start, st.width < full_width);
      };
      RenderImage img = session_.render(rs, true);
      show(img, st.spp, st.wavelengths, start, st.width < full_width);
      finish_stage_ = false;
      poll();  // a change during the coarse frame restarts here
    }
    refined_spp_ = shown_spp_;
    refined_seconds_ = std::chrono::duration<double>(Clock::now() - change_time_).count();
    refined_ = true;
    updateTitle(Clock::now());
    // The keys' pipelines compile on a core of their own, which a refining view would share (up
    // to half of the machine on lavapipe's 2 cores here): asked for once a view is refined, unless
    // the viewer ends now (--exit-after-frames; the renderer would wait for the compile).
    if (!prefetched_ && !firstLightPending() && !(args_.exit_after_frames > 0 && !lightPending()))
      prefetchKeys();
  }

  /// A stage whose view pipeline is not compiled yet (a key changed the integrator or RGB ↔
  /// spectral before its background compile finished, or --no-prefetch): it compiles on the
  /// renderer's thread while the last image stays on screen, presented again about 10 times a
  /// second under a "compiling..." title, and events are handled: the window keeps responding,
  /// and a change restarts the view (the compile goes on).
  void waitForPipeline(const RenderSettings& rs) {
    if (session_.renderReady(rs)) return;
    session_.prefetchRender(rs);
    const auto start = Clock::now();
    compiling_ = true;
    bool said_compiling = false;
    do {
      if (!shown_.rgb.empty()) {
        if (presentAgain()) ++compile_frames_;
      } else if (!said_compiling) {  // no frame yet: the title counts none (scripts wait for
        said_compiling = true;       // "frames/s"); set once: each new title wakes the wait
        glfwSetWindowTitle(window_, ("eikon view: " + session_.scene()->file.filename().string() +
                                     " (compiling the view pipeline)")
                                        .c_str());
      }
      glfwWaitEventsTimeout(0.1);
      handleRequests();
      if (changed_ || resized_ || quit_ || glfwWindowShouldClose(window_)) {
        compiling_ = false;
        throw Interrupted{};
      }
    } while (!session_.renderReady(rs));
    compiling_ = false;
    longest_compile_ =
        std::max(longest_compile_, std::chrono::duration<double>(Clock::now() - start).count());
  }

  /// The image on screen presented again (the window shows it is alive while the view waits for a
  /// pipeline or a light), with the title brought up to date; at most 10 times a second (a new
  /// title is an X event, which ends the wait for events at once: unthrottled, this would spin).
  /// False when it was too soon.
  bool presentAgain() {
    const auto now = Clock::now();
    if (shown_.rgb.empty() || now - last_again_ < std::chrono::milliseconds(95)) return false;
    last_again_ = now;
    const std::vector<unsigned char> px =
        previewPixels(shown_.width, shown_.height, shown_.rgb, args_.exposure);
    if (!chain_.present(px.data(), shown_.width, shown_.height)) resized_ = true;
    if (mover_ && mover_->busy()) ++light_frames_;
    updateTitle(now);
    return true;
  }

  /// The view pipelines the R and I keys lead to, compiled ahead in the background, one at a time
  /// (the M key needs none): RGB ↔ spectral first, then the next integrators, then both.
  void prefetchKeys() {
    prefetched_ = true;
    if (args_.no_prefetch) return;
    RenderSettings rs = base_;
    rs.modes = modes_;
    const int i0 = int(integrator_);
    for (const auto& [spectral, k] : {std::pair{!spectral_, 0},
                                      {spectral_, 1},
                                      {spectral_, 2},
                                      {!spectral_, 1},
                                      {!spectral_, 2}}) {
      rs.wavelengths = spectral ? full_wavelengths_ : 0;
      rs.march.integrator = Integrator((i0 + k) % 3);
      session_.prefetchRender(rs);
    }
  }

  int fullWidth() const {
    int w = 0, h = 0;
    glfwGetFramebufferSize(window_, &w, &h);
    return w;
  }

  /// One frame: the image on screen, the title, the frame counters.
  void show(const RenderImage& img, int samples, int wavelengths, Clock::time_point start,
            bool coarse) {
    const std::vector<unsigned char> px =
        previewPixels(img.width, img.height, img.rgb, args_.exposure);
    if (!chain_.present(px.data(), img.width, img.height)) resized_ = true;
    const auto now = Clock::now();
    if (frames_ == 0) {
      first_frame_seconds_ = std::chrono::duration<double>(now - opened_).count();
      timings::mark("first frame shown");  // EIKON_TIMINGS=1
    }
    if (samples == 1 && wavelengths == (spectral_ ? full_wavelengths_ : 0) && !coarse)
      full_quality_seconds_ = std::chrono::duration<double>(now - change_time_).count();
    if (wavelengths != (spectral_ ? full_wavelengths_ : 0) && !coarse) ++few_frames_;
    if (coarse) {
      const double seconds = std::chrono::duration<double>(now - start).count();
      if (frames_ > 0) adaptCoarse(seconds);  // the first frame waited for the compilation too
      coarse_seconds_.push_back(seconds);
    }
    shown_ = img;
    figures_ = lighting_.figures(coarse ? RenderImage{} : img);  // a coarse frame: the name
    shown_spp_ = samples;
    shown_wavelengths_ = wavelengths;
    shown_modes_ = stage_modes_;
    if (mover_ && mover_->busy()) ++light_rendered_;
    if (first_light_) ++unlit_frames_;
    if (first_light_ && !mover_->voxelised() && !session_.prepareGpuRender().fields)
      ++unlit_unvoxelised_;  // neither session has the whole volume (it was not waited for)
    ++frames_;
    ++frames_since_change_;
    frame_times_.push_back(now);
    while (frame_times_.size() > 2 && now - frame_times_.front() > std::chrono::seconds(2))
      frame_times_.pop_front();
    updateTitle(now);
    if (args_.exit_after_frames > 0 && frames_since_change_ >= args_.exit_after_frames &&
        inputDone() && !lightPending()) {
      quit_ = true;
      throw Interrupted{};
    }
    poll();
  }

  /// Aim at >= 10 coarse frames/s while the view changes: a coarse frame slower than 0.1 s halves
  /// the next one's size per side (down to 1/16), one faster than 0.025 s doubles it (up to
  /// 1/--coarse).
  void adaptCoarse(double seconds) {
    if (seconds > 0.1 && coarse_ < 16)
      coarse_ *= 2;
    else if (seconds < 0.025 && coarse_ / 2 >= args_.coarse)
      coarse_ /= 2;
  }

  void updateTitle(Clock::time_point now) {
    char light[96] = "";
    if (mover_ && mover_->busy()) {
      const LightMover::Stage stage = mover_->stage();
      if (stage == LightMover::Stage::Preparing)
        std::snprintf(light, sizeof light, " | unlit, preparing the lit view...");
      else
        std::snprintf(light, sizeof light, " | %s%s (%.0f%%)...", first_light_ ? "unlit, " : "",
                      stage == LightMover::Stage::Voxelising ? "voxelising for the light"
                                                             : "simulating the light",
                      100.0 * mover_->fraction());
    }
    double fps = 0;
    if (frame_times_.size() > 1)
      fps = double(frame_times_.size() - 1) /
            std::max(1e-6, std::chrono::duration<double>(now - frame_times_.front()).count());
    char buf[720];
    std::snprintf(
        buf, sizeof buf,
        "eikon view: %s | %.1f frames/s | %dx%d, %d/%d samples, %s | %s | modes %s%s%s%s%s",
        session_.scene()->file.filename().c_str(), fps, shown_.width, shown_.height, shown_spp_,
        args_.spp,
        shown_wavelengths_ > 0 ? (std::to_string(shown_wavelengths_) + " wavelengths").c_str()
                               : "RGB",
        integratorName(integrator_), modesName(modes_, session_.scene()->fastSlowModes()),
        compiling_ ? " | compiling..."
        : refined_ ? " | refined"
                   : "",
        *light ? light : light_note_.c_str(), figures_.empty() ? "" : " | light ",
        figures_.c_str());
    glfwSetWindowTitle(window_, buf);
  }

  /// Handle pending events; a change (or closing) ends the render in progress.
  void poll() {
    glfwPollEvents();
    handleRequests();
    if (finish_stage_ && !quit_ && !glfwWindowShouldClose(window_)) return;
    if (changed_ || resized_ || quit_ || glfwWindowShouldClose(window_)) throw Interrupted{};
  }

  void handleRequests() {
    if (save_requested_) {
      save_requested_ = false;
      save();
    }
    if (!mover_) return;
    if (mover_->finished(moved_)) {
      for (const std::string& w : moved_.warnings)
        std::fprintf(stderr, "eikon: warning: %s\n", w.c_str());
      if (moved_.error.empty()) {
        light_ready_ = changed_ = true;  // swapped in between renders (applyLight)
      } else if (first_light_) {
        throw CliError("the scene's light was not simulated: " + moved_.error);
      } else {
        std::fprintf(stderr, "eikon: warning: the moved light was not simulated: %s\n",
                     moved_.error.c_str());
        light_rendered_ = light_frames_ = 0;
      }
    }
    // The first light starts once the first frame is shown: the cores go to that frame first
    // (started at once, the mover's voxelising delayed the lit view as much; docs/viewer.md).
    if (light_moved_ && !mover_->busy() && !(first_light_ && frames_ == 0)) {
      const bool first = first_light_ && !first_light_started_;
      LitView view;
      if (first) view = litView();
      if (mover_->start(wanted_light_, first ? &view : nullptr)) {
        first_light_started_ = first_light_started_ || first;
        light_moved_ = false;
        updateTitle(Clock::now());
      }
    }
  }

  /// The first light's renderer is made on the viewer's context and scene, for the render the view
  /// restarts with (its first stage, with the keys' choices now).
  LitView litView() {
    LitView v;
    v.ctx = &session_.context();
    v.scene = session_.scene().get();
    v.expected = settingsOf(stages().front());
    const VolumeSet& volume = session_.prepareGpuRender();  // made before the first frame
    if (volume.whole()) v.whole = &volume;
    return v;
  }

  /// The view is unlit until the first light, simulated in the background, arrives.
  bool firstLightPending() const { return first_light_ && lightPending(); }

  bool lightPending() const {
    return mover_ && (light_moved_ || light_ready_ || mover_->busy() || mover_->done());
  }

  /// The light simulated in the background into the view: the first light's lit renderer
  /// replaces the unlit one; a moved light's volumes are written into the renderer's images in
  /// place (no renderer or pipeline made again). The view then restarts.
  void applyLight() {
    light_ready_ = false;
    session_.scene()->lights.front() = moved_.light;
    timings::mark(first_light_ ? "first light swapped in" : "moved light swapped in");
    if (moved_.renderer)
      moved_.renderer.adoptInto(session_, std::move(moved_.fluence), std::move(moved_.flux));
    else
      session_.setLightVolumes(std::move(moved_.fluence), std::move(moved_.flux));
    // The first light: how long the mover's voxelising took, and the frames shown unlit before
    // it ended (the first frame never waits for the whole volume).
    char meanwhile[200];
    if (first_light_)
      std::snprintf(meanwhile, sizeof meanwhile,
                    ", the volume %s there in %.2f s; %lld frames rendered unlit, %lld of them "
                    "before the volume was voxelised,",
                    moved_.volume_copied ? "copied" : "voxelised", moved_.voxelise_seconds,
                    unlit_frames_, unlit_unvoxelised_);
    else
      std::snprintf(meanwhile, sizeof meanwhile,
                    "; meanwhile %lld frames rendered with the former light", light_rendered_);
    std::printf(
        "eikon view: light 0 simulated %s the background (%s, %.2f s%s and %lld presented "
        "again): position %s, direction %s\n",
        first_light_ ? "in" : "again in", moved_.cached ? "from the light cache" : "simulated",
        moved_.seconds, meanwhile, light_frames_, vectorJson(moved_.light.position).c_str(),
        vectorJson(moved_.light.direction).c_str());
    std::fflush(stdout);
    light_rendered_ = light_frames_ = 0;
    char note[96];
    std::snprintf(note, sizeof note, " | light %s (%s, %.2f s)",
                  first_light_ ? "simulated" : "moved",
                  moved_.cached ? "from the light cache" : "simulated", moved_.seconds);
    light_note_ = note;
    first_light_ = false;
  }

  void resize() {
    resized_ = false;
    int w = 0, h = 0;
    glfwGetFramebufferSize(window_, &w, &h);
    while ((w == 0 || h == 0) && !glfwWindowShouldClose(window_)) {  // minimised
      glfwWaitEvents();
      glfwGetFramebufferSize(window_, &w, &h);
    }
    chain_.resize(uint32_t(w), uint32_t(h));
  }

  // Positions come from the motion events themselves, never from glfwGetCursorPos: events
  // queued while a render ran (a whole drag, from a script) are handled later, when the pointer
  // has moved on, and each must see the position it was sent with.
  /// --wait-for-input: a scripted input has ended (a button released, a key pressed).
  bool inputDone() const { return !args_.wait_for_input || input_seen_; }

  void onButton(int button, int action, int mods) {
    if (action == GLFW_RELEASE) input_seen_ = true;
    if (action == GLFW_PRESS) {
      drag_button_ = button;
      drag_mods_ = mods;
    } else if (button == drag_button_) {
      drag_button_ = -1;
    }
  }

  void onCursor(double x, double y) {
    const double px = last_x_, py = last_y_;
    last_x_ = x;
    last_y_ = y;
    if (drag_button_ < 0 || !have_cursor_) {
      have_cursor_ = true;
      return;
    }
    int w = 0, h = 0;
    glfwGetWindowSize(window_, &w, &h);
    const double dx = (x - px) / std::max(h, 1), dy = (y - py) / std::max(h, 1);
    if (dx == 0 && dy == 0) return;
    Camera& cam = session_.scene()->camera;
    if (mover_ && drag_button_ == GLFW_MOUSE_BUTTON_LEFT && (drag_mods_ & GLFW_MOD_CONTROL)) {
      moveLight(wanted_light_, cam, dx, -dy);  // the view stays until the new light is simulated
      light_moved_ = true;
      return;
    }
    const bool pan = drag_button_ != GLFW_MOUSE_BUTTON_LEFT || (drag_mods_ & GLFW_MOD_SHIFT);
    if (pan)
      panCamera(cam, -dx, dy);
    else
      orbitCamera(cam, -3.0 * dx, 3.0 * dy);  // a window height of drag: about 170°
    changed_ = true;
  }

  void onScroll(double dy) {
    zoomCamera(session_.scene()->camera, std::pow(0.9, dy));
    changed_ = true;
  }

  void onKey(int key) {
    input_seen_ = true;
    switch (key) {
      case GLFW_KEY_R:  // RGB ↔ spectral
        spectral_ = !spectral_;
        changed_ = true;
        break;
      case GLFW_KEY_I:  // euler → midpoint → rk4 → euler
        integrator_ = Integrator((int(integrator_) + 1) % 3);
        changed_ = true;
        break;
      case GLFW_KEY_M:  // both → o → e → both (crystal scenes; no new pipeline)
        modes_ = Modes((int(modes_) + 1) % 3);
        changed_ = true;
        break;
      case GLFW_KEY_L:  // the scene's lighting → dome → spot → aset → idealscope → lightbox
        lighting_.next();
        changed_ = true;
        break;
      case GLFW_KEY_S:
        save_requested_ = true;
        break;
      case GLFW_KEY_Q:
      case GLFW_KEY_ESCAPE:
        glfwSetWindowShouldClose(window_, GLFW_TRUE);
        break;
      default:
        break;
    }
  }

  /// The view as a render's pair (EXR + PNG, `eikon render`'s formats) named after the scene in
  /// the save folder (apps/view_save.h), and the camera as the scene file spells it. A save that
  /// fails says why on stderr and leaves the window open.
  void save() {
    if (shown_.rgb.empty()) return;
    std::filesystem::path exr, png;
    try {
      std::tie(exr, png) = reserveViewSave(
          args_.save_dir.empty() ? defaultViewSaveDir() : std::filesystem::path(args_.save_dir),
          session_.scene()->file.stem().string());
      writeFilesTogether(
          {{png, pngPreviewContent(shown_.width, shown_.height, shown_.rgb, args_.exposure)},
           {exr, exrRgbContent(shown_.width, shown_.height, shown_.rgb)}});
    } catch (const std::exception& e) {
      std::error_code ec;
      if (!exr.empty() && std::filesystem::file_size(exr, ec) == 0)
        std::filesystem::remove(exr, ec);
      std::fprintf(stderr, "eikon view: cannot save the view: %s\n", printable(e.what()).c_str());
      return;
    }
    std::printf("eikon view: saved %s and %s (%dx%d, %d samples, %s)\n\"camera\": %s\n",
                exr.c_str(), png.c_str(), shown_.width, shown_.height, shown_spp_,
                shown_wavelengths_ > 0
                    ? (std::to_string(shown_wavelengths_) + " wavelengths").c_str()
                    : "RGB",
                cameraJson(session_.scene()->camera, shown_.width, shown_.height).c_str());
    std::fflush(stdout);
  }

  const ViewArgs& args_;
  Session& session_;
  GLFWwindow* window_;
  ViewPresenter& chain_;
  RenderSettings base_;
  LightMover* mover_;
  ViewerLighting lighting_;
  std::string figures_;  ///< the title's lighting and its live figures (ViewerLighting::figures)
  Light wanted_light_;
  MovedLight moved_;  ///< the last light the mover finished, until applyLight swaps it in
  bool light_moved_ = false, light_ready_ = false;
  bool first_light_ = false;          ///< the mover simulates the first light (awaitFirstLight)
  bool first_light_started_ = false;  ///< the mover was started on it (after the first frame)
  long long unlit_frames_ = 0;        ///< frames shown before the first light arrived
  long long unlit_unvoxelised_ = 0;   ///< of which before any whole volume was made
  long long light_rendered_ = 0;      ///< frames rendered while the mover simulated
  long long light_frames_ = 0;        ///< frames presented again meanwhile (the view was refined)
  std::string light_note_;            ///< the title's word on the last moved light
  Clock::time_point last_again_;      ///< presentAgain's last frame
  Integrator integrator_;
  Modes modes_, stage_modes_ = modes_, shown_modes_ = modes_;
  bool spectral_ = false;
  bool compiling_ = false;        ///< waiting for a pipeline (waitForPipeline; the title says so)
  bool prefetched_ = false;       ///< the pipelines of the keys were asked for (prefetchKeys)
  long long compile_frames_ = 0;  ///< frames presented while a pipeline compiled
  double longest_compile_ = 0;    ///< the longest such wait, seconds
  int full_wavelengths_ = 0;
  bool changed_ = false, resized_ = false, quit_ = false, save_requested_ = false;
  bool input_seen_ = false;    // --wait-for-input
  bool refined_ = false;       ///< the view is fully refined (the title says so)
  bool finish_stage_ = false;  ///< poll() does not interrupt the stage (the coarse frame)
  int coarse_ = args_.coarse;  ///< the coarse frame's 1/size per side (adaptCoarse)
  int drag_button_ = -1, drag_mods_ = 0;
  double last_x_ = 0, last_y_ = 0;
  bool have_cursor_ = false;
  long long frames_ = 0;
  int frames_since_change_ = 0;
  int few_frames_ = 0;  ///< full-size frames of the last view at fewer wavelengths than all
  Clock::time_point change_time_ = Clock::now();
  std::deque<Clock::time_point> frame_times_;
  std::vector<double> coarse_seconds_;
  RenderImage shown_;
  int shown_spp_ = 0, shown_wavelengths_ = 0, refined_spp_ = 0;
  double refined_seconds_ = 0, first_frame_seconds_ = 0, full_quality_seconds_ = 0;
  const Clock::time_point opened_ = Clock::now();
};

/// GLFW's errors, kept for the one line that reports a failure.
std::string& glfwLastError() {
  static std::string last;
  return last;
}

/// The window system, or one line saying why there is none.
struct Glfw {
  Glfw() {
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display)
      throw CliError(
          "no display: DISPLAY is not set, so 'eikon view' cannot open a window; render without "
          "one with 'eikon render SCENE.json -o OUT.exr'");
    glfwSetErrorCallback([](int, const char* what) { glfwLastError() = what ? what : ""; });
    if (!glfwInit())
      throw CliError("cannot open the display '" + std::string(display) + "' (" + glfwLastError() +
                     "); render without one with 'eikon render SCENE.json -o "
                     "OUT.exr'");
    if (!glfwVulkanSupported()) {
      glfwTerminate();
      throw CliError("the Vulkan loader cannot present to the display '" + std::string(display) +
                     "'; render without a window with 'eikon render SCENE.json -o OUT.exr'");
    }
  }
  ~Glfw() { glfwTerminate(); }
};

struct Window {
  GLFWwindow* handle = nullptr;
  Window(int width, int height, const std::string& title) {
    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
    handle = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
    if (!handle) throw CliError("cannot open a window (" + glfwLastError() + ")");
  }
  ~Window() { glfwDestroyWindow(handle); }
};

void runView(const ViewArgs& given, const CLI::App& sub) {
  ViewArgs a = given;  // with the scene's "render" exposure where --exposure is not given
  ViewRequest view;
  if (sub.count("--width")) view.width = a.width;
  if (sub.count("--height")) view.height = a.height;
  view.spp = a.spp;
  if (sub.count("--wavelengths")) view.wavelengths = a.wavelengths;
  view.modes = parseModes(a.modes);
  checkViewRequest(view);
  if (a.coarse < 1 || a.coarse > 16)
    throw CliError("--coarse must be in [1, 16], got " + std::to_string(a.coarse));
  checkExposure(a.exposure);
  if (a.exit_after_frames < 0)
    throw CliError("--exit-after-frames must be >= 0, got " + std::to_string(a.exit_after_frames));
  const Integrator integrator = parseIntegrator(a.integrator);
  if (sub.count("--screenshot")) {  // given: an empty name is refused, not taken as no screenshot
    if (a.screenshot.empty()) throw CliError("--screenshot must name a .png file, got ''");
    if (std::filesystem::path(a.screenshot).extension() != ".png")
      throw CliError("--screenshot must end in .png: " + a.screenshot);
    checkWritable(a.screenshot);
  }
  if (!a.save_dir.empty()) checkWritable(std::filesystem::path(a.save_dir) / "x-view-1.exr");
  auto scene = std::make_shared<Scene>(loadScene(a.scene));
  for (const std::string& w : scene->warnings)
    std::fprintf(stderr, "eikon: warning: %s\n", w.c_str());
  if (!sub.count("--exposure") && scene->render.exposure) a.exposure = *scene->render.exposure;
  RenderSettings base = renderSettings(*scene, view);
  if (isPolarisedRender(*scene, base)) checkPolariserSheetsOnGpu(*scene);  // before any window
  base.march.integrator = integrator;
  const int width = view.width.value_or(scene->camera.width),
            height = view.height.value_or(scene->camera.height);

  Glfw glfw;
  uint32_t n_ext = 0;
  const char** ext = glfwGetRequiredInstanceExtensions(&n_ext);
  std::vector<std::string> surface_extensions(ext, ext + n_ext);
  Window window(width, height, "eikon view: " + scene->file.filename().string() + " (preparing)");
  Session session(scene, presentingContext(surface_extensions));
  session.setProgress(
      {[&](const char*, double) { glfwPollEvents(); }, [&](const char*) { glfwPollEvents(); }});
  session.context();  // the device, then the window's surface and swapchain on it
  int fw = 0, fh = 0;
  glfwGetFramebufferSize(window.handle, &fw, &fh);
  ViewPresenter chain(
      session,
      [&](VkInstance instance) {
        VkSurfaceKHR surface = VK_NULL_HANDLE;
        if (glfwCreateWindowSurface(instance, window.handle, nullptr, &surface) != VK_SUCCESS)
          throw CliError("cannot create a Vulkan surface for the window (" + glfwLastError() + ")");
        return surface;
      },
      uint32_t(fw), uint32_t(fh));
  std::unique_ptr<LightMover> mover;
  // As eikon render: the light volumes show only where a material has an albedo.
  if (!scene->lights.empty() && !a.no_light && !scene->anyScattering())
    std::fputs(kLightsNotSimulatedNote, stderr);
  if (!scene->lights.empty() && !a.no_light && scene->anyScattering())
    mover = std::make_unique<LightMover>(*scene, session.lightOnCpuTwin(LightRequest{}, false),
                                         defaultLightCacheFolder());
  // Input is handled from here on: events that arrive while the scene is voxelised (polled by
  // the progress callbacks) already move the camera of the first frame.
  Viewer viewer(a, session, window.handle, chain, base, mover.get());
  // A sharp scene is shown first from its interfaces alone (Session::prepareGpuRender;
  // docs/performance.md "Start-up"), unlit: with light, the mover voxelises the whole volume,
  // simulates the light (or finds it in the light cache: its key covers the whole volume) and
  // makes the lit renderer in the background, once the first frame is shown (docs/viewer.md "The
  // first light").
  session.prepareGpuRender();
  if (mover) viewer.awaitFirstLight();
  viewer.run();
  if (mover && mover->busy()) {  // closed before the light arrived: not waited for
    const LightMover::Stage stage = mover->stage();
    const double percent = 100.0 * mover->fraction();
    mover->stop();
    if (stage == LightMover::Stage::Preparing)
      std::printf(
          "eikon view: the window closed while the lit view was made (its light is in the "
          "light cache)\n");
    else
      std::printf(
          "eikon view: the window closed while the light was %s (%.0f%%): stopped there, "
          "nothing cached\n",
          stage == LightMover::Stage::Voxelising ? "voxelised" : "simulated", percent);
  }
  std::printf("%s\n", viewer.summary().c_str());
  if (!viewer.figures().empty()) std::printf("eikon view: lighting %s\n", viewer.figures().c_str());
  const RenderImage& img = viewer.shown();
  if (!a.screenshot.empty() && !img.rgb.empty()) {
    writeFilesTogether(
        {{a.screenshot, pngPreviewContent(img.width, img.height, img.rgb, a.exposure)}});
    std::printf("eikon view: screenshot %s (%dx%d, %d samples, %s, modes %s)\n\"camera\": %s\n",
                a.screenshot.c_str(), img.width, img.height, viewer.shownSamples(),
                viewer.shownWavelengths() > 0
                    ? (std::to_string(viewer.shownWavelengths()) + " wavelengths").c_str()
                    : "RGB",
                modesName(viewer.shownModes(), scene->fastSlowModes()),
                cameraJson(scene->camera, img.width, img.height).c_str());
  }
}

}  // namespace

void addViewCommand(CLI::App& app) {
  auto args = std::make_shared<ViewArgs>();
  auto* sub = app.add_subcommand(
      "view", "Open a window on a scene: progressive GPU rendering, orbit/zoom/pan with the mouse");
  addViewOptions(sub, *args);
  sub->callback([args, sub] { runView(*args, *sub); });
}

}  // namespace eikon::cli
