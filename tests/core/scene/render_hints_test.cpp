// A scene's "render" (its intended spp, wavelengths and exposure; docs/scene-format.md): parsed
// and range-checked with the JSON path, the defaults of a render, overridden by what is asked.
#include <gtest/gtest.h>

#include <string>

#include "core/render/render_defaults.h"
#include "core/scene/scene.h"
#include "core/session/session.h"
#include "tests/core/scene_support.h"

namespace eikon {
namespace {

std::string withRender(const std::string& render) {
  return R"({"render": )" + render +
         R"(, "objects": [{"shape": "sphere", "radius": 3, "material": "N-BK7"}]})";
}

TEST(RenderHints, ParsedAndUsedAsTheDefaults) {
  const Scene s =
      parseScene(withRender(R"({"spp": 64, "wavelengths": 8, "exposure": 2})"), "r.json");
  EXPECT_EQ(s.render.spp, 64);
  EXPECT_EQ(s.render.wavelengths, 8);
  EXPECT_EQ(s.render.exposure, 2.0);
  const RenderSettings d = defaultRenderSettings(s);
  EXPECT_EQ(d.spp, 64);
  EXPECT_EQ(d.wavelengths, 8);
  // Asked for: the request wins, each setting on its own.
  ViewRequest v;
  v.spp = 2;
  const RenderSettings asked = renderSettings(s, v);
  EXPECT_EQ(asked.spp, 2);
  EXPECT_EQ(asked.wavelengths, 8);
  v.wavelengths = 0;
  EXPECT_EQ(renderSettings(s, v).wavelengths, 0);
  // None given: the renderer's own defaults (N-BK7 is dispersive: 16 wavelengths).
  const Scene plain = parseScene(withRender("{}"), "r.json");
  EXPECT_FALSE(plain.render.spp || plain.render.wavelengths || plain.render.exposure);
  EXPECT_EQ(renderSettings(plain, ViewRequest{}).spp, 1);
  EXPECT_EQ(renderSettings(plain, ViewRequest{}).wavelengths, kDefaultDispersiveWavelengths);
}

TEST(RenderHints, OutOfRangeAndUnknownKeysAreErrorsWithTheirPath) {
  const std::pair<const char*, const char*> cases[] = {
      {R"({"spp": 0})", "/render/spp"},
      {R"({"spp": 4097})", "/render/spp"},
      {R"({"spp": 2.5})", "/render/spp"},
      {R"({"wavelengths": 257})", "/render/wavelengths"},
      {R"({"wavelengths": -1})", "/render/wavelengths"},
      {R"({"exposure": 65})", "/render/exposure"},
      {R"({"exposure": "2"})", "/render/exposure"},
      {R"({"samples": 8})", "/render/samples"},
      {R"({"width": 800})", "/render/width"},
      {R"(8)", "/render"},
  };
  for (const auto& [render, path] : cases) {
    const std::string e = test::sceneErrorOf(withRender(render), "r.json");
    EXPECT_EQ(e.rfind(std::string("r.json: ") + path + ": ", 0), 0u) << render << ": " << e;
  }
}

}  // namespace
}  // namespace eikon
