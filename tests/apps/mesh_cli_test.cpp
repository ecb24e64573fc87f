// The "mesh" shape through the real binary: a convex mesh is its exact
// polyhedron, so the self-made cube (tests/data/meshes/box.obj) scaled to 6 × 4 × 5 mm and the
// `box` shape of that size, placed and turned alike, must leave the same exit points under
// `eikon trace` with sharp interfaces (to 1e-4 mm, GPU and CPU twin) and render the same image.
// A non-convex mesh (an L-shaped prism) traces on Snell's line with sharp interfaces and renders
// with either kind, and bad meshes fail with one line.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "core/io/exr.h"
#include "tests/apps/cli_support.h"
#include "tests/sanitizers.h"

namespace {

namespace fs = std::filesystem;
using eikon::test::Outcome;
using eikon::test::quote;

const fs::path kMeshes = fs::path(EIKON_SOURCE_DIR) / "tests" / "data" / "meshes";

class MeshCli : public ::testing::Test {
 protected:
  fs::path scene(const std::string& name, const std::string& object,
                 const std::string& interfaces = "sharp") {
    const fs::path p = dir_ / name;
    std::ofstream(p) << R"({
  "camera": {"position": [0, 0, -40], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 20,
             "width": 48, "height": 36},
  "volume": {"bounds_min": [-6, -6, -6], "bounds_max": [6, 6, 6], "resolution": 48,
             "smoothing_voxels": 0.75},
  "interfaces": ")" + interfaces +
                            R"(", "materials": {"glass": {"n": 1.5}},
  "objects": [)" + object + "]}";
    return p;
  }
  Outcome eikon(const std::string& args) { return eikon::test::runEikon(args, dir_ / "io"); }

  eikon::test::TempDir tmp_{"eikon_mesh_cli"};
  const fs::path dir_ = tmp_.path();
};

const char* kPlace = R"("center": [0.3, -0.2, 0.1], "rotation_deg": [20, -35, 50])";

TEST_F(MeshCli, MeshBoxTracesAndRendersAsTheBoxShape) {
  const fs::path box = scene(
      "box.json",
      std::string(R"({"shape": "box", "material": "glass", "size": [6, 4, 5], )") + kPlace + "}");
  const fs::path mesh = scene("mesh.json", R"({"shape": "mesh", "material": "glass", "file": ")" +
                                               (kMeshes / "box.obj").string() +
                                               R"(", "scale": [6, 4, 5], )" + kPlace + "}");
  // Rays from the volume's faces through the box: straight on, oblique, and near an edge.
  const std::vector<std::pair<std::string, std::string>> rays = {{"0,0,-6", "0,0,1"},
                                                                 {"-6,1,-6", "1,-0.1,1"},
                                                                 {"1,6,-2", "-0.2,-1,0.3"},
                                                                 {"2.2,2,-6", "0,0,1"}};
  double worst = 0;
  // The CPU twin on every ray, the GPU (a pipeline build per run on lavapipe) on two of them.
  for (const std::string twin : {" --reference", ""})
    for (size_t ray = 0; ray < (twin.empty() ? 2 : rays.size()); ++ray) {
      const auto& [o, d] = rays[ray];
      std::vector<nlohmann::json> out;
      for (const fs::path& s : {box, mesh}) {
        const Outcome r = eikon("trace " + quote(s.string()) + " --origin " + o + " --dir " + d +
                                " --json" + twin);
        ASSERT_EQ(r.code, 0) << r.err;
        out.push_back(nlohmann::json::parse(r.out)["modes"][0]);
      }
      const auto pa = out[0]["exit_point"].get<std::vector<double>>();
      const auto pb = out[1]["exit_point"].get<std::vector<double>>();
      const auto da = out[0]["exit_direction"].get<std::vector<double>>();
      const auto db = out[1]["exit_direction"].get<std::vector<double>>();
      EXPECT_EQ(out[0]["interfaces"], out[1]["interfaces"]) << o << twin;
      EXPECT_GE(out[0]["interfaces"].get<int>(), 2) << o << " misses the box";
      for (int k = 0; k < 3; ++k) {
        worst = std::max(worst, std::abs(pa[size_t(k)] - pb[size_t(k)]));
        EXPECT_NEAR(pa[size_t(k)], pb[size_t(k)], 1e-4) << o << twin;
        EXPECT_NEAR(da[size_t(k)], db[size_t(k)], 1e-5) << o << twin;
      }
    }
  std::printf("[ measured ] largest exit-point difference, mesh box vs box: %.3g mm\n", worst);
  // Both twins' images: the same planes, so the same pixels.
  for (const std::string twin : {"", " --reference"}) {
    std::vector<std::vector<float>> img;
    for (const fs::path& s : {box, mesh}) {
      const fs::path exr = dir_ / (s.stem().string() + ".exr");
      const Outcome r =
          eikon("render " + quote(s.string()) + " -o " + quote(exr.string()) + " -q" + twin);
      ASSERT_EQ(r.code, 0) << r.err;
      img.push_back(eikon::readExrRgba(exr, 48, 36).rgba);
    }
    ASSERT_EQ(img[0].size(), img[1].size());
    double max_diff = 0, sum = 0;
    for (size_t i = 0; i < img[0].size(); ++i) {
      max_diff = std::max(max_diff, double(std::abs(img[0][i] - img[1][i])));
      sum += img[0][i];
    }
    std::printf("[ measured ] image difference, mesh box vs box%s: max %.3g (mean value %.3g)\n",
                twin.c_str(), max_diff, sum / double(img[0].size()));
    EXPECT_LT(max_diff, 1e-4) << twin;
  }
}

TEST_F(MeshCli, NonConvexMeshRendersWithSharpAndSmoothedInterfaces) {
  const std::string obj = R"({"shape": "mesh", "material": "glass", "file": ")" +
                          (kMeshes / "notched_box.obj").string() +
                          R"(", "scale": 3, "center": [-3, -3, -1.5]})";
  // The L spans x ∈ [-3, 3], y ∈ [-3, 0] and x ∈ [-3, 0], y ∈ [0, 3], z ∈ [-1.5, 1.5]. A ray at
  // 30° to the caps' normal enters the arm x < 0 through the cap z = −1.5 and leaves by the
  // other, displaced by 3 (tan 30° − tan θt) across the 3 mm slab, sin θt = sin 30° / 1.5.
  const std::string ray =
      " --origin -1.5,-1.5,-6 --dir 0,0.5," + std::to_string(std::sqrt(0.75)) + " --json";
  const double t30 = std::tan(std::asin(0.5)), st = 0.5 / 1.5, tt = st / std::sqrt(1 - st * st);
  // From z = −6 to the exit face z = 6: 12 tan 30° straight, less 3 (tan 30° − tan θt).
  const double y_exit = -1.5 + 12 * t30 - 3 * (t30 - tt);
  // Sharp (the default): the caps are triangle pairs refracting at their exact planes, so both
  // twins leave on Snell's line (1e-4 mm: tests/core/render/mesh_sharp_test.cpp derives it).
  const fs::path sh = scene("s.json", obj);
  for (const std::string twin : {" --reference", ""}) {
    const Outcome r = eikon("trace " + quote(sh.string()) + ray + twin);
    ASSERT_EQ(r.code, 0) << r.err;
    const auto m = nlohmann::json::parse(r.out)["modes"][0];
    const auto p = m["exit_point"].get<std::vector<double>>();
    std::printf("[ measured ] L prism, sharp%s: exit y %.6f mm (Snell %.6f)\n", twin.c_str(), p[1],
                y_exit);
    EXPECT_EQ(m["interfaces"].get<int>(), 2) << twin;
    EXPECT_NEAR(p[2], 6.0, 1e-5) << twin;
    EXPECT_NEAR(p[1], y_exit, 1e-4) << twin;
  }
  const Outcome sharp =
      eikon("render " + quote(sh.string()) + " -o " + quote((dir_ / "s.exr").string()) + " -q");
  ASSERT_EQ(sharp.code, 0) << sharp.err;
  EXPECT_TRUE(fs::exists(dir_ / "s.exr"));
  // Smoothed: as before sharp interfaces existed for non-convex meshes.
  const fs::path sm = scene("m.json", obj, "smoothed");
  const Outcome r = eikon("trace " + quote(sm.string()) + ray + " --reference");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto p = nlohmann::json::parse(r.out)["modes"][0]["exit_point"].get<std::vector<double>>();
  std::printf("[ measured ] L prism: exit y %.4f mm (Snell %.4f, straight %.4f)\n", p[1], y_exit,
              -1.5 + 12 * t30);
  EXPECT_NEAR(p[2], 6.0, 1e-6);
  // Smoothed interfaces place a flat face to first order in the voxel (0.25 mm): 0.05 mm here
  // (n = 1.4 would move the exit by 0.086 mm; measured: 0.029 mm short of Snell).
  EXPECT_NEAR(p[1], y_exit, 0.05);
  const Outcome img =
      eikon("render " + quote(sm.string()) + " -o " + quote((dir_ / "m.exr").string()) + " -q");
  ASSERT_EQ(img.code, 0) << img.err;
  EXPECT_TRUE(fs::exists(dir_ / "m.exr"));
}

TEST_F(MeshCli, OpenMeshFailsWithOneLineNamingTheEdge) {
  const fs::path s = scene("open.json", R"({"shape": "mesh", "material": "glass", "file": ")" +
                                            (kMeshes / "open_box.obj").string() + R"("})");
  const Outcome r =
      eikon("render " + quote(s.string()) + " -o " + quote((dir_ / "o.exr").string()) + " -q");
  EXPECT_NE(r.code, 0);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.err.find("eikon: error: " + s.string() +
                       ": /objects/0/file: open_box.obj: open mesh: "
                       "the edge ("),
            0u)
      << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "o.exr"));
}

// Fuzzing found a malformed OBJ vertex reported as "OBJ: vertex index out of range" and a scale of
// 1e300 as "the planes do not enclose a bounded solid": each is one line naming what is wrong.
TEST_F(MeshCli, BadVertexLineAndAbsurdScaleFailWithOneLine) {
  std::ofstream(dir_ / "bad.obj") << "v 0 0 0\nv 1 0 0\nv abc 0.5 0.5\nv 0 0 1\n"
                                     "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";
  std::ofstream(dir_ / "short.obj") << "v 0 0 0\nv 1 0 0\nv 0.5\nv 0 0 1\n"
                                       "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {R"("file": "bad.obj")",
       "/objects/0/file: bad.obj: line 3: the vertex's x 'abc' is not a number"},
      {R"("file": "short.obj")",
       "/objects/0/file: short.obj: line 3: the vertex 'v 0.5' has 1 number"},
      {R"("file": ")" + (kMeshes / "box.obj").string() + R"(", "scale": 1e300)",
       "/objects/0/scale: the scaled mesh must lie within ±1e+12 mm of its centre on each axis"},
      {R"("file": ")" + (kMeshes / "box.obj").string() + R"(", "scale": 1e-300)",
       "/objects/0/scale: the scaled mesh must be at least 1e-06 mm across on each axis"},
  };
  for (const auto& [keys, want] : cases) {
    const fs::path s = scene("s.json", R"({"shape": "mesh", "material": "glass", )" + keys + "}");
    const Outcome r =
        eikon("render " + quote(s.string()) + " -o " + quote((dir_ / "o.exr").string()) + " -q");
    EXPECT_NE(r.code, 0);
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.err.find("eikon: error: " + s.string() + ": " + want), 0u) << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "o.exr"));
  }
}

/// box.obj's cube as a binary little-endian PLY whose first face's list count is `first`
/// (uint32), the rest triangles.
std::string hostilePly(uint32_t first) {
  std::string t =
      "ply\nformat binary_little_endian 1.0\nelement vertex 8\nproperty float x\nproperty float "
      "y\nproperty float z\nelement face 12\nproperty list uint int vertex_indices\nend_header\n";
  auto put = [&](auto x) { t.append(reinterpret_cast<const char*>(&x), sizeof x); };
  for (int i = 0; i < 8; ++i)
    for (int a : {4, 2, 1}) put(i & a ? 0.5f : -0.5f);
  const int quads[6][4] = {{4, 6, 7, 5}, {0, 1, 3, 2}, {2, 3, 7, 6},
                           {0, 4, 5, 1}, {1, 5, 7, 3}, {0, 2, 6, 4}};
  bool head = true;
  for (const auto& q : quads)
    for (int j : {1, 2}) {
      put(head ? first : uint32_t(3));
      head = false;
      for (int c : {q[0], q[j], q[j + 1]}) put(int32_t(c));
    }
  return t;
}

// Hostile mesh files through the real binary: a PLY face list of 2³¹ corners (minutes and
// gigabytes for a reader that trusts it), a face of 0 corners, an OBJ whose mtllib names a FIFO
// (an open blocks for ever) and /etc/passwd. Each run is under `timeout` and an address-space
// limit, so that a regression fails (exit 124, or a memory error) rather than hangs or swells.
TEST_F(MeshCli, HostileMeshFilesFailAtOnceOrLoadWithoutOpeningAnythingElse) {
  if (eikon::test::kAddressSanitizer) GTEST_SKIP() << eikon::test::kNoAddressSpaceLimitUnderAsan;
  std::ofstream(dir_ / "huge.ply", std::ios::binary) << hostilePly(uint32_t(1) << 31);
  std::ofstream(dir_ / "zero.ply", std::ios::binary) << hostilePly(0);
  ASSERT_EQ(::mkfifo((dir_ / "pipe.mtl").c_str(), 0600), 0);
  std::ifstream box(kMeshes / "box.obj");
  std::ofstream(dir_ / "mtl.obj") << "mtllib /etc/passwd\nmtllib pipe.mtl\n" << box.rdbuf();
  // At most 2 GB of address space (the reader needs a few MB; the list declares 8 GB) and 60 s.
  const std::string timed = "ulimit -v 2000000; timeout 60 " + std::string(EIKON_BINARY);
  const std::string ray = " --origin 0,0,-6 --dir 0,0,1 --reference";
  const size_t header = hostilePly(3).find("end_header\n") + 11;
  const std::vector<std::pair<std::string, std::string>> refused = {
      {"huge.ply", "huge.ply: byte offset " + std::to_string(header + 96) +
                       ": the face 0 declares a list 'vertex_indices' of 2147483648 items, more "
                       "than the "},
      {"zero.ply", "zero.ply: byte offset " + std::to_string(header + 96) +
                       ": a face of 0 corners (a point or a line)"}};
  for (const auto& [file, want] : refused) {
    const fs::path s = scene(file + ".json", R"({"shape": "mesh", "material": "glass", "file": ")" +
                                                 file + R"(", "scale": 4})");
    const auto t0 = std::chrono::steady_clock::now();
    const Outcome r =
        eikon::test::runProgram(timed, "trace " + quote(s.string()) + ray, dir_ / "io");
    const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("[ measured ] %s refused by the binary in %.2f s (exit %d)\n", file.c_str(), sec,
                r.code);
    EXPECT_EQ(r.code, 1) << r.err;  // not 124 (the timeout), not -1 (a signal)
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.err.find("eikon: error: " + s.string() + ": /objects/0/file: " + want), 0u)
        << r.err;
  }
  const fs::path s = scene("mtl.json", R"({"shape": "mesh", "material": "glass", "file": "mtl.obj",
                                           "scale": 4})");
  const Outcome r = eikon::test::runProgram(timed, "trace " + quote(s.string()) + ray, dir_ / "io");
  EXPECT_EQ(r.code, 0) << r.err;  // 124: blocked on the FIFO
  EXPECT_NE(r.out.find("2 interfaces crossed"), std::string::npos) << r.out;
}

}  // namespace

// `eikon render --device`: auto renders a mesh scene of at least 131072 rays at 1 spp on the CPU
// twin where the Vulkan device is a CPU (lavapipe: the rule of renderTwin, core/render/
// render_defaults.h, measured in docs/view-renderer.md "Which twin renders"), and says so; every
// other scene, a smaller image and a render of several samples per pixel (whose previews only the
// GPU twin shows forming) on the GPU twin; gpu and cpu (and --reference) force one; both twins
// give the same picture.
TEST_F(MeshCli, DeviceAutoRendersMeshScenesOnTheCpuTwinOfACpuDevice) {
  // The L-shaped prism (a convex mesh is its polyhedron, which auto leaves on the GPU twin).
  const fs::path mesh = scene("mesh.json", R"({"shape": "mesh", "material": "glass", "file": ")" +
                                               (kMeshes / "notched_box.obj").string() +
                                               R"(", "scale": 3, "center": [-3, -3, -1.5]})");
  const fs::path sphere =
      scene("sphere.json", R"({"shape": "sphere", "material": "glass", "radius": 4})");
  auto render = [&](const fs::path& s, const std::string& args) {
    const fs::path exr = dir_ / (s.stem().string() + ".exr");
    return eikon("render " + quote(s.string()) + " -o " + quote(exr.string()) + " -q " + args);
  };
  const std::string big = "--width 400 --height 330";  // 132000 rays ≥ 131072
  const Outcome gpu = render(mesh, big + " --device gpu");
  ASSERT_EQ(gpu.code, 0) << gpu.err;
  EXPECT_NE(gpu.out.find("(GPU twin: asked for)"), std::string::npos) << gpu.out;
  const std::vector<float> gpu_img = eikon::readExrRgba(dir_ / "mesh.exr", 400, 330).rgba;
  const bool cpu_device = gpu.out.find("llvmpipe") != std::string::npos;
  const Outcome autoBig = render(mesh, big);
  ASSERT_EQ(autoBig.code, 0) << autoBig.err;
  EXPECT_NE(autoBig.out.find(cpu_device ? "on CPU reference (CPU twin: auto on a CPU device, mesh "
                                          "scene, 132000 rays)"
                                        : "(GPU twin: auto on a GPU)"),
            std::string::npos)
      << autoBig.out;
  // The twins' pictures: a ray's crossings agree to ~1e-5 mm (float against double), so a pixel
  // differs only where its ray passes that close to an edge of the prism and takes the other face.
  const std::vector<float> auto_img = eikon::readExrRgba(dir_ / "mesh.exr", 400, 330).rgba;
  ASSERT_EQ(auto_img.size(), gpu_img.size());
  size_t differ = 0;
  for (size_t i = 0; i < gpu_img.size(); ++i)
    differ += std::abs(auto_img[i] - gpu_img[i]) > 1e-3f * (1.0f + std::abs(gpu_img[i])) ? 1 : 0;
  EXPECT_LE(double(differ), 1e-3 * double(gpu_img.size()));
  // The GPU twin where the rule says so: a smaller image, several samples per pixel, no mesh.
  for (const auto& [s, args] : std::vector<std::pair<fs::path, std::string>>{
           {mesh, ""}, {mesh, "--width 300 --height 220 --spp 2"}, {sphere, big}}) {
    const Outcome r = render(s, args + " --device auto");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("(GPU twin: auto"), std::string::npos) << args << ": " << r.out;
  }
  for (const std::string cpu : {"--device cpu", "--reference", "--reference --device cpu"}) {
    const Outcome r = render(mesh, cpu);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("on CPU reference (CPU twin: asked for)"), std::string::npos) << r.out;
  }
  for (const auto& [args, says] : std::vector<std::pair<std::string, std::string>>{
           {"--device tpu", "--device must be auto, gpu or cpu, got 'tpu'"},
           {"--reference --device gpu", "--reference is --device cpu"}}) {
    const Outcome r = render(mesh, args);
    EXPECT_NE(r.code, 0) << args;
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
}
