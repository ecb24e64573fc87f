// Spectral rendering cost and accuracy on scenes/prism_bk7.json, measured in one run:
//  1. GPU march time for N = 1, 4, 8, 16 wavelengths per pixel sample, as ratios to N = 1;
//  2. colour error of N = 1, 2, 4, 8, 16, 32 against a reference with N = 128 (same pixels,
//     spp = 1, so pixel positions are identical and only the wavelength sampling differs);
//  3. eikon vs POV-Ray 3.7 (bench/povray/prism_bk7.pov, dispersion_samples 16) at the same
//     resolution, skipped with a message when `povray` is not on PATH (CI does not install it).
//
//  4. hero wavelength sampling on scenes/diamond_brilliant.json: the march time of a 16-wavelength
//     hero render and of a 16-wavelength stratified render against the RGB render (same size and
//     spp), and (at --error-width x --error-height) the colour error of both methods against N and
//     spp, against a converged stratified reference (N = 32, --reference-spp samples).
//
//   spectral_bench [WIDTH HEIGHT]     # default 800 600 (the scene camera); lavapipe on few cores
//                                     # needs minutes there: pass e.g. 160 120 and say so.
//   spectral_bench --only-hero --diamond-width 200 --diamond-height 150 --diamond-resolution 128
//                  --reference-spp 32
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "core/render/view_renderer.h"
#include "core/scene/scene.h"
#include "core/vk/context.h"
#include "core/volume/volume_set.h"

using namespace eikon;

namespace {
double seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
double luminance(const float* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

// RMS |ΔRGB| over the pixels of `mask`, relative to their mean reference luminance.
double colourError(const RenderImage& img, const RenderImage& ref, const std::vector<size_t>& mask,
                   double lumMean) {
  double s2 = 0.0;
  for (size_t i : mask)
    for (int c = 0; c < 3; ++c) {
      const double d = double(img.rgb[3 * i + c]) - ref.rgb[3 * i + c];
      s2 += d * d;
    }
  return std::sqrt(s2 / double(std::max<size_t>(mask.size(), 1))) / lumMean;
}

// Section 0: how well the Cauchy fields carry each library material.
void printCauchyFits(const std::filesystem::path& src) {
  // How well the Cauchy fields carry each library material (least-squares A + B/λ² + C/λ⁴ over
  //    380–780 nm, 1 nm samples): max |n_fit − n| and the Abbe number of the fit vs the model.
  std::printf(
      "0. Cauchy fit of the library materials over 380-780 nm (what the renderer carries)\n"
      "   material          index   model          max|dn|   rms|dn|   V_d model  V_d fit\n");
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(src / "materials"))
    files.push_back(e.path());
  std::sort(files.begin(), files.end());
  for (const auto& f : files) {
    Material m = loadMaterialFile(f);
    for (int k = 0; k < (m.uniaxial ? 2 : 1); ++k) {
      const Dispersion& d = k ? m.n_e : m.n_o;
      auto fit = d.cauchyApproximation(380.0, 780.0);
      auto n = [&](double nm) {
        double il2 = 1e6 / (nm * nm);
        return fit.coeffs[0] + fit.coeffs[1] * il2 + fit.coeffs[2] * il2 * il2;
      };
      double vFit = (n(587.5618) - 1) / (n(486.1327) - n(656.2725));
      std::printf("   %-16s  %-5s  %-13.13s  %9.2e %9.2e  %9.2f  %7.2f\n", m.name.c_str(),
                  m.uniaxial ? (k ? "n_e" : "n_o") : "n", d.describe().c_str(), fit.max_error,
                  fit.rms_error, d.abbeNumber(), vFit);
    }
  }
  std::printf("\n");
}

// Section 4: hero wavelength sampling against stratified sampling and RGB on the brilliant.
int heroSection(vk::Context& ctx, int W, int H, int res, int timeSpp, int refSpp, int eW, int eH) {
  const std::filesystem::path src(EIKON_SOURCE_DIR);
  Scene scene = loadScene(src / "scenes/diamond_brilliant.json");
  scene.volume.resolution = res;
  checkVolumeFits(ctx, makeGrid(scene.volume), scene);
  const VolumeSet vol = voxelize(scene);
  ViewRenderer renderer(ctx, scene, vol);
  auto render = [&](int n, int spp, SpectralSampling sampling, bool small = false) {
    RenderSettings rs;
    rs.width = small ? eW : W;
    rs.height = small ? eH : H;
    rs.spp = spp;
    rs.wavelengths = n;
    rs.sampling = sampling;
    return renderer.render(rs);
  };
  // Warm-up: each pipeline (RGB, spectral) is compiled on its first render.
  render(0, 1, SpectralSampling::Auto);
  render(16, 1, SpectralSampling::Hero);
  std::printf(
      "\n4. Hero wavelength sampling: scenes/diamond_brilliant.json, %dx%d, %d^3, on %s\n"
      "   march time, %d spp          seconds   ratio to RGB   cut samples\n",
      W, H, res, ctx.deviceName().c_str(), timeSpp);
  const RenderImage rgb = render(0, timeSpp, SpectralSampling::Auto);
  const RenderImage hero = render(16, timeSpp, SpectralSampling::Hero);
  const RenderImage strat = render(16, timeSpp, SpectralSampling::Stratified);
  for (const auto& [name, img] : {std::pair<const char*, const RenderImage*>{"RGB", &rgb},
                                  {"16 wavelengths, hero", &hero},
                                  {"16 wavelengths, stratified", &strat}})
    std::printf("   %-27s %8.3f   %12.2f   %lld\n", name, img->seconds, img->seconds / rgb.seconds,
                img->cut_samples);

  // The error study at eW x eH: the reference is stratified with N = 32 (other wavelengths than
  // any N = 16 render's, the same camera jitter as all of them).
  const RenderImage ref = render(32, refSpp, SpectralSampling::Stratified, true);
  std::vector<size_t> mask;
  double lumSum = 0.0;
  for (size_t i = 0; i < size_t(eW) * eH; ++i)
    if (luminance(&ref.rgb[3 * i]) > 0.02) {
      mask.push_back(i);
      lumSum += luminance(&ref.rgb[3 * i]);
    }
  const double lumMean = lumSum / double(std::max<size_t>(mask.size(), 1));
  std::printf(
      "   colour error (RMS |dRGB| / mean luminance) at %dx%d vs the reference (stratified, N = "
      "32, "
      "%d spp, %.1f s; %zu pixels of luminance > 0.02, mean %.3f); time in s\n"
      "   N   spp   hero error   time   stratified error   time\n",
      eW, eH, refSpp, ref.seconds, mask.size(), lumMean);
  for (int n : {4, 16})
    for (int spp : {1, 4, 16}) {
      const RenderImage h = render(n, spp, SpectralSampling::Hero, true);
      const RenderImage st = render(n, spp, SpectralSampling::Stratified, true);
      std::printf("  %3d  %4d  %10.4f  %6.2f  %17.4f  %6.2f\n", n, spp,
                  colourError(h, ref, mask, lumMean), h.seconds,
                  colourError(st, ref, mask, lumMean), st.seconds);
    }
  return 0;
}
}  // namespace

/// Section 2: colour error against the reference over the pixels where it shows the spectrum.
void printColourError(const std::vector<RenderImage>& imgs, const std::vector<int>& ns,
                      const RenderImage& ref, int W, int H) {
  // Colour error over the pixels where the reference shows the spectrum (luminance > 0.1; the
  // sky is 0.02): RMS of |ΔRGB| / mean reference luminance there, and the RMS chromaticity error.
  std::printf(
      "\n2. Colour error vs N (reference N = 128, spp 1, same pixel positions)\n"
      "   N   rel. RMS |dRGB|   mean |dRGB|/lum   (pixels in the spectrum: ");
  std::vector<size_t> mask;
  double lumSum = 0.0;
  for (size_t i = 0; i < size_t(W) * H; ++i)
    if (luminance(&ref.rgb[3 * i]) > 0.1) {
      mask.push_back(i);
      lumSum += luminance(&ref.rgb[3 * i]);
    }
  const double lumMean = lumSum / double(mask.size());
  std::printf("%zu, mean luminance %.3f)\n", mask.size(), lumMean);
  for (size_t k = 0; k < ns.size(); ++k) {
    double s2 = 0.0, s1 = 0.0;
    for (size_t i : mask) {
      double d2 = 0.0;
      for (int c = 0; c < 3; ++c) {
        double d = double(imgs[k].rgb[3 * i + c]) - ref.rgb[3 * i + c];
        d2 += d * d;
      }
      s2 += d2;
      s1 += std::sqrt(d2);
    }
    std::printf("  %3d  %14.4f  %16.4f\n", ns[k], std::sqrt(s2 / double(mask.size())) / lumMean,
                s1 / double(mask.size()) / lumMean);
  }
}

int main(int argc, char** argv) {
  int W = 800, H = 600;
  CLI::App app{
      "Spectral rendering cost and accuracy on scenes/prism_bk7.json (and POV-Ray when on PATH)",
      "spectral_bench"};
  app.add_option("width", W, "Image width (default 800, the scene camera's)")
      ->check(CLI::Range(1, 16384));
  app.add_option("height", H, "Image height (default 600)")->check(CLI::Range(1, 16384));
  int dW = 200, dH = 150, dRes = 128, refSpp = 32, timeSpp = 4, eW = 64, eH = 48;
  bool onlyHero = false;
  app.add_option("--diamond-width", dW, "Section 4 image width (default 200)")
      ->check(CLI::Range(8, 4096));
  app.add_option("--diamond-height", dH, "Section 4 image height (default 150)")
      ->check(CLI::Range(8, 4096));
  app.add_option("--diamond-resolution", dRes, "Section 4 volume resolution (default 128)")
      ->check(CLI::Range(16, 512));
  app.add_option("--reference-spp", refSpp, "Section 4 reference samples per pixel (default 32)")
      ->check(CLI::Range(1, 4096));
  app.add_option("--time-spp", timeSpp, "Section 4 samples per pixel of the timed renders (4)")
      ->check(CLI::Range(1, 4096));
  app.add_option("--error-width", eW, "Section 4 error study width (default 64)")
      ->check(CLI::Range(8, 4096));
  app.add_option("--error-height", eH, "Section 4 error study height (default 48)")
      ->check(CLI::Range(8, 4096));
  app.add_flag("--only-hero", onlyHero, "Run section 4 only");
  CLI11_PARSE(app, argc, argv);
  if (onlyHero) return heroSection(*vk::Context::create(), dW, dH, dRes, timeSpp, refSpp, eW, eH);
  const std::filesystem::path src(EIKON_SOURCE_DIR);
  printCauchyFits(src);

  Scene scene = loadScene(src / "scenes/prism_bk7.json");
  auto ctx = vk::Context::create();
  checkVolumeFits(*ctx, makeGrid(scene.volume), scene);
  auto t0 = std::chrono::steady_clock::now();
  VolumeSet vol = voxelize(scene);
  double tVox = seconds(t0);
  t0 = std::chrono::steady_clock::now();
  ViewRenderer renderer(*ctx, scene, vol);
  double tSetup = seconds(t0);
  std::printf(
      "spectral_bench: scenes/prism_bk7.json, %dx%d, %d^3-class volume (voxelise %.2f s, upload "
      "%.2f s) on %s\n",
      W, H, scene.volume.resolution, tVox, tSetup, ctx->deviceName().c_str());

  auto render = [&](int n) {
    RenderSettings rs;
    rs.width = W;
    rs.height = H;
    rs.wavelengths = n;
    rs.sampling = SpectralSampling::Stratified;  // sections 1-2 as before hero sampling; see 4
    return renderer.render(rs);
  };
  render(1);  // warm-up: the first render pays pipeline creation / shader JIT (13 s at 160x120 on
              // lavapipe)
  std::vector<int> ns = {1, 2, 4, 8, 16, 32};
  std::vector<RenderImage> imgs;
  for (int n : ns) imgs.push_back(render(n));
  RenderImage ref = render(128);

  std::printf(
      "\n1. GPU cost of N wavelengths (march time, ratio to N = 1)\n   N   seconds   ratio   "
      "ns/ray\n");
  const double t1 = imgs[0].seconds;
  for (size_t k = 0; k < ns.size(); ++k)
    std::printf("  %3d  %8.3f  %6.2f  %7.1f\n", ns[k], imgs[k].seconds, imgs[k].seconds / t1,
                1e9 * imgs[k].seconds / (double(W) * H * ns[k]));
  std::printf("  128  %8.3f  %6.2f  %7.1f\n", ref.seconds, ref.seconds / t1,
              1e9 * ref.seconds / (double(W) * H * 128));

  printColourError(imgs, ns, ref, W, H);

  if (int rc = heroSection(*ctx, dW, dH, dRes, timeSpp, refSpp, eW, eH); rc != 0) return rc;

  std::printf("\n3. eikon vs POV-Ray 3.7 (same view, %dx%d, 1 sample per pixel, 16 wavelengths)\n",
              W, H);
  if (std::system("command -v povray > /dev/null 2>&1") != 0) {
    std::printf("   povray not found on PATH: peer skipped (apt-get install povray to run it)\n");
    return 0;
  }
  const size_t k16 = 4;
  std::filesystem::path out =
      std::filesystem::temp_directory_path() / "eikon_spectral_bench_povray.png";
  std::string cmd = "povray +I" + (src / "bench/povray/prism_bk7.pov").string() + " +O" +
                    out.string() + " +W" + std::to_string(W) + " +H" + std::to_string(H) +
                    " -A -D -V +FN -GA > /dev/null 2>&1";
  t0 = std::chrono::steady_clock::now();
  int rc = std::system(cmd.c_str());
  double tPov = seconds(t0);
  if (rc != 0) {
    std::printf("   povray failed (exit %d): %s\n", rc, cmd.c_str());
    return 1;
  }
  const double tEikon = imgs[k16].seconds, tEikonAll = tVox + tSetup + tEikon;
  std::printf("   POV-Ray (parse + photons + trace, wall): %.3f s\n", tPov);
  std::printf("   eikon N = 16 march: %.3f s   -> eikon/POV-Ray %.2f\n", tEikon, tEikon / tPov);
  std::printf("   eikon N = 16 incl. voxelise + upload: %.3f s -> eikon/POV-Ray %.2f\n", tEikonAll,
              tEikonAll / tPov);
  return 0;
}
