// eikon.gem: the gem studio (core/session/gem.h, docs/gem-studio.md) as `eikon gem` runs it, with
// its defaults (GemRequest) and its checks (checkGemRequest: ValueError with the CLI's words).
//
//   g = eikon.gem(scene, tilts=[-10, 0, 10], width=64, height=64)
//   g["brightness"], g["fire"], g["per_tilt"][1]["extinction"]
//   eikon.gem(scene, keep_images=True)["images"]["dome_0"]   # (H, W, 3) float32
#include <pybind11/stl.h>

#include <cstdint>

#include "core/session/gem.h"
#include "python/module.h"

namespace eikon::python {
namespace {

py::array_t<float> rgbArray(const std::vector<float>& rgb, int width, int height) {
  py::array_t<float> a({py::ssize_t(height), py::ssize_t(width), py::ssize_t(3)});
  std::copy(rgb.begin(), rgb.end(), a.mutable_data());
  return a;
}

/// `tilts`: a sequence of degrees, or `eikon gem --tilts`'s text ("-20:20:5", "-10,0,10").
std::vector<double> gemTilts(const py::handle& tilts) {
  if (py::isinstance<py::str>(tilts)) {
    std::vector<double> out;
    checkSetting([&] { out = parseGemTilts(tilts.cast<std::string>()); });
    return out;
  }
  std::vector<double> out;
  try {
    out = tilts.cast<std::vector<double>>();
  } catch (const py::cast_error&) {
    throw std::invalid_argument("tilts must be a sequence of degrees or FROM:TO:STEP text, got " +
                                py::str(py::type::of(tilts).attr("__name__")).cast<std::string>());
  }
  return out;
}

/// `eikon gem --json`'s figures: the overall numbers, per_tilt, and with keep_images the pictures
/// ("dome_K" and "spot_K" for per_tilt[K], "aset", "idealscope", "lightbox" face-up).
py::dict gemDict(const GemReport& r, bool keep_images) {
  // The CLI's JSON (gemReportJson) as Python objects, without the scene file it names.
  nlohmann::json j = gemReportJson(r, "");
  j.erase("scene");
  py::dict d = py::module_::import("json").attr("loads")(j.dump());
  if (keep_images) {
    const GemImages& im = r.images;
    py::dict images;
    for (size_t k = 0; k < im.dome.size(); ++k)
      images[py::str("dome_" + std::to_string(k))] = rgbArray(im.dome[k], im.width, im.height);
    for (size_t k = 0; k < im.spot.size(); ++k)
      images[py::str("spot_" + std::to_string(k))] = rgbArray(im.spot[k], im.width, im.height);
    images["aset"] = rgbArray(im.aset, im.width, im.height);
    images["idealscope"] = rgbArray(im.idealscope, im.width, im.height);
    images["lightbox"] = rgbArray(im.lightbox, im.width, im.height);
    d["images"] = images;
  }
  return d;
}

py::dict gem(const std::shared_ptr<Scene>& scene, const py::object& tilts, int width, int height,
             int spp, int wavelengths, std::optional<int> object, int threads, bool keep_images,
             long long seed) {
  if (seed < 0 || seed > 4294967295LL)
    throw py::value_error("seed must be in [0, 4294967295], got " + std::to_string(seed));
  GemRequest req;
  req.tilts_deg = gemTilts(tilts);
  req.width = width;
  req.height = height;
  req.spp = spp;
  req.wavelengths = wavelengths;
  req.object = object;
  req.threads = threads;
  req.keep_images = keep_images;
  req.seed = std::uint32_t(seed);
  checkSetting([&] { checkGemRequest(req); });  // every bad argument before any work
  (void)gemStone(*scene, req.object);           // std::invalid_argument: ValueError
  // analyseGem replaces the scene's camera and environment: the caller's Scene stays as it is.
  auto copy = std::make_shared<Scene>(*scene);
  GemReport r;
  {
    py::gil_scoped_release release;
    r = analyseGem(copy, req);
  }
  return gemDict(r, keep_images);
}

}  // namespace

void bindGem(py::module_& m) {
  const GemRequest d;  // `eikon gem`'s defaults
  m.def("gem", &gem, py::arg("scene"), py::arg("tilts") = d.tilts_deg, py::arg("width") = d.width,
        py::arg("height") = d.height, py::arg("spp") = d.spp,
        py::arg("wavelengths") = d.wavelengths, py::arg("object") = py::none(),
        py::arg("threads") = d.threads, py::arg("keep_images") = d.keep_images,
        py::arg("seed") = d.seed,
        "the gem studio (`eikon gem`, docs/gem-studio.md) on the CPU twin: the stone (object, "
        "else the first transparent one) viewed face-up from 250 mm, tilted through `tilts` "
        "(degrees in [-60, 60], or --tilts' text 'FROM:TO:STEP'), rendered under the standard "
        "lighting presets and measured. Returns `eikon gem --json`'s figures: {'brightness', "
        "'fire', 'scintillation', 'windowing', 'extinction', 'contrast_change', 'object', "
        "'seconds', 'per_tilt': [{'tilt_deg', 'brightness', 'fire', 'windowing', 'extinction', "
        "'flashes', 'outline_px'}]}, and with keep_images=True 'images': {'dome_K', 'spot_K' "
        "(per_tilt[K]), 'aset', 'idealscope', 'lightbox' (face-up)}: (H, W, 3) float32 linear "
        "sRGB. width and height in [16, 2048], spp in [1, 256], wavelengths (the fire render's) "
        "in [1, 64]; ValueError naming the argument otherwise. seed (eikon gem --seed): 0 centres "
        "the pixel grid on the stone, another value shifts it by a sub-pixel offset drawn from "
        "it (another draw of the same estimate). The scene is not changed.");
}

}  // namespace eikon::python
