// `eikon fit DATA [E_DATA] [--model M] [--loss huber:δ] [--json] [--export-yaml FILE] [--strict]
//             [--range-nm LO,HI] [--samples N] [--name NAME] -o MATERIAL.json`
//
// Fits a dispersion model to refractive-index data (CSV or refractiveindex.info YAML; see
// fitting/index_data.h) and writes the material file the renderer loads. A CSV with n_o,n_e
// columns, or two single-index files (ordinary first, then extraordinary), makes a uniaxial
// crystal, fitted per mode. Prints a table (or, with --json, one JSON object) on stdout;
// warnings go to stderr as "eikon: warning: ..." (errors with --strict). Output files are
// written to a temporary file beside the target and renamed, so a failed run leaves nothing.

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "apps/commands.h"
#include "core/io/atomic_write.h"
#include "fitting/fitting.h"
#include "fitting/index_data.h"

namespace eikon::cli {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct FitArgs {
  std::vector<std::string> data;
  std::string model = "cauchy3";
  std::string loss;
  bool json_out = false;
  std::string export_yaml;
  bool strict = false;
  std::string output;
  std::string range_nm;
  bool range_given = false;  ///< --range-nm was given, with any value (an empty one is refused)
  int samples = 201;
  std::string name;
};

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

json nullable(const std::optional<double>& v) { return v ? json(*v) : json(nullptr); }

std::string lossName(const FitResult& r) {
  return r.huber_delta ? "huber:" + fmt("%g", *r.huber_delta) : "none";
}

bool isCauchy(DispersionModel m) {
  return m == DispersionModel::Cauchy2 || m == DispersionModel::Cauchy3;
}

// The renderer's GPU fields hold Cauchy {A, B, C}; every other model reaches them through
// Dispersion::cauchyApproximation over the visible window (core/volume/volume_set.cpp), so fit
// states what that approximation costs instead of approximating silently.
constexpr double kRenderLoNm = 380.0, kRenderHiNm = 780.0;
CauchyApproximation rendererApproximation(const FitResult& r) {
  return r.dispersion().cauchyApproximation(kRenderLoNm, kRenderHiNm);
}

json approximationJson(const FitResult& r) {
  const CauchyApproximation ap = rendererApproximation(r);
  return {{"cauchy", ap.coeffs},
          {"window_nm", {kRenderLoNm, kRenderHiNm}},
          {"max_abs_dn", ap.max_error},
          {"rms_abs_dn", ap.rms_error}};
}

json fitStats(const FitResult& r) {
  json j = {{"chi2_reduced", nullable(r.chi2_reduced)},
            {"rms", r.rms},
            {"max_residual", r.max_residual},
            {"residual_std", r.residual_std},
            {"n_F", r.n_F},
            {"n_d", r.n_d},
            {"n_C", r.n_C},
            {"abbe", r.abbe},
            {"points", r.points},
            {"weighted", r.weighted},
            {"model", modelName(r.model)},
            {"loss", lossName(r)}};
  if (!isCauchy(r.model)) j["renderer_cauchy"] = approximationJson(r);
  return j;
}

// {"cauchy": [...], "range_nm": [...], "sigma": [...]} (or "sellmeier": all B then all C, or
// "conrady": [n0, A, B]); the scene loader reads each of them (core/scene/scene.cpp).
json materialIndex(const FitResult& r) {
  const char* key = isCauchy(r.model)                     ? "cauchy"
                    : r.model == DispersionModel::Conrady ? "conrady"
                                                          : "sellmeier";
  return {{key, r.coeffs}, {"range_nm", r.range_nm}, {"sigma", r.sigma}};
}

json reportMode(const FitResult& r) {
  json coeffs = json::object(), sig = json::object();
  const auto names = parameterNames(r.model);
  for (size_t k = 0; k < names.size(); ++k)
    coeffs[names[k]] = r.coeffs[k], sig[names[k]] = r.sigma[k];
  json j = fitStats(r);
  j["coefficients"] = coeffs;
  j["sigma"] = sig;
  j["covariance"] = r.covariance;
  j["range_nm"] = r.range_nm;
  j["iterations"] = r.iterations;
  return j;
}

void printTable(std::ostream& os, const IndexData& data, const std::vector<FitResult>& fits) {
  const FitResult& f0 = fits.front();
  os << "eikon fit: " << data.source << ", model " << modelName(f0.model) << ", loss "
     << lossName(f0) << "\n";
  for (const FitResult& r : fits) {
    os << "\n"
       << r.label << ": " << r.points << " points, " << fmt("%g", r.range_nm[0]) << "-"
       << fmt("%g", r.range_nm[1]) << " nm, "
       << (r.weighted ? "weighted by sigma" : "unweighted (sigma of n estimated from the scatter)")
       << "\n";
    const auto names = parameterNames(r.model);
    for (size_t k = 0; k < names.size(); ++k)
      os << "  " << names[k] << std::string(4 - std::min<size_t>(4, names[k].size()), ' ') << "= "
         << fmt("%15.8e", r.coeffs[k]) << "  +/- " << fmt("%.2e", r.sigma[k]) << "\n";
    os << "  residual rms " << fmt("%.3e", r.rms) << ", max " << fmt("%.3e", r.max_residual)
       << ", chi2_red "
       << (r.chi2_reduced ? fmt("%.3f", *r.chi2_reduced) : std::string("- (no sigma column)"))
       << "\n";
    os << "  n_F " << fmt("%.6f", r.n_F) << "  n_d " << fmt("%.6f", r.n_d) << "  n_C "
       << fmt("%.6f", r.n_C) << "  V_d " << fmt("%.2f", r.abbe) << "\n";
    if (!isCauchy(r.model)) {
      const CauchyApproximation ap = rendererApproximation(r);
      os << "  renderer: cauchy [" << fmt("%.8e", ap.coeffs[0]) << ", " << fmt("%.8e", ap.coeffs[1])
         << ", " << fmt("%.8e", ap.coeffs[2]) << "] over " << fmt("%g", kRenderLoNm) << "-"
         << fmt("%g", kRenderHiNm) << " nm, |dn| max " << fmt("%.3e", ap.max_error) << ", rms "
         << fmt("%.3e", ap.rms_error) << "\n";
    }
  }
}

// refractiveindex.info entry for one fitted mode: formula 5 (Cauchy / Conrady) or 2 (Sellmeier).
std::string yamlEntry(const FitResult& r, const std::string& source) {
  std::ostringstream coeffs;
  coeffs.precision(12);
  int formula = 5;
  switch (r.model) {
    case DispersionModel::Cauchy2:
    case DispersionModel::Cauchy3:
      for (size_t k = 0; k < r.coeffs.size(); ++k)
        coeffs << (k ? " " : "") << r.coeffs[k] << (k ? " " + std::to_string(-2 * int(k)) : "");
      break;
    case DispersionModel::Conrady:
      coeffs << r.coeffs[0] << " " << r.coeffs[1] << " -1 " << r.coeffs[2] << " -3.5";
      break;
    default: {
      formula = 2;
      const size_t K = r.coeffs.size() / 2;
      coeffs << 0;
      for (size_t i = 0; i < K; ++i) coeffs << " " << r.coeffs[i] << " " << r.coeffs[K + i];
    }
  }
  std::ostringstream comment;
  comment << "1-sigma: ";
  const auto names = parameterNames(r.model);
  for (size_t k = 0; k < names.size(); ++k)
    comment << (k ? ", " : "") << names[k] << " " << fmt("%.3e", r.sigma[k]);
  comment << "; residual rms " << fmt("%.3e", r.rms) << ", max " << fmt("%.3e", r.max_residual);
  RefractiveIndexFormulaEntry entry;
  entry.references =
      "eikon fit of " + source + ", model " + modelName(r.model) + " (" + r.label + ")";
  entry.comments = comment.str();
  entry.formula = formula;
  entry.wavelength_range =
      fmt("%.10g", r.range_nm[0] * 1e-3) + " " + fmt("%.10g", r.range_nm[1] * 1e-3);
  entry.coefficients = coeffs.str();
  return formatRefractiveIndexYaml(entry);
}

// The scene loader refuses a material whose index anywhere in 380–780 nm (1 nm steps) is not a
// finite number in [1, 10] (checkIndexInRange, core/scene/scene.cpp); data in [1, 10] can still
// fit a curve that leaves it there (extrapolated from IR data, say), so the material to be written
// is checked the same way and refused, naming the data file, rather than written unloadable.
void checkLoadable(const FitResult& r, const std::string& file) {
  const Dispersion d = r.dispersion();
  for (double l = kRenderLoNm; l <= kRenderHiNm; l += 1.0) {
    const double n = d.index(l);
    if (!(n >= kMinFitIndex && n <= kMaxFitIndex))
      throw CliError(file + ": the fitted " + r.label + " is " + fmt("%g", n) + " at " +
                     fmt("%g", l) + " nm, outside [1, 10] where a scene needs it (380-780 nm); " +
                     "the material would not load, so it is not written");
  }
}

// "calcite.yml" + "o" → "calcite-o.yml".
std::string withSuffix(const std::string& path, const std::string& suffix) {
  fs::path p(path);
  return (p.parent_path() / (p.stem().string() + "-" + suffix + p.extension().string())).string();
}

// An output that is one of the inputs (the same file by device and inode, however it is spelt:
// "./", symbolic or hard links) would be replaced by a fit of itself, and two outputs naming one
// file would overwrite each other: both are refused before anything is written.
void checkOutputs(const std::vector<std::string>& inputs,
                  const std::vector<std::pair<std::string, std::string>>& files) {
  for (size_t i = 0; i < files.size(); ++i) {
    const std::string& out = files[i].first;
    std::error_code ec;
    for (const std::string& in : inputs)
      if (fs::equivalent(in, out, ec))
        throw CliError(out + ": the output is the input data file " + in +
                       " (it would be overwritten); choose another path");
    for (size_t j = 0; j < i; ++j) {
      const bool same = fs::equivalent(files[j].first, out, ec) ||
                        fs::weakly_canonical(files[j].first, ec) == fs::weakly_canonical(out, ec);
      if (same)
        throw CliError(out +
                       ": named by two outputs (-o and --export-yaml); choose different paths");
    }
  }
}

// The material and YAML files are written as one set through core/io (temporaries renamed only
// when all were written; missing folders created, and removed again when the write fails).
void writeAllAtomically(const std::vector<std::pair<std::string, std::string>>& files) {
  std::vector<OutputFile> set;
  for (const auto& [path, content] : files) set.push_back({path, bytesWriter(content)});
  try {
    writeFilesTogether(set);
  } catch (const std::runtime_error& e) {
    throw CliError(e.what());
  }
}

std::optional<double> parseLoss(const std::string& s) {
  if (s.empty() || s == "none") return std::nullopt;
  const std::string prefix = "huber:";
  if (s.rfind(prefix, 0) != 0)
    throw CliError("--loss must be 'huber:DELTA' or 'none', got '" + s + "'");
  const std::string v = s.substr(prefix.size());
  double d = 0.0;
  auto [ptr, ec] = std::from_chars(v.data(), v.data() + v.size(), d);
  if (ec != std::errc() || ptr != v.data() + v.size() || !(std::isfinite(d) && d > 0))
    throw CliError("--loss huber:DELTA needs a number DELTA > 0, got '" + v + "'");
  if (!(d >= kMinHuberDelta && d <= kMaxHuberDelta))
    throw CliError("--loss huber:DELTA must be in [" + fmt("%g", kMinHuberDelta) + ", " +
                   fmt("%g", kMaxHuberDelta) +
                   "] (residual units: sigma with a sigma column, else index), got '" + v + "'");
  return d;
}

void run(const FitArgs& a) {
  FitOptions fo;
  fo.model = parseDispersionModel(a.model);
  fo.huber_delta = parseLoss(a.loss);
  // Refused before reading (the crystal's FILE-o/-e YAML names are checked again once known).
  std::vector<std::pair<std::string, std::string>> named;
  for (const std::string* o : {&a.output, &a.export_yaml})
    if (!o->empty()) named.emplace_back(*o, "");
  checkOutputs(a.data, named);
  IndexReadOptions ro;
  if (a.samples < 2 || a.samples > kMaxFormulaSamples)
    throw CliError("--samples must be in [2, " + std::to_string(kMaxFormulaSamples) +
                   "] (samples per refractiveindex.info formula block), got " +
                   std::to_string(a.samples));
  ro.formula_samples = a.samples;
  if (a.range_given) {
    const std::vector<double> r = parseNumberList(a.range_nm, "--range-nm", 2, "LO,HI (nm)");
    if (!(r[0] > 0 && r[1] > r[0]))
      throw CliError("--range-nm must satisfy 0 < LO < HI (nm), got '" + a.range_nm + "'");
    ro.window_nm = std::array<double, 2>{r[0], r[1]};
  }
  IndexData data = readIndexData(a.data[0], ro);
  if (a.data.size() == 2) {
    data = combineOrdinaryExtraordinary(std::move(data), readIndexData(a.data[1], ro));
  }
  for (const std::string& w : data.warnings) {
    if (a.strict) throw CliError(w + " (--strict)");
    std::fprintf(stderr, "eikon: warning: %s\n", w.c_str());
  }

  std::vector<FitResult> fits;
  for (size_t k = 0; k < data.modes.size(); ++k) {
    // A fit's failure names the data file it came from (two files: o from the first, e from the
    // second), as a reading error does: "rank-deficient start" alone did not.
    const std::string& file = a.data[a.data.size() == 2 ? k : 0];
    try {
      fits.push_back(fitDispersion(data.modes[k], fo));
    } catch (const std::exception& e) {
      throw CliError(file + ": " + e.what());
    }
  }
  for (const FitResult& r : fits)
    for (const std::string& w : r.warnings) {
      if (a.strict) throw CliError(w + " (--strict)");
      std::fprintf(stderr, "eikon: warning: %s\n", w.c_str());
    }

  const std::string name = !a.name.empty() ? a.name : fs::path(a.data[0]).stem().string();
  const std::string source = "eikon fit of " + data.source + ", model " + modelName(fo.model);
  std::vector<std::pair<std::string, std::string>> files;
  if (!a.output.empty()) {
    for (size_t k = 0; k < fits.size(); ++k)
      checkLoadable(fits[k], a.data[a.data.size() == 2 ? k : 0]);
    json m = {{"name", name}, {"source", source}};
    if (!data.uniaxial()) {
      m["n"] = materialIndex(fits[0]);
      m["fit"] = fitStats(fits[0]);
    } else {
      m["n_o"] = materialIndex(fits[0]);
      m["n_e"] = materialIndex(fits[1]);
      m["fit"] = {{"model", modelName(fo.model)},
                  {"loss", lossName(fits[0])},
                  {"n_o", fitStats(fits[0])},
                  {"n_e", fitStats(fits[1])}};
    }
    files.emplace_back(a.output, m.dump(2) + "\n");
  }
  if (!a.export_yaml.empty()) {
    if (!data.uniaxial()) {
      files.emplace_back(a.export_yaml, yamlEntry(fits[0], data.source));
    } else {
      files.emplace_back(withSuffix(a.export_yaml, "o"), yamlEntry(fits[0], data.source));
      files.emplace_back(withSuffix(a.export_yaml, "e"), yamlEntry(fits[1], data.source));
    }
  }
  checkOutputs(a.data, files);
  writeAllAtomically(files);

  if (a.json_out) {
    json modes = json::object();
    json warnings = data.warnings;
    for (const FitResult& r : fits)
      for (const std::string& w : r.warnings) warnings.push_back(w);
    for (const FitResult& r : fits) modes[r.label] = reportMode(r);
    json out = {{"source", data.source},
                {"model", modelName(fo.model)},
                {"loss", lossName(fits[0])},
                {"modes", modes},
                {"warnings", warnings}};
    json written = json::array();
    for (auto& f : files) written.push_back(f.first);
    out["written"] = written;
    std::cout << out.dump(2) << "\n";
  } else {
    printTable(std::cout, data, fits);
    for (auto& f : files) std::cout << "wrote " << f.first << "\n";
  }
}

// CLI11 2.1 shows a positional with expected(1, 2) as "data(1x)"; the fit's usage line names what
// it takes instead: "DATA [E_DATA]".
class FitFormatter final : public CLI::Formatter {
 public:
  std::string make_option_usage(const CLI::Option* opt) const override {
    if (opt->get_name() == "DATA") return "DATA [E_DATA]";
    return CLI::Formatter::make_option_usage(opt);
  }
};

}  // namespace

void addFitCommand(CLI::App& app) {
  auto args = std::make_shared<FitArgs>();
  auto* sub = app.add_subcommand(
      "fit", "Fit a dispersion model to refractive-index data (CSV or refractiveindex.info YAML)");
  sub->formatter(std::make_shared<FitFormatter>());
  sub->add_option(
         "DATA", args->data,
         "one or two index files (.csv, or refractiveindex.info .yml). One: n, or a CSV with "
         "n_o,n_e "
         "columns (a uniaxial crystal). Two single-index files: ordinary (DATA) then extraordinary "
         "(E_DATA)")
      ->type_name("FILE")
      ->required()
      ->expected(1, 2);
  sub->add_option("--model", args->model,
                  "cauchy2 | cauchy3 | sellmeier1 | sellmeier2 | sellmeier3 | conrady")
      ->capture_default_str();
  sub->add_option(
      "--loss", args->loss,
      "robust loss 'huber:DELTA' (DELTA in [1e-9, 100]: sigma units with a sigma column, else "
      "index units)");
  sub->add_flag("--json", args->json_out, "print the fit as one JSON object instead of a table");
  sub->add_option("--export-yaml", args->export_yaml,
                  "also write a refractiveindex.info formula entry (crystals: FILE-o/-e)");
  sub->add_flag("--strict", args->strict, "treat warnings (e.g. unsorted rows) as errors");
  sub->add_option("-o,--output", args->output, "material JSON file for the renderer");
  CLI::Option* range = sub->add_option("--range-nm", args->range_nm,
                                       "fit only LO,HI nm (formulas are sampled inside it)");
  sub->add_option("--samples", args->samples,
                  "samples per refractiveindex.info formula block (2 to 100000)")
      ->capture_default_str();
  sub->add_option("--name", args->name, "material name (default: the DATA file's stem)");
  sub->callback([args, range] {
    args->range_given = range->count() > 0;
    try {
      run(*args);
    } catch (const CliError&) {
      throw;
    } catch (const std::exception& e) {
      throw CliError(e.what());
    }
  });
}

}  // namespace eikon::cli
