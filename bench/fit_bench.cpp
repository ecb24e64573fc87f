// Fits per second of `cauchy3` on 50 points, eikon (Ceres + covariance) against SciPy's
// least_squares (bench/fit_peer_scipy.py, Debian python3-scipy), in one run. Prints both rates,
// the ratio eikon/SciPy and the largest coefficient difference (absolute, and in units of the
// coefficient's 1σ).
//
// Data: N-BK7 (SCHOTT Sellmeier) at 50 wavelengths from 400 to 700 nm plus Gaussian noise
// σ = 1e-5 (fixed seed), with a σ column, written to a temporary CSV both programs read.
// Run: build-fit/bench/fit_bench [MIN_SECONDS]   (plain main; no Google Benchmark harness, since
// the peer runs in another process and only the two rates and their ratio matter).
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <string>

#include "anisotropic/dispersion.h"
#include "fitting/fitting.h"
#include "fitting/index_data.h"

int main(int argc, char** argv) {
  double min_seconds = 1.0;
  CLI::App app{
      "Fits per second of cauchy3 on 50 points: eikon (Ceres) against SciPy's least_squares",
      "fit_bench"};
  app.add_option("min_seconds", min_seconds, "Least time to spend fitting, in seconds (default 1)")
      ->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);
  namespace fs = std::filesystem;
  std::string tmpl = (fs::temp_directory_path() / "eikon_fit_bench_XXXXXX").string();
  if (!::mkdtemp(tmpl.data())) {
    std::perror("mkdtemp");
    return 1;
  }
  const fs::path dir = tmpl;
  const std::string csv = (dir / "bk7_50.csv").string();

  const auto bk7 = eikon::Dispersion::sellmeier({1.03961212, 0.231792344, 1.01046945},
                                                {0.00600069867, 0.0200179144, 103.560653});
  std::mt19937_64 rng(2024);
  std::normal_distribution<double> noise(0.0, 1e-5);
  {
    std::ofstream out(csv);
    out.precision(17);
    out << "wavelength_nm,n,sigma\n";
    for (int i = 0; i < 50; ++i) {
      const double l = 400.0 + 300.0 * i / 49.0;
      out << l << "," << bk7.index(l) + noise(rng) << "," << 1e-5 << "\n";
    }
  }
  const eikon::IndexSeries data = eikon::readIndexCsv(csv).modes[0];

  // eikon: the full fitDispersion (start, Ceres solve, ceres::Covariance, summary).
  eikon::FitResult r =
      eikon::fitDispersion(data, {.model = eikon::DispersionModel::Cauchy3});  // warm-up
  int fits = 0;
  const auto t0 = std::chrono::steady_clock::now();
  double elapsed = 0.0;
  while (elapsed < min_seconds || fits < 20) {
    r = eikon::fitDispersion(data, {.model = eikon::DispersionModel::Cauchy3});
    ++fits;
    elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  const double eikon_rate = fits / elapsed;

  // SciPy peer, same data, same run.
  const std::string cmd = "/usr/bin/python3 " + std::string(EIKON_SOURCE_DIR) +
                          "/bench/fit_peer_scipy.py " + csv + " " + std::to_string(min_seconds);
  std::string peer_out;
  if (FILE* p = ::popen(cmd.c_str(), "r")) {
    char buf[4096];
    while (std::fgets(buf, sizeof buf, p)) peer_out += buf;
    if (::pclose(p) != 0) peer_out.clear();
  }
  fs::remove_all(dir);
  if (peer_out.empty()) {
    std::fprintf(stderr, "fit_bench: the SciPy peer failed (%s)\n", cmd.c_str());
    return 1;
  }
  const auto peer = nlohmann::json::parse(peer_out);
  const double scipy_rate = peer["fits_per_s"];
  const auto pc = peer["coeffs"].get<std::vector<double>>();

  std::printf("cauchy3 fit, 50 points (N-BK7 400-700 nm + noise 1e-5), one run\n");
  std::printf("  eikon (Ceres %s, LM + covariance): %10.0f fits/s  (%d fits)\n", "2.1", eikon_rate,
              fits);
  std::printf("  SciPy %s least_squares (lm):   %10.0f fits/s  (%d fits)\n",
              peer["scipy"].get<std::string>().c_str(), scipy_rate, peer["fits"].get<int>());
  std::printf("  ratio eikon/SciPy: %.1fx\n", eikon_rate / scipy_rate);
  double max_abs = 0.0, max_sig = 0.0;
  const char* names[] = {"A", "B", "C"};
  for (int k = 0; k < 3; ++k) {
    const double d = std::abs(r.coeffs[size_t(k)] - pc[size_t(k)]);
    max_abs = std::max(max_abs, d);
    max_sig = std::max(max_sig, d / r.sigma[size_t(k)]);
    std::printf("  %s: eikon % .12e  scipy % .12e  |diff| %.2e (%.1e sigma)\n", names[k],
                r.coeffs[size_t(k)], pc[size_t(k)], d, d / r.sigma[size_t(k)]);
  }
  std::printf("  largest coefficient difference: %.2e (%.1e of its 1-sigma)\n", max_abs, max_sig);
  return 0;
}
