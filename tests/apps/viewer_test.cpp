// `eikon view` as a user runs it: the real binary in a virtual X server (Xvfb, started
// here on a display number it picks itself, -displayfd), a mouse drag sent with xdotool, the
// screenshot it writes on exit compared with `eikon render` of the camera it prints. The
// tolerance comes from the renderer's own sample noise, measured from two renders with different
// sample counts, never from the viewer's output. Skipped only when the Xvfb binary is missing (CI
// installs it: scripts/install_deps.sh).
#include <gtest/gtest.h>
#include <png.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "tests/apps/cli_support.h"

namespace {

namespace fs = std::filesystem;
using eikon::test::Outcome;
using eikon::test::quote;

/// The first executable `name` on PATH (or the usual Debian folders); "" if none.
std::string findProgram(const std::string& name) {
  std::string path = std::getenv("PATH") ? std::getenv("PATH") : "";
  path += ":/usr/bin:/usr/local/bin";
  std::istringstream dirs(path);
  for (std::string d; std::getline(dirs, d, ':');)
    if (!d.empty() && ::access((fs::path(d) / name).c_str(), X_OK) == 0)
      return (fs::path(d) / name).string();
  return "";
}

struct Png {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;
};

Png readPng(const fs::path& p) {
  png_image img{};
  img.version = PNG_IMAGE_VERSION;
  Png out;
  if (!png_image_begin_read_from_file(&img, p.c_str())) return out;
  img.format = PNG_FORMAT_RGB;
  out.rgb.resize(PNG_IMAGE_SIZE(img));
  if (!png_image_finish_read(&img, nullptr, out.rgb.data(), 0, nullptr)) {
    png_image_free(&img);
    return {};
  }
  out.width = int(img.width);
  out.height = int(img.height);
  return out;
}

/// Root mean square of the channel differences, in units of full scale (255).
double rmsDifference(const Png& a, const Png& b) {
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  if (a.rgb.size() != b.rgb.size() || a.rgb.empty()) return 1e9;
  double s = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i) {
    const double d = (double(a.rgb[i]) - double(b.rgb[i])) / 255.0;
    s += d * d;
  }
  return std::sqrt(s / double(a.rgb.size()));
}

/// A virtual X server on a free display (Xvfb -displayfd picks it), killed by the destructor.
class Xvfb {
 public:
  explicit Xvfb(const std::string& binary) {
    int fds[2];
    if (::pipe(fds) != 0) return;
    pid_ = ::fork();
    if (pid_ == 0) {
      ::close(fds[0]);
      const std::string fd = std::to_string(fds[1]);
      std::freopen("/dev/null", "w", stderr);
      ::execl(binary.c_str(), "Xvfb", "-displayfd", fd.c_str(), "-screen", "0", "640x480x24",
              "-nolisten", "tcp", static_cast<char*>(nullptr));
      ::_exit(127);
    }
    ::close(fds[1]);
    std::string number;
    char c = 0;
    while (::read(fds[0], &c, 1) == 1 && c != '\n') number += c;  // written once it is ready
    ::close(fds[0]);
    if (!number.empty()) display_ = ":" + number;
  }
  ~Xvfb() {
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      int st = 0;
      ::waitpid(pid_, &st, 0);
    }
  }
  const std::string& display() const { return display_; }

 private:
  pid_t pid_ = -1;
  std::string display_;
};

class ViewerTest : public ::testing::Test {
 protected:
  void SetUp() override { fs::create_directories(dir_ / "render_io"); }
  std::string env(const std::string& display) const {
    return "EIKON_VALIDATION=1 DISPLAY=" + quote(display) + " " + extra_env_;
  }
  /// `eikon render` of `scene` at the viewer's size, `spp` samples: its PNG.
  Png render(const fs::path& scene, int spp, const std::string& name) const {
    const fs::path out = dir_ / (name + ".exr");
    const Outcome o =
        eikon::test::runEikon("render " + quote(scene.string()) + " -o " + quote(out.string()) +
                                  " --width 160 --height 120 -q --spp " + std::to_string(spp),
                              dir_ / "render_io", "EIKON_VALIDATION=1");
    EXPECT_EQ(o.code, 0) << o.err;
    EXPECT_EQ(o.err.find("validation"), std::string::npos) << o.err;
    return readPng(fs::path(out).replace_extension(".png"));
  }
  /// The viewer on `scene` with `args`, in `server`'s display, sent the xdotool `actions` on its
  /// window once the window shows; waits for it to exit. Its exit status, stdout and stderr.
  struct ViewerRun {
    int status = -1;
    std::string out, err;
  };
  ViewerRun viewWhile(const Xvfb& server, const std::string& xdotool, const std::string& scene,
                      const std::string& args, const std::string& actions) const {
    const std::string cmd = env(server.display()) + " " + quote(EIKON_BINARY) + " view " +
                            quote(scene) + " " + args + " >" + quote((dir_ / "view.out").string()) +
                            " 2>" + quote((dir_ / "view.err").string()) + " </dev/null";
    const pid_t viewer = ::fork();
    if (viewer == 0) {
      ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
    ViewerRun r;
    if (actions.empty()) {
      // Nothing to send: a small view may converge and exit before a window search would see it.
      EXPECT_EQ(::waitpid(viewer, &r.status, 0), viewer);
    } else {
      const std::string send = "exec env DISPLAY=" + quote(server.display()) + " timeout 300 " +
                               quote(xdotool) + " search --sync --onlyvisible --name 'eikon view'" +
                               actions + " >/dev/null 2>&1";
      const pid_t sender = ::fork();
      if (sender == 0) {
        ::execl("/bin/sh", "sh", "-c", send.c_str(), static_cast<char*>(nullptr));
        ::_exit(127);
      }
      // Whichever ends first: a viewer that exits before its window was found fails the test at
      // once, with its stderr, rather than leaving the search to wait out its timeout.
      int sent = -1;
      bool viewer_done = false;
      for (;;) {
        if (::waitpid(sender, &sent, WNOHANG) == sender) break;
        if (::waitpid(viewer, &r.status, WNOHANG) == viewer) {
          viewer_done = true;
          ::kill(sender, SIGTERM);
          ::waitpid(sender, &sent, 0);
          break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
      EXPECT_FALSE(viewer_done) << "the viewer exited before " << send << " was done:\n"
                                << eikon::test::slurp(dir_ / "view.err");
      EXPECT_TRUE(WIFEXITED(sent) && WEXITSTATUS(sent) == 0) << send;
      if (!viewer_done) {
        EXPECT_EQ(::waitpid(viewer, &r.status, 0), viewer);
      }
    }
    r.out = eikon::test::slurp(dir_ / "view.out");
    r.err = eikon::test::slurp(dir_ / "view.err");
    return r;
  }
  std::string extra_env_;  ///< more VAR=value for the viewer (EIKON_CACHE_DIR)
  eikon::test::TempDir tmp_{"eikon_viewer_test"};
  const fs::path dir_ = tmp_.path();
};

const std::string kGlassSphere = std::string(EIKON_SOURCE_DIR) + "/scenes/glass_sphere.json";

TEST_F(ViewerTest, DisplayUnsetIsOneLinePointingAtRender) {
  const Outcome o = eikon::test::runEikon("view " + quote(kGlassSphere), dir_ / "io",
                                          "env -u DISPLAY EIKON_VALIDATION=1");
  EXPECT_NE(o.code, 0);
  EXPECT_EQ(o.err.find("eikon: error: "), 0u) << o.err;
  EXPECT_NE(o.err.find("DISPLAY is not set"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("eikon render"), std::string::npos) << o.err;
  EXPECT_EQ(std::count(o.err.begin(), o.err.end(), '\n'), 1) << o.err;
  EXPECT_TRUE(o.out.empty()) << o.out;
}

TEST_F(ViewerTest, UnreachableDisplayIsOneLinePointingAtRender) {
  // A display number no X server listens on (TCP is not tried for a local ":N").
  const Outcome o = eikon::test::runEikon("view " + quote(kGlassSphere), dir_ / "io",
                                          "EIKON_VALIDATION=1 DISPLAY=:65531");
  EXPECT_NE(o.code, 0);
  EXPECT_EQ(o.err.find("eikon: error: cannot open the display ':65531'"), 0u) << o.err;
  EXPECT_NE(o.err.find("eikon render"), std::string::npos) << o.err;
  EXPECT_EQ(std::count(o.err.begin(), o.err.end(), '\n'), 1) << o.err;
}

TEST_F(ViewerTest, BadOptionsAreOneLineBeforeAnyWindow) {
  for (const std::string& bad :
       {std::string("--screenshot x.jpg"), std::string("--coarse 0"), std::string("--spp 0"),
        std::string("--exit-after-frames -1"), std::string("--modes oe")}) {
    const Outcome o = eikon::test::runEikon("view " + quote(kGlassSphere) + " " + bad, dir_ / "io",
                                            "env -u DISPLAY");
    EXPECT_NE(o.code, 0) << bad;
    EXPECT_EQ(std::count(o.err.begin(), o.err.end(), '\n'), 1) << bad << ": " << o.err;
    EXPECT_EQ(o.err.find("DISPLAY"), std::string::npos) << bad << ": " << o.err;
  }
}

// --screenshot "" passed as no screenshot at all (a name ending in '/' is refused), and
// --exposure 1e300 was refused with the value printed as a 301-digit decimal.
TEST_F(ViewerTest, EmptyScreenshotAndHugeExposureAreOneShortLine) {
  const std::pair<std::string, std::string> cases[] = {
      {"--screenshot ''", "eikon: error: --screenshot must name a .png file, got ''\n"},
      {"--exposure 1e300", "eikon: error: --exposure must be in [-64, 64] stops, got 1e+300\n"},
      {"--exposure -64.5", "eikon: error: --exposure must be in [-64, 64] stops, got -64.5\n"}};
  for (const auto& [bad, message] : cases) {
    const Outcome o = eikon::test::runEikon("view " + quote(kGlassSphere) + " " + bad, dir_ / "io",
                                            "env -u DISPLAY");
    EXPECT_NE(o.code, 0) << bad;
    EXPECT_EQ(o.err.rfind(message, 0), 0u) << bad << ": " << o.err;
    EXPECT_EQ(std::count(o.err.begin(), o.err.end(), '\n'), 1) << bad << ": " << o.err;
    EXPECT_TRUE(o.out.empty()) << o.out;
  }
}

/// The drag changes the view, and the refined view is `eikon render` of the camera printed.
TEST_F(ViewerTest, DragOrbitsAndRefinedViewMatchesRender) {
  const std::string xvfb = findProgram("Xvfb"), xdotool = findProgram("xdotool");
  if (xvfb.empty()) GTEST_SKIP() << "Xvfb is not installed (Debian package xvfb)";
  ASSERT_FALSE(xdotool.empty()) << "xdotool is not installed (Debian package xdotool)";
  Xvfb server(xvfb);
  ASSERT_FALSE(server.display().empty()) << "Xvfb did not start";
  const fs::path shot = dir_ / "shot.png";
  // The viewer exits once its last view is refined to 4 samples, after the drag
  // (--wait-for-input: a sphere's view refines faster than xdotool finds the window). Once its
  // window shows, a drag across it with the left button: an orbit about look_at.
  const ViewerRun run =
      viewWhile(server, xdotool, kGlassSphere,
                "--width 160 --height 120 --spp 4 --exit-after-frames 100 --wait-for-input "
                "--screenshot " +
                    quote(shot.string()),
                " mousemove --window %1 60 60 sleep 0.1 mousedown 1 sleep 0.1"
                " mousemove --window %1 75 64 sleep 0.1 mousemove --window %1 90 68 sleep 0.1"
                " mousemove --window %1 105 72 sleep 0.1 mouseup 1");
  const std::string &out = run.out, &err = run.err;
  ASSERT_TRUE(WIFEXITED(run.status) && WEXITSTATUS(run.status) == 0) << err;
  EXPECT_EQ(err.find("validation"), std::string::npos) << err;
  EXPECT_NE(out.find("4 samples"), std::string::npos) << out;

  // The camera it printed, in a copy of the scene.
  const size_t at = out.find("\"camera\": ");
  ASSERT_NE(at, std::string::npos) << out;
  const nlohmann::json camera =
      nlohmann::json::parse(out.substr(at + 10, out.find('\n', at) - at - 10));
  nlohmann::json scene = nlohmann::json::parse(std::ifstream(kGlassSphere));
  const nlohmann::json original = scene["camera"];
  EXPECT_GT(std::abs(camera["position"][0].get<double>() - original["position"][0].get<double>()),
            1.0)
      << "the drag did not orbit the camera: " << camera.dump();
  scene["camera"] = camera;
  std::ofstream(dir_ / "moved.json") << scene.dump();

  const Png viewed = readPng(shot), moved4 = render(dir_ / "moved.json", 4, "moved4"),
            moved8 = render(dir_ / "moved.json", 8, "moved8"),
            original4 = render(kGlassSphere, 4, "original4");
  ASSERT_EQ(viewed.width, 160);
  ASSERT_EQ(viewed.height, 120);
  // Noise of a 4-sample image: R4 − R8 = (A − B)/2 for the two 4-sample halves A, B of R8, so
  // two independent 4-sample images differ by 2·rms(R4 − R8); 3 of that plus the 8-bit rounding
  // of both images (at most 1/255) bounds an honest difference.
  const double noise = 2.0 * rmsDifference(moved4, moved8), tolerance = 3.0 * noise + 1.0 / 255;
  const double same = rmsDifference(viewed, moved4), before = rmsDifference(viewed, original4);
  std::printf(
      "rms: viewer vs render of its camera %.5f, vs the scene's camera %.5f, tolerance "
      "%.5f (noise %.5f)\n",
      same, before, tolerance, noise);
  EXPECT_LE(same, tolerance);
  EXPECT_GT(before, tolerance) << "the screenshot did not change with the drag";
}

/// Keys: M selects the o-mode, R switches to spectral. With --no-prefetch
/// the spectral pipeline is compiled only after the key, on the renderer's thread, while the
/// window keeps presenting the last image under a "compiling..." title and handling events: the
/// viewer reports the frames it presented meanwhile, which a viewer that froze for the compile
/// (the render call blocking the event loop) would not have presented. Q then closes it.
TEST_F(ViewerTest, KeysSwitchModeAndSpectralWhileTheWindowKeepsResponding) {
  const std::string xvfb = findProgram("Xvfb"), xdotool = findProgram("xdotool");
  if (xvfb.empty()) GTEST_SKIP() << "Xvfb is not installed (Debian package xvfb)";
  ASSERT_FALSE(xdotool.empty()) << "xdotool is not installed (Debian package xdotool)";
  Xvfb server(xvfb);
  ASSERT_FALSE(server.display().empty()) << "Xvfb did not start";
  const fs::path shot = dir_ / "keys.png";
  // Once a first frame is up (the title then counts samples), focus, M and R; once the spectral
  // o-mode view is refined, Q.
  const ViewerRun run = viewWhile(
      server, xdotool, kGlassSphere,
      "--width 80 --height 60 --spp 2 --no-prefetch --screenshot " + quote(shot.string()),
      " search --sync --onlyvisible --name 'samples' windowfocus %1 sleep 0.2 key m sleep 0.1"
      " key r search --sync --onlyvisible --name 'wavelengths.*modes o.*refined' key q");
  const std::string &out = run.out, &err = run.err;
  ASSERT_TRUE(WIFEXITED(run.status) && WEXITSTATUS(run.status) == 0) << err;
  EXPECT_EQ(err.find("validation"), std::string::npos) << err;
  EXPECT_NE(out.find("wavelengths, modes o)"), std::string::npos) << out;
  const std::string said = " frames presented while a pipeline compiled";
  const size_t at = out.find(said);
  ASSERT_NE(at, std::string::npos) << out;
  const size_t start = out.rfind(' ', at - 1) + 1;
  const long long frames = std::stoll(out.substr(start, at - start));
  EXPECT_GT(frames, 0) << out;
}

// A glass ball over a diffuse floor lit by a point light, small enough to simulate in seconds.
constexpr const char* kLitScene = R"({
  "camera": {"position": [0, 12, -30], "look_at": [0, -2, 0], "up": [0, 1, 0], "fov_deg": 40, "width": 80, "height": 60},
  "environment": {"type": "constant", "radiance": [0.02, 0.02, 0.02]},
  "volume": {"bounds_min": [-8, -5, -8], "bounds_max": [8, 9, 8], "resolution": 32},
  "materials": {"glass": {"n": 1.5}, "floor": {"n": 1.0, "opacity": 1, "albedo": 0.8}},
  "objects": [{"shape": "box", "center": [0, -4, 0], "size": [15, 1, 15], "material": "floor"},
              {"shape": "sphere", "center": [0, 1, 0], "radius": 3, "material": "glass"}],
  "lights": [{"type": "point", "position": [0, 7, 0], "intensity": 40}]
})";

/// kLitScene voxelised at `resolution` voxels a side, written to DIR/lit.json: its path.
fs::path writeLitScene(const fs::path& dir, int resolution) {
  nlohmann::json scene = nlohmann::json::parse(kLitScene);
  scene["volume"]["resolution"] = resolution;
  std::ofstream(dir / "lit.json") << scene.dump();
  return dir / "lit.json";
}

/// The brightness (mean of the 8-bit channels over a 5×5 patch) of the screenshot where `point`
/// shows through the camera of kLitScene at 80×60 (a vertical field of view; the image's right is
/// the camera's forward × up).
double patchAt(const Png& img, const glm::dvec3& point) {
  const glm::dvec3 eye(0, 12, -30), look(0, -2, 0);
  const glm::dvec3 fwd = glm::normalize(look - eye),
                   right = glm::normalize(glm::cross(fwd, {0, 1, 0}));
  const glm::dvec3 up = glm::cross(right, fwd), d = point - eye;
  const double t = std::tan(0.5 * 40.0 * std::numbers::pi / 180.0), z = glm::dot(d, fwd);
  const double u = glm::dot(d, right) / (z * t * (80.0 / 60.0)), v = glm::dot(d, up) / (z * t);
  const int px = int(std::lround(0.5 * (u + 1.0) * 80.0 - 0.5)),
            py = int(std::lround(0.5 * (1.0 - v) * 60.0 - 0.5));
  EXPECT_TRUE(px >= 2 && px < 78 && py >= 2 && py < 58) << px << ", " << py;
  double sum = 0;
  for (int y = py - 2; y <= py + 2; ++y)
    for (int x = px - 2; x <= px + 2; ++x)
      for (int c = 0; c < 3; ++c) sum += img.rgb[size_t(3 * (y * img.width + x) + c)];
  return sum / 75.0;
}

/// The numbers of the viewer's last "light 0 simulated again in the background (HOW, T s;
/// meanwhile R frames rendered with the former light and P presented again): position [...]".
struct LightReport {
  bool found = false, cached = false;
  long long rendered = 0, presented = 0;
  nlohmann::json position;
};

LightReport lastLightReport(const std::string& out) {
  const std::string said = "light 0 simulated again in the background (";
  LightReport r;
  const size_t at = out.rfind(said);
  if (at == std::string::npos) return r;
  const std::string line = out.substr(at, out.find('\n', at) - at);
  r.found = true;
  r.cached = line.compare(said.size(), 20, "from the light cache") == 0;
  const size_t meanwhile = line.find("meanwhile ") + 10;
  r.rendered = std::stoll(line.substr(meanwhile));
  const size_t and_ = line.find(" and ", meanwhile) + 5;
  r.presented = std::stoll(line.substr(and_));
  const size_t open = line.find("position ") + 9;
  r.position = nlohmann::json::parse(line.substr(open, line.find(']', open) + 1 - open));
  return r;
}

/// Ctrl + drag moves the first light. The moved light is simulated on a thread
/// of the viewer's own while the view keeps refining with the former light volumes (the viewer
/// reports the frames it rendered or presented meanwhile: a viewer that simulated in its event
/// loop would report none), then swapped into the renderer; the view then shows what `eikon
/// render` shows with the light where the viewer says it put it, and the floor brightens on the
/// side the light moved to and darkens on the other. A second viewer making the same drag finds
/// the light in the light cache.
TEST_F(ViewerTest, CtrlDragMovesTheLightInTheBackground) {
  const std::string xvfb = findProgram("Xvfb"), xdotool = findProgram("xdotool");
  if (xvfb.empty()) GTEST_SKIP() << "Xvfb is not installed (Debian package xvfb)";
  ASSERT_FALSE(xdotool.empty()) << "xdotool is not installed (Debian package xdotool)";
  Xvfb server(xvfb);
  ASSERT_FALSE(server.display().empty()) << "Xvfb did not start";
  // At 64 voxels a side the moved light takes 0.5-1 s to simulate, longer than the view takes to
  // refine after the first light is swapped in, so frames are rendered meanwhile on any load (at
  // kLitScene's 32 it took 0.11 s, and under load the window's thread rendered none in it).
  writeLitScene(dir_, 64);
  const fs::path shot = dir_ / "lit.png";
  extra_env_ = "EIKON_CACHE_DIR=" + quote((dir_ / "cache").string());  // none of it seen before
  // Once the first frame shows (the view then refines to 32 samples), the light is dragged 12
  // pixels of the 60-pixel window to the right in one motion (one simulation); once the view
  // with the moved light is refined (the title says both), Q.
  const std::string args = "--width 80 --height 60 --spp 32 --screenshot " + quote(shot.string());
  const std::string drag =
      " search --sync --onlyvisible --name 'samples' windowfocus %1 mousemove --window %1 40 30"
      " sleep 0.1 keydown ctrl sleep 0.1 mousedown 1 sleep 0.1 mousemove --window %1 52 30"
      " sleep 0.1 mouseup 1 sleep 0.1 keyup ctrl"
      " search --sync --onlyvisible --name 'refined . light moved' key q";
  const ViewerRun run = viewWhile(server, xdotool, (dir_ / "lit.json").string(), args, drag);
  const std::string &out = run.out, &err = run.err;
  ASSERT_TRUE(WIFEXITED(run.status) && WEXITSTATUS(run.status) == 0) << err;
  EXPECT_EQ(err.find("validation"), std::string::npos) << err;
  const LightReport light = lastLightReport(out);
  ASSERT_TRUE(light.found) << out;
  std::printf("while the light was simulated: %lld frames rendered, %lld presented again\n",
              light.rendered, light.presented);
  EXPECT_GT(light.rendered + light.presented, 0) << out;
  const nlohmann::json position = light.position;
  // 12 pixels of a 60-pixel window to the right: 0.2 of the image height at the light's depth.
  EXPECT_LT(position[0].get<double>(), -1.0) << position.dump();  // the image's right is -x
  nlohmann::json scene = nlohmann::json::parse(kLitScene);
  scene["volume"]["resolution"] = 64;
  scene["lights"][0]["position"] = position;
  std::ofstream(dir_ / "moved.json") << scene.dump();
  const auto render80 = [&](const fs::path& s, const std::string& name) {
    const fs::path out_exr = dir_ / (name + ".exr");
    const Outcome o = eikon::test::runEikon(
        "render " + quote(s.string()) + " -o " + quote(out_exr.string()) + " -q --spp 32",
        dir_ / "render_io", "EIKON_VALIDATION=1");
    EXPECT_EQ(o.code, 0) << o.err;
    return readPng(fs::path(out_exr).replace_extension(".png"));
  };
  const Png viewed = readPng(shot), moved = render80(dir_ / "moved.json", "moved"),
            before = render80(dir_ / "lit.json", "before");
  // The same samples as the render's: only the 8-bit rounding of the two images and the light
  // position's 9 printed digits separate the view from the render of the moved light.
  const double same = rmsDifference(viewed, moved), unmoved = rmsDifference(viewed, before);
  std::printf("rms: viewer vs render with the moved light %.5f, with the scene's light %.5f\n",
              same, unmoved);
  EXPECT_LE(same, 2.0 / 255) << out;
  EXPECT_GT(unmoved, 2.0 / 255) << "the moved light did not change the view";

  // The floor's front corners, out of the glass ball's shadow and caustic: a point light's
  // irradiance there, h/r³ (h the light's height above the floor, r its distance), rises on the
  // side the light moved to and falls on the other.
  const glm::dvec3 lit0(0, 7, 0),
      lit1(position[0].get<double>(), position[1].get<double>(), position[2].get<double>());
  const auto irradiance = [](const glm::dvec3& l, const glm::dvec3& p) {
    const double r = glm::length(l - p);
    return (l.y - p.y) / (r * r * r);
  };
  for (const glm::dvec3& corner : {glm::dvec3(-5.5, -3.5, -5), glm::dvec3(5.5, -3.5, -5)}) {
    const double expected = irradiance(lit1, corner) / irradiance(lit0, corner);
    const double after = patchAt(viewed, corner), was = patchAt(before, corner);
    std::printf("floor at x = %+.1f: brightness %.1f -> %.1f; irradiance x %.3f\n", corner.x, was,
                after, expected);
    if (expected > 1)
      EXPECT_GT(after, was + 3) << corner.x;
    else
      EXPECT_LT(after, was - 3) << corner.x;
  }

  // The same drag again in a second viewer: the light is found in the cache the first filled.
  const ViewerRun again = viewWhile(server, xdotool, (dir_ / "lit.json").string(), args, drag);
  ASSERT_TRUE(WIFEXITED(again.status) && WEXITSTATUS(again.status) == 0) << again.err;
  const LightReport cached = lastLightReport(again.out);
  ASSERT_TRUE(cached.found) << again.out;
  EXPECT_TRUE(cached.cached) << again.out;
  EXPECT_EQ(cached.position, position) << again.out;
}

/// A lit scene whose light is not in the light cache: the viewer shows the scene unlit at once
/// and simulates the light in the background, then swaps the lit renderer in; a view ended by
/// --exit-after-frames waits for it. The refined view then equals `eikon render` of the scene (the
/// same samples: within the 8-bit rounding, as in CtrlDragMovesTheLightInTheBackground) and
/// differs from the unlit render. A second viewer finds the light in the cache the first filled,
/// simulates nothing and shows the same picture.
TEST_F(ViewerTest, FirstLightIsSimulatedInTheBackgroundAndWaitedFor) {
  const std::string xvfb = findProgram("Xvfb");
  if (xvfb.empty()) GTEST_SKIP() << "Xvfb is not installed (Debian package xvfb)";
  Xvfb server(xvfb);
  ASSERT_FALSE(server.display().empty()) << "Xvfb did not start";
  std::ofstream(dir_ / "lit.json") << kLitScene;
  extra_env_ = "EIKON_CACHE_DIR=" + quote((dir_ / "cache").string());  // none of it seen before
  const auto view = [&](const std::string& name) {
    const fs::path shot = dir_ / (name + ".png");
    const ViewerRun run =
        viewWhile(server, "", (dir_ / "lit.json").string(),
                  "--width 80 --height 60 --spp 8 --exit-after-frames 100 --screenshot " +
                      quote(shot.string()),
                  "");
    EXPECT_TRUE(WIFEXITED(run.status) && WEXITSTATUS(run.status) == 0) << run.err;
    EXPECT_EQ(run.err.find("validation"), std::string::npos) << run.err;
    EXPECT_NE(run.out.find("8 samples"), std::string::npos) << run.out;
    return std::pair{run.out, readPng(shot)};
  };
  const auto render80 = [&](const std::string& extra, const std::string& name) {
    const fs::path out_exr = dir_ / (name + ".exr");
    const Outcome o =
        eikon::test::runEikon("render " + quote((dir_ / "lit.json").string()) + " -o " +
                                  quote(out_exr.string()) + " -q --spp 8 --no-light-cache " + extra,
                              dir_ / "render_io", "EIKON_VALIDATION=1");
    EXPECT_EQ(o.code, 0) << o.err;
    return readPng(fs::path(out_exr).replace_extension(".png"));
  };
  const auto [out, viewed] = view("first");
  EXPECT_NE(out.find("eikon view: light 0 simulated in the background (simulated, "),
            std::string::npos)
      << out;
  const Png lit = render80("", "lit"), unlit = render80("--no-light", "unlit");
  const double same = rmsDifference(viewed, lit), dark = rmsDifference(viewed, unlit);
  std::printf("rms: viewer vs the lit render %.5f, vs the unlit render %.5f\n", same, dark);
  EXPECT_LE(same, 2.0 / 255) << out;
  EXPECT_GT(dark, 2.0 / 255) << "the view was not lit";

  const auto [again, cached] = view("again");
  EXPECT_NE(again.find("eikon view: light 0 simulated in the background (from the light cache, "),
            std::string::npos)
      << again;
  EXPECT_EQ(rmsDifference(cached, viewed), 0.0);
}

/// A lit scene's first frame does not wait for the whole volume (docs/viewer.md "The first
/// light"): the viewer shows a sharp scene unlit from its interfaces alone, and the light mover
/// voxelises the whole volume only once that frame is shown. The viewer counts the frames it showed
/// before any whole volume existed; the first is one of them, whatever the machine's speed.
TEST_F(ViewerTest, FirstFrameIsShownBeforeTheWholeVolumeIsVoxelised) {
  const std::string xvfb = findProgram("Xvfb");
  if (xvfb.empty()) GTEST_SKIP() << "Xvfb is not installed (Debian package xvfb)";
  Xvfb server(xvfb);
  ASSERT_FALSE(server.display().empty()) << "Xvfb did not start";
  std::ofstream(dir_ / "lit.json") << kLitScene;
  extra_env_ = "EIKON_CACHE_DIR=" + quote((dir_ / "cache").string());
  for (const char* run : {"simulated", "from the light cache"}) {
    const ViewerRun r = viewWhile(server, "", (dir_ / "lit.json").string(),
                                  "--width 80 --height 60 --spp 1 --exit-after-frames 1", "");
    ASSERT_TRUE(WIFEXITED(r.status) && WEXITSTATUS(r.status) == 0) << r.err;
    // "light 0 simulated in the background (HOW, T s, the volume voxelised there in V s; N frames
    // rendered unlit, K of them before the volume was voxelised, and P presented again)"
    const std::string said = "eikon view: light 0 simulated in the background (" + std::string(run);
    const size_t at = r.out.find(said);
    ASSERT_NE(at, std::string::npos) << r.out;
    const std::string line = r.out.substr(at, r.out.find('\n', at) - at);
    const size_t unlit = line.find(" frames rendered unlit, "), of = line.find(" of them before");
    ASSERT_TRUE(unlit != std::string::npos && of != std::string::npos) << line;
    const long long frames = std::stoll(line.substr(line.rfind(' ', unlit - 1) + 1)),
                    before = std::stoll(line.substr(unlit + 24));
    EXPECT_GE(before, 1) << line;
    EXPECT_LE(before, frames) << line;
  }
}

/// A window closed before its first light arrived does not wait for it: the light's voxelising or
/// simulation stops at its next progress report (a 160-voxel volume: seconds of work, against
/// the key pressed at the first frame), the viewer says so and exits cleanly, and nothing is
/// written to the light cache.
TEST_F(ViewerTest, ClosingBeforeTheLightArrivesStopsItAndCachesNothing) {
  const std::string xvfb = findProgram("Xvfb"), xdotool = findProgram("xdotool");
  if (xvfb.empty()) GTEST_SKIP() << "Xvfb is not installed (Debian package xvfb)";
  ASSERT_FALSE(xdotool.empty()) << "xdotool is not installed (Debian package xdotool)";
  Xvfb server(xvfb);
  ASSERT_FALSE(server.display().empty()) << "Xvfb did not start";
  writeLitScene(dir_, 160);
  extra_env_ = "EIKON_CACHE_DIR=" + quote((dir_ / "cache").string());
  const ViewerRun run =
      viewWhile(server, xdotool, (dir_ / "lit.json").string(), "--width 80 --height 60 --spp 1",
                " search --sync --onlyvisible --name 'samples' key q");
  ASSERT_TRUE(WIFEXITED(run.status) && WEXITSTATUS(run.status) == 0) << run.err;
  EXPECT_EQ(run.err.find("validation"), std::string::npos) << run.err;
  EXPECT_NE(run.out.find("eikon view: the window closed while the light was "), std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("stopped there, nothing cached"), std::string::npos) << run.out;
  EXPECT_EQ(run.out.find("light 0 simulated in the background"), std::string::npos) << run.out;
  size_t lights = 0;
  if (fs::exists(dir_ / "cache"))
    for (const auto& e : fs::recursive_directory_iterator(dir_ / "cache"))
      lights += e.path().filename().string().rfind("light-", 0) == 0;
  EXPECT_EQ(lights, 0u) << "a light was cached";
}

/// An N-BK7 (Sellmeier: dispersive, so 16 wavelengths) sphere; `attenuation` per mm in it.
std::string dispersiveScene(double attenuation) {
  return R"({
  "camera": {"position": [0, 0, -40], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 30, "width": 40, "height": 30},
  "environment": {"type": "checker", "squares": 8},
  "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 16},
  "materials": {"glass": {"n": {"sellmeier": [1.03961212, 0.231792344, 1.01046945, 0.00600069867, 0.0200179144, 103.560653]}, "attenuation_per_mm": )" +
         std::to_string(attenuation) + R"(}},
  "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 5, "material": "glass"}]
})";
}

/// The refinement's middle stage (the full size at few wavelengths) is kept where spectral passes
/// are stratified (an attenuating medium, docs/spectra.md: one march per wavelength, so few
/// wavelengths are cheaper) and skipped under hero wavelength sampling, where one march carries
/// every wavelength and few cost nearly as much as all (docs/viewer.md "Progressive refinement").
TEST_F(ViewerTest, HeroSpectralViewGoesFromCoarseStraightToFullQuality) {
  const std::string xvfb = findProgram("Xvfb"), xdotool = findProgram("xdotool");
  if (xvfb.empty()) GTEST_SKIP() << "Xvfb is not installed (Debian package xvfb)";
  ASSERT_FALSE(xdotool.empty()) << "xdotool is not installed (Debian package xdotool)";
  Xvfb server(xvfb);
  ASSERT_FALSE(server.display().empty()) << "Xvfb did not start";
  for (const auto& [attenuation, few] : {std::pair{0.0, 0}, std::pair{0.02, 1}}) {
    std::ofstream(dir_ / "sphere.json") << dispersiveScene(attenuation);
    const ViewerRun run =
        viewWhile(server, xdotool, (dir_ / "sphere.json").string(),
                  "--width 40 --height 30 --spp 2 --exit-after-frames 100 --no-light", "");
    ASSERT_TRUE(WIFEXITED(run.status) && WEXITSTATUS(run.status) == 0) << run.err;
    EXPECT_EQ(run.err.find("validation"), std::string::npos) << run.err;
    const std::string said = "(" + std::to_string(few) + " full-size frames at fewer wavelengths";
    EXPECT_NE(run.out.find(said), std::string::npos) << attenuation << ": " << run.out;
    EXPECT_NE(run.out.find("2 samples after"), std::string::npos) << run.out;
  }
}

/// S saves into ~/Pictures/eikon (HOME here a temporary folder), never over a file that is there:
/// with glass_sphere-view-1.png present, two saves write -2 and -3 (both files each), leave the
/// PNG as it was and print the absolute paths. A --save-dir that cannot be written is refused
/// before any window.
TEST_F(ViewerTest, SaveGoesToThePicturesFolderAndNeverOverwrites) {
  const std::string xvfb = findProgram("Xvfb"), xdotool = findProgram("xdotool");
  if (xvfb.empty()) GTEST_SKIP() << "Xvfb is not installed (Debian package xvfb)";
  ASSERT_FALSE(xdotool.empty()) << "xdotool is not installed (Debian package xdotool)";
  Xvfb server(xvfb);
  ASSERT_FALSE(server.display().empty()) << "Xvfb did not start";
  const fs::path home = dir_ / "home", pictures = home / "Pictures" / "eikon";
  fs::create_directories(pictures);
  std::ofstream(pictures / "glass_sphere-view-1.png") << "not the viewer's";
  extra_env_ = "HOME=" + quote(home.string());
  const ViewerRun run = viewWhile(
      server, xdotool, kGlassSphere, "--width 40 --height 30 --spp 1 --no-prefetch",
      " search --sync --onlyvisible --name 'refined' windowfocus %1 sleep 0.2 key s sleep 0.6"
      " key s sleep 0.6 key q");
  ASSERT_TRUE(WIFEXITED(run.status) && WEXITSTATUS(run.status) == 0) << run.err;
  EXPECT_EQ(run.err.find("validation"), std::string::npos) << run.err;
  EXPECT_EQ(eikon::test::slurp(pictures / "glass_sphere-view-1.png"), "not the viewer's");
  EXPECT_FALSE(fs::exists(pictures / "glass_sphere-view-1.exr"));
  for (const char* k : {"2", "3"}) {
    const fs::path exr = pictures / (std::string("glass_sphere-view-") + k + ".exr");
    const fs::path png = fs::path(exr).replace_extension(".png");
    EXPECT_GT(fs::file_size(exr), 0u) << exr;
    EXPECT_EQ(readPng(png).width, 40) << png;
    EXPECT_NE(run.out.find("eikon view: saved " + exr.string() + " and " + png.string()),
              std::string::npos)
        << run.out;
  }
  EXPECT_FALSE(fs::exists(pictures / "glass_sphere-view-4.exr"));
  // Not the current folder.
  for (const auto& e : fs::directory_iterator(dir_))
    EXPECT_EQ(e.path().filename().string().find("-view-"), std::string::npos) << e.path();
  // A folder below a file cannot be made: refused before the window, in one line.
  std::ofstream(dir_ / "file") << "x";
  const Outcome bad = eikon::test::runEikon(
      "view " + quote(kGlassSphere) + " --save-dir " + quote((dir_ / "file" / "sub").string()),
      dir_ / "render_io", "EIKON_VALIDATION=1 DISPLAY=" + quote(server.display()));
  EXPECT_NE(bad.code, 0);
  EXPECT_EQ(bad.err.rfind("eikon: error: ", 0), 0u) << bad.err;
  EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
}

/// The lighting key (L) cycles the scene's own lighting, then the gem studio's presets (dome,
/// spot, aset, idealscope, lightbox). Under dome the title gives the stone's brightness measured
/// as `eikon gem` measures a tilt. Here the scene's camera is the analysis' own face-up camera of
/// the stone (a sphere of diamond's index, radius 3: its bounds' half-diagonal is 3√3, so the
/// camera stands 250 mm above its centre with a field of 2·atan(1.05·3√3/250)), so the viewer's
/// figure is the one `eikon gem --tilts 0` reports at the same size and samples, up to the twins'
/// float precision (the viewer renders on the GPU twin, the analysis on the CPU twin, with the
/// same samples). The bound is the sample noise: three times the spread of two analyses whose
/// pixel grids are shifted by sub-pixel offsets (--seed 1 and 2), at least 0.005.
TEST_F(ViewerTest, LightingKeyShowsTheDomeAndTheStonesBrightnessAsTheGemAnalysis) {
  const std::string xvfb = findProgram("Xvfb"), xdotool = findProgram("xdotool");
  if (xvfb.empty()) GTEST_SKIP() << "Xvfb is not installed (Debian package xvfb)";
  ASSERT_FALSE(xdotool.empty()) << "xdotool is not installed (Debian package xdotool)";
  const double fov =
      2.0 * std::atan(1.05 * 3.0 * std::sqrt(3.0) / 250.0) * 180.0 / std::numbers::pi;
  nlohmann::json scene = nlohmann::json::parse(R"({
    "camera": {"position": [0, 250, 0], "look_at": [0, 0, 0], "up": [0, 0, 1], "width": 48,
               "height": 48},
    "volume": {"bounds_min": [-4, -4, -4], "bounds_max": [4, 4, 4], "resolution": 32},
    "materials": {"stone": {"n": 2.4175}},
    "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 3, "material": "stone"}]})");
  scene["camera"]["fov_deg"] = fov;
  const fs::path file = dir_ / "stone.json";
  std::ofstream(file) << scene.dump();
  const auto analysed = [&](const std::string& seed) {
    const Outcome o = eikon::test::runEikon(
        "gem " + quote(file.string()) +
            " --tilts 0 --width 48 --height 48 --spp 4 -q --json --seed " + seed,
        dir_ / "render_io", "EIKON_VALIDATION=1");
    EXPECT_EQ(o.code, 0) << o.err;
    return o.code == 0 ? nlohmann::json::parse(o.out).at("brightness").get<double>() : -1.0;
  };
  const double gem = analysed("0");
  const double bound = std::max(0.005, 3.0 * std::abs(analysed("1") - analysed("2")));
  Xvfb server(xvfb);
  ASSERT_FALSE(server.display().empty()) << "Xvfb did not start";
  const ViewerRun run =
      viewWhile(server, xdotool, file.string(), "--width 48 --height 48 --spp 4",
                " search --sync --onlyvisible --name 'samples' windowfocus %1 sleep 0.2 key l"
                " search --sync --onlyvisible --name 'refined . light dome: brightness' key q");
  ASSERT_TRUE(WIFEXITED(run.status) && WEXITSTATUS(run.status) == 0) << run.err;
  EXPECT_EQ(run.err.find("validation"), std::string::npos) << run.err;
  const std::string said = "eikon view: lighting dome: brightness ";
  const size_t at = run.out.find(said);
  ASSERT_NE(at, std::string::npos) << run.out;
  const double shown = std::stod(run.out.substr(at + said.size()));
  std::printf("[ measured ] brightness: viewer %.4f, eikon gem %.4f (bound %.4f)\n", shown, gem,
              bound);
  EXPECT_NEAR(shown, gem, bound);
  EXPECT_GT(gem, 0.05);  // the stone is lit and in view
}

}  // namespace
