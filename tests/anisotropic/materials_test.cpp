// The shipped material library (materials/*.json) against tests/data/reference/materials.json:
// every file parses with only the documented keys, builds an eikon::Dispersion, and reproduces
// the reference n at F/d/C (and D) to 2e-6 and the Abbe number to 1%.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>
#include <string>

#include "anisotropic/dispersion.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

json readJson(const fs::path& p) {
  std::ifstream f(p);
  if (!f) throw std::runtime_error("cannot open " + p.string());
  return json::parse(f);
}

// The dispersion spec of materials/*.json: a number, {"sellmeier": [B..., C...], "range_nm"},
// {"cauchy": [A, B, C...], "range_nm"} or {"conrady": [n0, A, B], "range_nm"}. Unknown keys are
// errors (as in the scene loader).
eikon::Dispersion parseSpec(const json& j, const std::string& where) {
  if (j.is_number()) return eikon::Dispersion::constant(j.get<double>());
  if (!j.is_object()) throw std::runtime_error(where + ": expected a number or an object");
  for (const auto& [k, v] : j.items())
    if (k != "sellmeier" && k != "cauchy" && k != "conrady" && k != "range_nm")
      throw std::runtime_error(where + ": unknown key " + k);
  eikon::Dispersion d;
  if (int(j.contains("sellmeier")) + int(j.contains("cauchy")) + int(j.contains("conrady")) != 1)
    throw std::runtime_error(where + ": need exactly one of sellmeier, cauchy, conrady");
  if (j.contains("conrady")) {
    const auto c = j.at("conrady").get<std::vector<double>>();
    if (c.size() != 3) throw std::runtime_error(where + ": conrady needs [n0, A, B]");
    d = eikon::Dispersion::conrady(c[0], c[1], c[2]);
  } else if (j.contains("sellmeier")) {
    const auto c = j.at("sellmeier").get<std::vector<double>>();
    if (c.empty() || c.size() % 2 != 0)
      throw std::runtime_error(where + ": sellmeier needs 2k numbers");
    const std::ptrdiff_t k = std::ptrdiff_t(c.size() / 2);
    d = eikon::Dispersion::sellmeier({c.begin(), c.begin() + k}, {c.begin() + k, c.end()});
  } else {
    d = eikon::Dispersion::cauchy(j.at("cauchy").get<std::vector<double>>());
  }
  if (j.contains("range_nm")) {
    const auto r = j.at("range_nm").get<std::vector<double>>();
    if (r.size() != 2) throw std::runtime_error(where + ": range_nm needs [lo, hi]");
    d.withRange(r[0], r[1]);
  }
  return d;
}

void checkAgainst(const eikon::Dispersion& d, const json& ref, const std::string& what) {
  const auto& lines = ref.at("n_at_lines_computed");
  const std::map<std::string, double> nm{{"F", eikon::fraunhofer::F},
                                         {"d", eikon::fraunhofer::d},
                                         {"D", eikon::fraunhofer::D},
                                         {"C", eikon::fraunhofer::C}};
  for (const auto& [line, lambda] : nm) {
    EXPECT_TRUE(d.inRange(lambda)) << what << " " << line;
    EXPECT_NEAR(d.index(lambda), lines.at(line).get<double>(), 2e-6) << what << " at " << line;
  }
}

const std::set<std::string> kIsotropicKeys{"name", "source", "notes", "n"};
const std::set<std::string> kCrystalKeys{"name",
                                         "source",
                                         "notes",
                                         "n_o",
                                         "n_e",
                                         "optic_axis",
                                         "attenuation_o_per_mm",
                                         "attenuation_e_per_mm"};

}  // namespace

TEST(Materials, LibraryMatchesReference) {
  const json ref =
      readJson(fs::path(EIKON_SOURCE_DIR) / "tests" / "data" / "reference" / "materials.json");
  const fs::path dir = fs::path(EIKON_SOURCE_DIR) / "materials";
  std::set<std::string> seen;
  int checked_against_reference = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().extension() != ".json") continue;
    const std::string stem = entry.path().stem().string();
    SCOPED_TRACE(stem);
    const json m = readJson(entry.path());
    seen.insert(stem);
    ASSERT_TRUE(m.is_object());
    EXPECT_EQ(m.at("name").get<std::string>(), stem) << "file name must be <name>.json";
    EXPECT_FALSE(m.at("source").get<std::string>().empty());
    if (m.contains("n_alpha")) continue;  // biaxial: tests/core/scene/biaxial_material_test.cpp
    const bool crystal = m.contains("n_o");
    for (const auto& [k, v] : m.items())
      EXPECT_TRUE((crystal ? kCrystalKeys : kIsotropicKeys).count(k)) << "unknown key " << k;
    const std::string ref_key = stem == "fused-silica" ? "fused_silica" : stem;
    if (!crystal) {
      const auto d = parseSpec(m.at("n"), stem + ".n");
      if (ref.contains(ref_key) && ref.at(ref_key).contains("n")) {
        checkAgainst(d, ref.at(ref_key).at("n"), stem);
        EXPECT_NEAR(d.abbeNumber() / ref.at(ref_key).at("Vd_computed").get<double>(), 1.0, 0.01);
        ++checked_against_reference;
      }
      continue;
    }
    for (const char* k : {"n_e", "optic_axis", "attenuation_o_per_mm", "attenuation_e_per_mm"})
      ASSERT_TRUE(m.contains(k)) << k;
    const auto o = parseSpec(m.at("n_o"), stem + ".n_o");
    const auto e = parseSpec(m.at("n_e"), stem + ".n_e");
    const auto axis = m.at("optic_axis").get<std::vector<double>>();
    ASSERT_EQ(axis.size(), 3u);
    EXPECT_GT(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2], 0.0);
    // [r, g, b] band values or a spectrum over 380–780 nm (ruby; its values are checked against
    // the data in tests/core/scene/measured_spectra_test.cpp).
    for (const char* k : {"attenuation_o_per_mm", "attenuation_e_per_mm"}) {
      if (m.at(k).is_object()) {
        const auto nm = m.at(k).at("wavelength_nm").get<std::vector<double>>();
        const auto a = m.at(k).at("per_mm").get<std::vector<double>>();
        ASSERT_EQ(a.size(), nm.size()) << k;
        ASSERT_FALSE(nm.empty()) << k;
        EXPECT_LE(nm.front(), 380.0) << k;
        EXPECT_GE(nm.back(), 780.0) << k;
        for (double x : a) EXPECT_GE(x, 0.0) << k;
        continue;
      }
      const auto a = m.at(k).get<std::vector<double>>();
      ASSERT_EQ(a.size(), 3u) << k;
      for (double x : a) EXPECT_GE(x, 0.0) << k;
    }
    if (ref.contains(ref_key) && ref.at(ref_key).contains("o")) {
      checkAgainst(o, ref.at(ref_key).at("o"), stem + " o");
      checkAgainst(e, ref.at(ref_key).at("e"), stem + " e");
      EXPECT_NEAR(o.abbeNumber() / ref.at(ref_key).at("Vd_computed").at("o").get<double>(), 1.0,
                  0.01);
      EXPECT_NEAR(e.abbeNumber() / ref.at(ref_key).at("Vd_computed").at("e").get<double>(), 1.0,
                  0.01);
      ++checked_against_reference;
    }
  }
  for (const char* name : {"N-BK7", "N-SF11", "fused-silica", "diamond", "water", "calcite",
                           "quartz", "sapphire", "rutile", "tourmaline"})
    EXPECT_TRUE(seen.count(name)) << "missing materials/" << name << ".json";
  EXPECT_EQ(checked_against_reference, 9) << "all but tourmaline (and ruby) have reference lines";
}

TEST(Materials, TourmalineAndRubyAreDocumentedApproximations) {
  const fs::path dir = fs::path(EIKON_SOURCE_DIR) / "materials";
  const json t = readJson(dir / "tourmaline.json");
  // Mid-range elbaite indices (Handbook of Mineralogy), no dispersion.
  EXPECT_EQ(t.at("n_o").get<double>(), 1.642);
  EXPECT_EQ(t.at("n_e").get<double>(), 1.6225);
  const auto ao = t.at("attenuation_o_per_mm").get<std::vector<double>>();
  const auto ae = t.at("attenuation_e_per_mm").get<std::vector<double>>();
  for (int i = 0; i < 3; ++i)
    EXPECT_GT(ao[size_t(i)], 3.0 * ae[size_t(i)]) << "o absorbed much more than e";
  EXPECT_NE(t.at("notes").get<std::string>().find("ILLUSTRATIVE"), std::string::npos);
  if (fs::exists(dir / "ruby.json")) {  // optional: sapphire indices
    const json r = readJson(dir / "ruby.json");
    const json s = readJson(dir / "sapphire.json");
    EXPECT_EQ(r.at("n_o"), s.at("n_o"));
    EXPECT_EQ(r.at("n_e"), s.at("n_e"));
    EXPECT_NE(r.at("notes").get<std::string>().find("APPROXIMATION"), std::string::npos);
  }
}

TEST(Materials, RutileRewriteIsExact) {
  // Devore's n² = 5.913 + 0.2441/(λ² − 0.0803) rewritten as Sellmeier terms.
  const json r = readJson(fs::path(EIKON_SOURCE_DIR) / "materials" / "rutile.json");
  const auto d = parseSpec(r.at("n_o"), "rutile.n_o");
  for (double nm = 430; nm <= 1530; nm += 50) {
    const double l2 = (nm * 1e-3) * (nm * 1e-3);
    EXPECT_NEAR(d.index(nm), std::sqrt(5.913 + 0.2441 / (l2 - 0.0803)), 1e-14) << nm;
  }
}

TEST(Materials, MoissaniteRewriteMatchesWangWithinItsStatedError) {
  // Wang et al.'s 6H-SiC n² = A + b/(λ² − c) − dλ² as Sellmeier terms, −dλ² by a pole at
  // C = 10⁴ µm²: the difference dλ⁴/(C − λ²) in n² over 2n, below 1.3e-5 at 2325 nm.
  const json m = readJson(fs::path(EIKON_SOURCE_DIR) / "materials" / "moissanite.json");
  struct Wang {
    const char* key;
    double a, b, c, d;
  };
  for (const Wang& w : {Wang{"n_o", 6.57232, 0.1401, 0.03178, 0.02153},
                        Wang{"n_e", 6.7452, 0.15352, 0.03597, 0.02249}}) {
    const auto spec = parseSpec(m.at(w.key), std::string("moissanite.") + w.key);
    for (double nm = 440; nm <= 2320; nm += 40) {
      const double l2 = (nm * 1e-3) * (nm * 1e-3);
      const double n = std::sqrt(w.a + w.b / (l2 - w.c) - w.d * l2);
      EXPECT_NEAR(spec.index(nm), n, w.d * l2 * l2 / (1e4 - l2) / (2 * n) * 1.001 + 1e-14)
          << w.key << " " << nm;
    }
  }
}
