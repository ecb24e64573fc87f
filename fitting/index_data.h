// Measured (or catalogue) refractive indices to fit dispersion models to: a strict CSV reader
// and a reader for refractiveindex.info database YAML files (plus the writer of one formula
// entry, which `eikon fit --export-yaml` uses, so that yaml-cpp stays inside fitting/).
//
// CSV (one header line, then one row per wavelength; `#` starts a comment line, blank lines are
// skipped; fields are separated by commas, surrounding spaces ignored):
//
//   wavelength_nm,n[,sigma]                           isotropic material
//   wavelength_nm,n_o,n_e[,sigma_o,sigma_e]           uniaxial crystal (principal indices)
//
// The first column must name its unit — `wavelength_nm` or `wavelength_um` — because a reader
// that guesses units from magnitudes gets "500" vs "0.5" right and "2" (µm? nm?) wrong. σ is the
// 1σ uncertainty of n (same unit as n); without it every point has equal, unknown weight.
//
// YAML: a refractiveindex.info file (`DATA:` list; each block is `type: tabulated n`,
// `tabulated nk` (k ignored), `tabulated k` (skipped), or `formula 1..9` with `coefficients` and
// `wavelength_range`, or the older `range` key; `SPECS`/`CONDITIONS` and other metadata are
// ignored). Database wavelengths are µm. Formulas are sampled uniformly over their range (or the
// part of it inside the caller's window). All blocks' samples are merged.
//
// Validation, common to both: every value finite, λ > 0, 1 ≤ n ≤ 10, σ > 0, at least two points,
// no repeated wavelength (an error naming both lines). Rows out of order are sorted and a warning
// is recorded in `IndexData::warnings` (the CLI prints it, or fails with --strict).
// Errors are std::invalid_argument / std::runtime_error whose message starts with
// "FILE:LINE:" (CSV) or "FILE: DATA[i].key:" (YAML).
//
// Example:
//   auto data = eikon::readIndexData("bk7.csv");          // picks the reader by extension
//   const eikon::IndexSeries& s = data.modes[0];          // s.lambda_nm, s.n, s.sigma
//
// Common mistakes: a header `wavelength,n` (no unit) is rejected, not guessed; n_e here is the
// principal extraordinary index (E ∥ optic axis), not n_e(θ); a database `tabulated k` file has
// no refractive index in it.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "anisotropic/index_limits.h"

namespace eikon {

/// One dispersion curve n(λ): wavelengths ascending, in nm.
struct IndexSeries {
  std::string label;              ///< "n", "n_o" or "n_e"
  std::vector<double> lambda_nm;  ///< ascending, > 0, no repeats
  std::vector<double> n;          ///< refractive index at lambda_nm
  std::vector<double> sigma;      ///< 1σ of n per point, or empty (unweighted)
  size_t size() const { return lambda_nm.size(); }
  bool weighted() const { return !sigma.empty(); }
};

/// A material's data: one series (isotropic) or two (o then e, uniaxial crystal).
struct IndexData {
  std::string source;                 ///< the file it came from
  std::vector<IndexSeries> modes;     ///< {n} or {n_o, n_e}
  std::vector<std::string> warnings;  ///< recoverable oddities (e.g. rows sorted)
  bool uniaxial() const { return modes.size() == 2; }
};

struct IndexReadOptions {
  /// Keep only points with lo ≤ λ ≤ hi (nm); formulas are sampled inside it.
  std::optional<std::array<double, 2>> window_nm;
  /// Number of uniform samples taken from each `formula` block, 2 … kMaxFormulaSamples.
  int formula_samples = 201;
};

/// Most samples per `formula` block: far more than a smooth formula needs (201 resolve it to
/// 1e-12), and small enough that a typo (2000000000 ran 55 s into std::bad_alloc) is refused
/// before any allocation.
inline constexpr int kMaxFormulaSamples = 100000;

/// Most samples a file's `formula` blocks may be sampled to in all (blocks × formula_samples):
/// the per-block cap alone did not bound it (300 blocks × 100000 samples in a 31 KB file used
/// 3.6 GB). Ten blocks at the most samples, or ~5000 at the default 201; a database file has one
/// or two. Checked, counting every formula block (even one the window leaves out), before any
/// block is sampled.
inline constexpr long long kMaxFormulaSamplesTotal = 1000000;

/// The wavelengths a fit takes, nm: 100 nm (vacuum UV) to 100 µm (far IR) holds every optical
/// measurement the models describe and keeps λ^-2 … λ^-4 (in µm) well scaled; a row outside
/// (1e-300 nm was reported as "rank-deficient start (design matrix)") is refused with its file
/// and line when read, after the window (--range-nm) has dropped what it leaves out.
inline constexpr double kMinFitWavelengthNm = 100.0;
inline constexpr double kMaxFitWavelengthNm = 100000.0;

/// The indices a fit takes: [1, 10], those a scene's materials may have (kMinIndex, kMaxIndex of
/// anisotropic/index_limits.h); data above 10 made a material that `eikon fit` wrote and the scene
/// loader refused. A row outside is refused with its file and line (after the window has dropped
/// what it leaves out).
inline constexpr double kMinFitIndex = kMinIndex;
inline constexpr double kMaxFitIndex = kMaxIndex;

/// Strict CSV reader (format above). Throws with "path:line: message".
IndexData readIndexCsv(const std::string& path, const IndexReadOptions& options = {});
/// Same, from text already in memory (`name` is used in messages).
IndexData parseIndexCsv(const std::string& text, const std::string& name,
                        const IndexReadOptions& options = {});

/// refractiveindex.info YAML reader (format above). Throws with "path: DATA[i].key: message".
IndexData readRefractiveIndexYaml(const std::string& path, const IndexReadOptions& options = {});
IndexData parseRefractiveIndexYaml(const std::string& text, const std::string& name,
                                   const IndexReadOptions& options = {});

/// A series given as arrays (Python's fit_dispersion) checked as a file's rows are (the
/// validation above): equal lengths, every value finite, λ in [kMinFitWavelengthNm,
/// kMaxFitWavelengthNm], n in [kMinFitIndex, kMaxFitIndex], σ finite and > 0, at least two points,
/// no repeated wavelength. Errors (std::invalid_argument) name the point, "point 3: n must be >=
/// 1, got 0.5", or `name` for the whole; points out of order are sorted, with a warning in
/// `warnings` ("NAME: n points are not in ascending wavelength order; sorted them").
IndexSeries checkIndexSeries(const IndexSeries& series, const std::string& name,
                             std::vector<std::string>& warnings);

/// Dispatch on the extension: .csv → CSV; .yml/.yaml → YAML; anything else is an error.
IndexData readIndexData(const std::string& path, const IndexReadOptions& options = {});

/// One refractiveindex.info entry with a single `formula N` block, all fields as the database
/// writes them: wavelength_range "lo hi" in µm, coefficients space-separated.
struct RefractiveIndexFormulaEntry {
  std::string references;
  std::string comments;
  int formula = 0;
  std::string wavelength_range;
  std::string coefficients;
};

/// The entry as YAML text (REFERENCES, COMMENTS, DATA: [{type, wavelength_range, coefficients}]),
/// ending in a newline; yaml-cpp quotes free text as needed, so parseRefractiveIndexYaml reads it
/// back whatever the references say.
std::string formatRefractiveIndexYaml(const RefractiveIndexFormulaEntry& entry);

/// Combine two isotropic data sets into one crystal (o from `ordinary`, e from `extraordinary`).
IndexData combineOrdinaryExtraordinary(IndexData ordinary, IndexData extraordinary);

}  // namespace eikon
