#include "core/session/settings.h"

#include <cmath>
#include <cstdio>

#include "core/session/session.h"

namespace eikon {

namespace {

namespace F = SettingFront;
using K = SettingKind;

// The table, in the order of the CLI's help and of its checks (fillSettings): the image, its
// wavelengths and layers, the march, the twin, the light simulator.
// clang-format off
const std::vector<Setting> kSettings = {
    {.name = "width", .kind = K::Integer, .fronts = F::RenderCli | F::ViewCli | F::PyRender,
     .help = "Image width", .field = "ViewRequest::width",
     .fill = [](const SettingValue& v, SettingRequests& r) {
       if (v.given) r.view.width = v.integer;
     },
     .means = "the scene camera's", .min = 1, .max = 16384, .says_value = true,
     .defaults = {{F::PyRender, "0", "the scene camera's", true}}},
    {.name = "height", .kind = K::Integer, .fronts = F::RenderCli | F::ViewCli | F::PyRender,
     .help = "Image height", .field = "ViewRequest::height",
     .fill = [](const SettingValue& v, SettingRequests& r) {
       if (v.given) r.view.height = v.integer;
     },
     .means = "the scene camera's", .min = 1, .max = 16384, .says_value = true,
     .defaults = {{F::PyRender, "0", "the scene camera's", true}}},
    {.name = "spp", .kind = K::Integer, .fronts = F::RenderCli | F::ViewCli | F::PyRender,
     .help = "Jittered samples per pixel", .field = "ViewRequest::spp",
     .fill = [](const SettingValue& v, SettingRequests& r) {
       if (v.given) r.view.spp = v.integer;
     },
     .means = "the scene's \"render\" spp, else 1", .min = 1, .max = 4096, .says_value = true,
     .defaults = {{F::ViewCli, "16", "the view refines to them while nothing changes"}}},
    {.name = "wavelengths", .kind = K::Integer,
     .fronts = F::RenderCli | F::ViewCli | F::PyRender,
     .help = "Spectral samples per pixel sample (0: RGB mode)", .field = "ViewRequest::wavelengths",
     .fill = [](const SettingValue& v, SettingRequests& r) {
       if (v.given) r.view.wavelengths = v.integer;
     },
     .means = "the scene's \"render\" wavelengths, else 16 for dispersive scenes, else 0",
     .min = 0, .max = 256, .says_value = true,
     .defaults = {{F::ViewCli, "", "16 for dispersive scenes, else 0; the R key toggles"}}},
    {.name = "wavelength", .kind = K::Number,
     .fronts = F::RenderCli | F::TraceCli | F::PyRender | F::PyTrace,
     .help = "Wavelength of a traced ray, and the one wavelength whose indices an RGB render "
             "(wavelengths 0) takes,",
     .field = "ViewRequest::wavelength_nm, TraceRequest::wavelength_nm",
     .fill = [](const SettingValue& v, SettingRequests& r) {
       r.view.wavelength_nm = v.number;
       r.wavelength_nm = v.number;
     },
     .value = "587.5618", .means = "the d line", .min = 100, .max = 10000, .unit = "nm",
     .keyword = "wavelength_nm"},
    {.name = "spectral-sampling", .kind = K::Choice, .fronts = F::RenderCli | F::PyRender,
     .help = "How a spectral render samples its wavelengths",
     .field = "ViewRequest::sampling",
     .fill = [](const SettingValue& v, SettingRequests& r) {
       r.view.sampling = parseSpectralSampling(v.text);
     },
     .value = "auto", .says_value = true,
     .choices = {{"auto", "hero unless the scene attenuates, emits or has opaque objects"},
                 {"hero", "one march per pixel sample, the other wavelengths share its path "
                          "until it disperses"},
                 {"stratified", "one march per wavelength"}},
     .keyword = "sampling"},
    {.name = "layers", .kind = K::Text, .fronts = F::RenderCli | F::PyRender,
     .help = "Extra image layers, comma-separated (R, G, B are always written)",
     .field = "ViewRequest::spectral_layer, mode_layers, aov_layer, stokes_layers",
     .fill = [](const SettingValue& v, SettingRequests& r) { parseLayers(v.text, r.view); },
     .means = "none",
     .choices = {{"spectral", "one S0.<nm> channel per wavelength bin; needs a spectral render, "
                              "wavelengths > 0"},
                 {"modes", "o.R..B, e.R..B: the o- and e-mode radiance (fast.R..slow.B when "
                            "the scene's crystals are all biaxial)"},
                 {"aov", "Z, Px Py Pz, Nx Ny Nz, objectId: the first interface of each pixel's "
                         "first ray; steps: march steps per pixel"},
                 {"stokes", "S0.R..S3.B of a polarised render; makes the render polarised"}}},
    {.name = "polarised", .kind = K::Flag, .fronts = F::RenderCli | F::PyRender,
     .help = "Polarised render (Stokes transport, docs/polarisation.md) even without polariser "
             "sheets or a camera analyzer, which make a render polarised by themselves",
     .field = "ViewRequest::polarised",
     .fill = [](const SettingValue& v, SettingRequests& r) { r.view.polarised = v.flag; }},
    {.name = "modes", .kind = K::Choice, .fronts = F::RenderCli | F::ViewCli | F::PyRender,
     .help = "Which modes of a crystal's light are rendered",
     .field = "ViewRequest::modes",
     .fill = [](const SettingValue& v, SettingRequests& r) { r.view.modes = parseModes(v.text); },
     .value = "both", .says_value = true,
     .choices = {{"o", "the o-mode alone, at the whole of the light"},
                 {"e", "the e-mode alone, at the whole of the light: o + e = 2 x both"},
                 {"fast", "a biaxial crystal's fast mode alone (mode 0, as o)"},
                 {"slow", "a biaxial crystal's slow mode alone (mode 1, as e)"},
                 {"both", "unpolarised light, each mode carrying half"}},
     .defaults = {{F::ViewCli, "both", "the M key cycles"}}},
    {.name = "step", .kind = K::Number,
     .fronts = F::RenderCli | F::TraceCli | F::PyRender | F::PyTrace,
     .help = "Integration step", .field = "MarchSettings::step_voxels",
     .fill = [](const SettingValue& v, SettingRequests& r) { r.march.step_voxels = v.number; },
     .value = "0.5", .min = 0, .max = 4, .min_open = true, .unit = "voxels",
     .keyword = "march.step_voxels", .defaults = {{F::TraceCli, "0.25", ""}}},
    {.name = "tree-min-weight", .kind = K::Number, .fronts = F::TraceCli,
     .help = "Light tree (--tree): the weight below which a branch is cut,",
     .field = "LightTreeSettings::min_weight",
     .fill = [](const SettingValue& v, SettingRequests& r) { r.tree.min_weight = v.number; },
     .value = "1e-06", .min = 1e-15, .max = 1, .keyword = "min_weight"},
    {.name = "tree-max-depth", .kind = K::Integer, .fronts = F::TraceCli,
     .help = "Light tree (--tree): the reflections, refractions and total reflections a branch "
             "takes before it is cut,",
     .field = "LightTreeSettings::max_depth",
     .fill = [](const SettingValue& v, SettingRequests& r) { r.tree.max_depth = v.integer; },
     .value = "64", .min = 1, .max = 1024, .keyword = "max_depth"},
    {.name = "integrator", .kind = K::Choice,
     .fronts = F::RenderCli | F::ViewCli | F::PyRender | F::PyTrace,
     .help = "The march's integrator", .field = "MarchSettings::integrator",
     .fill = [](const SettingValue& v, SettingRequests& r) {
       r.march.integrator = parseIntegrator(v.text);
     },
     .value = "rk4",
     .choices = {{"euler", "first order"},
                 {"midpoint", "second order"},
                 {"rk4", "fourth-order Runge-Kutta"}},
     .keyword = "march.integrator", .defaults = {{F::ViewCli, "rk4", "the I key cycles"}}},
    {.name = "no-skip", .kind = K::Flag, .fronts = F::RenderCli | F::PyRender,
     .help = "Do not cross homogeneous regions in one step", .field = "MarchSettings::skip_empty",
     .fill = [](const SettingValue& v, SettingRequests& r) { r.march.skip_empty = !v.flag; },
     .keyword = "march.skip_empty"},
    {.name = "no-fresnel", .kind = K::Flag, .fronts = F::RenderCli | F::PyRender,
     .help = "Disable Fresnel reflection and transmission losses", .field = "MarchSettings::fresnel",
     .fill = [](const SettingValue& v, SettingRequests& r) { r.march.fresnel = !v.flag; },
     .keyword = "march.fresnel"},
    {.name = "transport", .kind = K::Choice, .fronts = F::RenderCli | F::PyRender,
     .help = "What a view sample follows at an interface (docs/view-renderer.md \"Light "
             "transport\")",
     .field = "MarchSettings::transport",
     .fill = [](const SettingValue& v, SettingRequests& r) {
       r.march.transport = v.text == "single" ? Transport::Single : Transport::Full;
     },
     .value = "full", .says_value = true,
     .choices = {{"full", "reflection or refraction by their Fresnel weights, every path to its end"},
                 {"single", "the transmitted path, external reflections from the environment"}},
     .keyword = "march.transport"},
    {.name = "max-reflections", .kind = K::Integer, .fronts = F::RenderCli | F::PyRender,
     .help = "Fresnel reflections a path follows before it goes on as the transmitted path",
     .field = "MarchSettings::max_reflections",
     .fill = [](const SettingValue& v, SettingRequests& r) { r.march.max_reflections = v.integer; },
     .value = "32", .min = 0, .max = 1024, .keyword = "march.max_reflections"},
    {.name = "threads", .kind = K::Integer, .fronts = F::RenderCli | F::PyRender,
     .help = "CPU threads of the CPU twin, voxelising and the CPU light simulator,",
     .field = "Session::setThreads, LightRequest::threads",
     .fill = [](const SettingValue& v, SettingRequests& r) {
       r.threads = v.integer;
       r.light.threads = v.integer;
     },
     .value = "0", .means = "all cores; the light simulator at most 8", .min = 1, .max = 1024,
     .special = 0.0, .special_means = "for all cores"},
    {.name = "device", .kind = K::Choice, .fronts = F::RenderCli | F::PyRender,
     .help = "The twin that renders", .field = "renderTwin's device",
     .fill = [](const SettingValue& v, SettingRequests& r) { r.device = v.text; },
     .value = "auto", .says_value = true,
     .choices = {{"auto", "the faster twin: the GPU on a GPU; on a CPU Vulkan device such as "
                          "lavapipe the CPU reference for mesh scenes of at least 131072 rays at "
                          "1 spp; docs/view-renderer.md"},
                 {"gpu", "the GPU twin"},
                 {"cpu", "the double-precision CPU reference"}}},
    {.name = "light-bands", .kind = K::Integer, .fronts = F::RenderCli | F::PyLight,
     .help = "Light simulator wavelength bands", .field = "LightRequest::bands",
     .fill = [](const SettingValue& v, SettingRequests& r) { r.light.bands = v.integer; },
     .value = "0", .means = "12 for dispersive scenes, 3 for attenuating ones, else 1", .min = 1,
     .max = 64, .special = 0.0, .special_means = "for the scene's default", .keyword = "bands"},
    {.name = "light-splat", .kind = K::Choice, .fronts = F::RenderCli | F::PyLight,
     .help = "What the light simulator stores in each voxel", .field = "LightRequest::splat",
     .fill = [](const SettingValue& v, SettingRequests& r) { r.light.splat = v.text; },
     .value = "accumulate", .says_value = true,
     .choices = {{"accumulate", "the fluence rate"},
                 {"highest", "the highest patch irradiance"}},
     .keyword = "splat"},
    {.name = "light-device", .kind = K::Choice, .fronts = F::RenderCli | F::PyLight,
     .help = "The twin that simulates the light", .field = "LightRequest::device",
     .fill = [](const SettingValue& v, SettingRequests& r) { r.light.device = v.text; },
     .value = "auto", .says_value = true,
     .choices = {{"auto", "the CPU reference when the Vulkan device is a CPU, e.g. lavapipe, "
                          "where the two are about even: the CPU faster for one run, the GPU for "
                          "a 12-band dispersive scene; else the GPU"},
                 {"gpu", "the GPU twin"},
                 {"cpu", "the double-precision CPU reference"}},
     .keyword = "device",
     .defaults = {{F::PyLight, "gpu", "simulate_light takes gpu or cpu"}}},
    {.name = "caustics", .kind = K::Choice, .fronts = F::RenderCli | F::PyLight,
     .help = "What wavefront patches do at a fold caustic", .field = "LightRequest::caustics",
     .fill = [](const SettingValue& v, SettingRequests& r) { r.light.caustics = v.text; },
     .value = "pass", .says_value = true,
     .choices = {{"pass", "the light continues through a focus"},
                 {"kill", "the patches end there, as Tevs's"}}},
    {.name = "light-step", .kind = K::Number, .fronts = F::RenderCli | F::PyLight,
     .help = "Light simulator time step", .field = "LightRequest::step_voxels",
     .fill = [](const SettingValue& v, SettingRequests& r) { r.light.step_voxels = v.number; },
     .value = "0", .min = 0, .max = 2, .min_open = true, .unit = "voxels", .special = 0.0,
     .special_means = "for the default (0.5)", .keyword = "step_voxels",
     .defaults = {{F::PyLight, "0.5", ""}}},
    {.name = "light-smoothing", .kind = K::Number, .fronts = F::RenderCli | F::PyLight,
     .help = "Width (σ) of the final smoothing of the light volumes",
     .field = "LightRequest::smoothing_voxels",
     .fill = [](const SettingValue& v, SettingRequests& r) {
       r.light.smoothing_voxels = v.number;
     },
     .value = "1", .min = 0, .max = 8, .unit = "voxels", .keyword = "smoothing_voxels"},
    {.name = "light-split", .kind = K::Number, .fronts = F::RenderCli | F::PyLight,
     .help = "Split wavefront patches longer than this,", .field = "LightRequest::split_voxels",
     .fill = [](const SettingValue& v, SettingRequests& r) { r.light.split_voxels = v.number; },
     .value = "1", .min = 0.25, .max = 8, .unit = "voxels", .keyword = "split_voxels"},
    {.name = "max-patches", .kind = K::Integer, .fronts = F::RenderCli | F::PyLight,
     .help = "Most live wavefront patches", .field = "LightRequest::max_patches",
     .fill = [](const SettingValue& v, SettingRequests& r) { r.light.max_patches = v.integer; },
     .value = "1048576", .min = 1024, .max = 16777216, .keyword = "max_patches"},
    {.name = "light-reflections", .kind = K::Integer, .fronts = F::RenderCli | F::PyLight,
     .help = "Generations of reflected wavefronts followed at sharp interfaces",
     .field = "LightRequest::reflections",
     .fill = [](const SettingValue& v, SettingRequests& r) { r.light.reflections = v.integer; },
     .value = "4", .min = 0, .max = 64, .keyword = "reflections"},
};
// clang-format on

}  // namespace

const std::vector<Setting>& settings() { return kSettings; }

const Setting& setting(std::string_view name) {
  for (const Setting& s : kSettings)
    if (name == s.name) return s;
  throw std::logic_error("no setting named '" + std::string(name) + "' in the settings table");
}

SettingDefault settingDefault(const Setting& s, unsigned front) {
  for (const SettingDefault& d : s.defaults)
    if (d.fronts & front) return d;
  return {s.fronts, s.value, s.means};
}

std::string settingKeyword(const Setting& s) {
  if (*s.keyword) return s.keyword;
  std::string k = s.name;
  for (char& c : k)
    if (c == '-') c = '_';
  return k;
}

const Setting* settingByKeyword(std::string_view keyword) {
  for (const Setting& s : kSettings)
    if (keyword == settingKeyword(s)) return &s;
  return nullptr;
}

std::string settingNumber(double v) {
  if (std::abs(v) < 1e15 && v == std::floor(v)) return std::to_string(static_cast<long long>(v));
  char text[32];
  std::snprintf(text, sizeof text, "%.10g", v);
  return text;
}

std::string settingRange(const Setting& s) {
  if (s.kind != SettingKind::Integer && s.kind != SettingKind::Number) return {};
  std::string r = std::string("in ") + (s.min_open ? "(" : "[") + settingNumber(s.min) + ", " +
                  settingNumber(s.max) + "]";
  if (*s.unit) r += std::string(" ") + s.unit;
  if (s.special) r += ", or " + settingNumber(*s.special) + " " + s.special_means;
  return r;
}

std::string settingChoiceList(const Setting& s, const char* last) {
  std::string list;
  for (size_t i = 0; i < s.choices.size(); ++i)
    list += (i == 0                      ? ""
             : i + 1 == s.choices.size() ? last
                                         : ", ") +
            std::string(s.choices[i].name);
  return list;
}

std::string settingHelp(const Setting& s, unsigned front) {
  std::string help = s.help;
  const std::string range = settingRange(s);
  if (!range.empty()) help += " " + range;
  if (!s.choices.empty()) {
    help += ": ";
    for (size_t i = 0; i < s.choices.size(); ++i)
      help += (i == 0                      ? ""
               : i + 1 == s.choices.size() ? (s.kind == SettingKind::Text ? " and " : " or ")
                                           : ", ") +
              std::string(s.choices[i].name) + " (" + s.choices[i].means + ")";
  }
  if (s.kind == SettingKind::Flag) return help;
  const SettingDefault d = settingDefault(s, front);
  help += ". Default: ";
  if (!*d.value) return help + d.means;
  help += d.value;
  return *d.means ? help + " (" + d.means + ")" : help;
}

bool settingInRange(const Setting& s, double v) {
  if (s.special && v == *s.special) return true;
  return (s.min_open ? v > s.min : v >= s.min) && v <= s.max;
}

void checkSettingValue(const Setting& s, double v) {
  if (settingInRange(s, v)) return;
  throw SettingError(s.name, "must be " + settingRange(s) +
                                 (s.says_value ? ", got " + settingNumber(v) : std::string()));
}

void checkSettingChoice(const Setting& s, const std::string& v) {
  for (const SettingChoice& c : s.choices)
    if (v == c.name) return;
  throw SettingError(s.name, "must be " + settingChoiceList(s) +
                                 (s.says_value ? ", got '" + v + "'" : std::string()));
}

}  // namespace eikon
