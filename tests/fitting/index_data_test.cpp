// Index data readers: the strict CSV reader, refractiveindex.info YAML (tabulated and formula
// blocks, old and new keys), and the nine database formulas against materials.json and against
// the formulas written out by hand.
#include "fitting/index_data.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "anisotropic/dispersion.h"
#include "fitting/refractiveindex_formula.h"

namespace eikon {
namespace {

// Expects `fn` to throw std::invalid_argument whose message contains every piece of `parts`.
template <class F>
void expectError(F fn, std::initializer_list<const char*> parts) {
  try {
    fn();
    ADD_FAILURE() << "expected an error containing '" << *parts.begin() << "'";
  } catch (const std::invalid_argument& e) {
    const std::string msg = e.what();
    for (const char* p : parts) EXPECT_NE(msg.find(p), std::string::npos) << "message: " << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line: " << msg;
  }
}

TEST(IndexCsv, IsotropicWithSigma) {
  const IndexData d = parseIndexCsv(
      "# BK7 by hand\nwavelength_nm, n, sigma\n486.1327,1.522376,1e-5\n\n"
      "587.5618, 1.516800 ,2e-5\r\n656.2725,1.514322,1e-5\n",
      "bk7.csv");
  ASSERT_EQ(d.modes.size(), 1u);
  EXPECT_FALSE(d.uniaxial());
  EXPECT_EQ(d.modes[0].label, "n");
  EXPECT_EQ(d.modes[0].size(), 3u);
  EXPECT_DOUBLE_EQ(d.modes[0].n[1], 1.5168);
  EXPECT_DOUBLE_EQ(d.modes[0].sigma[1], 2e-5);
  EXPECT_TRUE(d.warnings.empty());
}

TEST(IndexCsv, MicrometresAreConverted) {
  const IndexData d = parseIndexCsv("wavelength_um,n\n0.5,1.52\n0.6,1.51\n", "x.csv");
  EXPECT_DOUBLE_EQ(d.modes[0].lambda_nm[0], 500.0);
  EXPECT_DOUBLE_EQ(d.modes[0].lambda_nm[1], 600.0);
  EXPECT_FALSE(d.modes[0].weighted());
}

TEST(IndexCsv, CrystalColumns) {
  const IndexData d = parseIndexCsv(
      "wavelength_nm,n_o,n_e,sigma_o,sigma_e\n486.1,1.6676,1.4905,1e-4,2e-4\n656.3,1.6545,1.4843,"
      "1e-4,2e-4\n",
      "c.csv");
  ASSERT_TRUE(d.uniaxial());
  EXPECT_EQ(d.modes[0].label, "n_o");
  EXPECT_EQ(d.modes[1].label, "n_e");
  EXPECT_DOUBLE_EQ(d.modes[1].n[0], 1.4905);
  EXPECT_DOUBLE_EQ(d.modes[1].sigma[1], 2e-4);
}

TEST(IndexCsv, UnsortedRowsAreSortedWithOneWarning) {
  const IndexData d = parseIndexCsv(
      "wavelength_nm,n_o,n_e\n600,1.65,1.48\n500,1.66,1.49\n550,1.655,1.485\n", "u.csv");
  EXPECT_EQ(d.modes[0].lambda_nm, (std::vector<double>{500, 550, 600}));
  EXPECT_EQ(d.modes[1].n, (std::vector<double>{1.49, 1.485, 1.48}));
  ASSERT_EQ(d.warnings.size(), 1u);
  EXPECT_NE(d.warnings[0].find("sorted"), std::string::npos);
}

TEST(IndexCsv, BadInputIsOneClearError) {
  auto csv = [](const std::string& text) { return [text] { parseIndexCsv(text, "bad.csv"); }; };
  expectError(csv(""), {"bad.csv", "empty"});
  expectError(csv("# only a comment\n\n"), {"bad.csv", "empty"});
  expectError(csv("wavelength_nm,n\n"), {"bad.csv", "no data"});
  expectError(csv("wavelength_nm,n\n500,1.5\n"), {"bad.csv", "one data point"});
  expectError(csv("wavelength_nm,n\n500,1.5\n600,nan\n"), {"bad.csv:3", "not a finite"});
  expectError(csv("wavelength_nm,n\n500,1.5\n600,inf\n"), {"bad.csv:3", "not a finite"});
  expectError(csv("wavelength_nm,n\n0,1.5\n600,1.4\n"), {"bad.csv:2", "wavelength must be > 0"});
  expectError(csv("wavelength_nm,n\n-500,1.5\n600,1.4\n"), {"bad.csv:2", "wavelength must be > 0"});
  expectError(csv("wavelength_nm,n\n500,1.5\n600,0.9\n"), {"bad.csv:3", "n must be >= 1"});
  expectError(csv("wavelength_nm,n\n500,1.5\n600,1.4\n500,1.5\n"),
              {"bad.csv:4", "duplicate wavelength 500", "bad.csv:2"});
  expectError(csv("wavelength,n\n500,1.5\n600,1.4\n"),
              {"bad.csv:1", "wavelength_nm", "never guessed"});
  expectError(csv("500,1.5\n600,1.4\n"), {"bad.csv:1", "missing header"});
  expectError(csv("wavelength_nm,index\n500,1.5\n"), {"bad.csv:1", "unrecognised header"});
  expectError(csv("wavelength_nm,n\n500,1.5,3\n600,1.4\n"), {"bad.csv:2", "expected 2 fields"});
  expectError(csv("wavelength_nm,n\n500,1.5x\n600,1.4\n"), {"bad.csv:2", "not a number"});
  expectError(csv("wavelength_nm,n\n500,\n600,1.4\n"), {"bad.csv:2", "not a number"});
  expectError(csv("wavelength_nm,n,sigma\n500,1.5,0\n600,1.4,1e-4\n"), {"bad.csv:2", "sigma"});
}

TEST(IndexCsv, MissingFileIsAnError) {
  EXPECT_THROW(readIndexCsv("/nonexistent/x.csv"), std::runtime_error);
  EXPECT_THROW(readIndexData("data.txt"), std::invalid_argument);
}

TEST(IndexCsv, WindowKeepsOnlyPointsInside) {
  IndexReadOptions o;
  o.window_nm = std::array<double, 2>{450.0, 650.0};
  const IndexData d =
      parseIndexCsv("wavelength_nm,n\n400,1.53\n500,1.52\n600,1.51\n700,1.50\n", "w.csv", o);
  EXPECT_EQ(d.modes[0].lambda_nm, (std::vector<double>{500, 600}));
}

// materials.json n_at_lines_computed were computed from the same database formulas (1: fused
// silica, diamond, sapphire; 2: glasses, calcite, quartz, water; 4: rutile) and printed to six
// decimals, so agreement to 6e-7 (rounding) is required.
TEST(RefractiveIndexFormula, MatchesMaterialsJsonAtFraunhoferLines) {
  std::ifstream in(std::string(EIKON_SOURCE_DIR) + "/tests/data/reference/materials.json");
  ASSERT_TRUE(in.good());
  const auto m = nlohmann::json::parse(in);
  int checked = 0;
  for (auto& [name, mat] : m.items()) {
    if (name == "_meta") continue;
    for (const char* mode : {"n", "o", "e"}) {
      if (!mat.contains(mode) || !mat[mode].contains("formula_type")) continue;
      const RefractiveIndexFormula f(mat[mode]["formula_type"].get<int>(),
                                     mat[mode]["coefficients"].get<std::vector<double>>());
      const auto& lines = mat[mode]["n_at_lines_computed"];
      for (auto [line, nm] :
           {std::pair{"F", fraunhofer::F}, {"d", fraunhofer::d}, {"C", fraunhofer::C}}) {
        EXPECT_NEAR(f.index(nm * 1e-3), lines[line].get<double>(), 6e-7)
            << name << " " << mode << " " << line;
        ++checked;
      }
    }
  }
  EXPECT_GE(checked, 3 * 14);
}

// The other formulas, against the database definitions written out by hand.
TEST(RefractiveIndexFormula, AllNineFormulasByHand) {
  const double l = 0.55, l2 = l * l;
  // 1 and 2 are the same curve when formula 1's poles are the square roots of formula 2's.
  EXPECT_NEAR(
      RefractiveIndexFormula(1, {0.1, 1.0, std::sqrt(0.01), 0.5, std::sqrt(100.0)}).index(l),
      RefractiveIndexFormula(2, {0.1, 1.0, 0.01, 0.5, 100.0}).index(l), 1e-14);
  EXPECT_NEAR(RefractiveIndexFormula(2, {0.1, 1.0, 0.01}).index(l),
              std::sqrt(1.1 + l2 / (l2 - 0.01)), 1e-14);
  EXPECT_NEAR(RefractiveIndexFormula(3, {2.25, 0.01, -2, -0.001, 2}).index(l),
              std::sqrt(2.25 + 0.01 / l2 - 0.001 * l2), 1e-14);
  EXPECT_NEAR(RefractiveIndexFormula(4, {2.0, 0.1, 2, 0.2, 2, 0.05, 0, 3, 2, 0.01, -2}).index(l),
              std::sqrt(2.0 + 0.1 * l2 / (l2 - 0.04) + 0.05 / (l2 - 9.0) + 0.01 / l2), 1e-14);
  // 5 with exponents −2, −4 is eikon's Cauchy.
  EXPECT_NEAR(RefractiveIndexFormula(5, {1.5, 4.3e-3, -2, -1.9e-5, -4}).index(l),
              Dispersion::cauchy({1.5, 4.3e-3, -1.9e-5}).index(550.0), 1e-14);
  EXPECT_NEAR(RefractiveIndexFormula(6, {1e-4, 0.02, 150.0}).index(l),
              1.0 + 1e-4 + 0.02 / (150.0 - 1.0 / l2), 1e-14);
  const double q = 1.0 / (l2 - 0.028);
  EXPECT_NEAR(RefractiveIndexFormula(7, {1.5, 0.01, 0.001, -0.002, 1e-4, -1e-6}).index(l),
              1.5 + 0.01 * q + 0.001 * q * q - 0.002 * l2 + 1e-4 * l2 * l2 - 1e-6 * l2 * l2 * l2,
              1e-14);
  // 8: Lorentz–Lorenz; with only C1 = (n²−1)/(n²+2) it returns n.
  EXPECT_NEAR(RefractiveIndexFormula(8, {(2.25 - 1) / (2.25 + 2)}).index(l), 1.5, 1e-14);
  EXPECT_NEAR(
      RefractiveIndexFormula(9, {2.0, 0.05, 0.03, 0.01, 0.3, 0.02}).index(l),
      std::sqrt(2.0 + 0.05 / (l2 - 0.03) + 0.01 * (l - 0.3) / ((l - 0.3) * (l - 0.3) + 0.02)),
      1e-14);
  EXPECT_THROW(RefractiveIndexFormula(10, {1.0}), std::invalid_argument);
  EXPECT_THROW(RefractiveIndexFormula(2, {}), std::invalid_argument);
  EXPECT_THROW(RefractiveIndexFormula(8, {1, 2, 3, 4, 5}), std::invalid_argument);
}

const char* kBk7Yaml = R"(# SCHOTT N-BK7, abbreviated from refractiveindex.info
REFERENCES: "SCHOTT Zemax catalog 2017-01-20b"
DATA:
  - type: formula 2
    wavelength_range: 0.3 2.5
    coefficients: 0 1.03961212 0.00600069867 0.231792344 0.0200179144 1.01046945 103.560653
  - type: tabulated k
    data: |
        0.300 2.8607E-06
        0.310 1.3679E-06
CONDITIONS:
  temperature: 293.15
)";

TEST(RefractiveIndexYaml, FormulaIsSampledOverItsRange) {
  const IndexData d = parseRefractiveIndexYaml(kBk7Yaml, "bk7.yml");
  ASSERT_EQ(d.modes.size(), 1u);
  const IndexSeries& s = d.modes[0];
  EXPECT_EQ(s.size(), 201u);
  EXPECT_DOUBLE_EQ(s.lambda_nm.front(), 300.0);
  EXPECT_DOUBLE_EQ(s.lambda_nm.back(), 2500.0);
  // Window: samples inside [400, 700] only, still 201 of them; n_d from materials.json (±6e-7).
  IndexReadOptions o;
  o.window_nm = std::array<double, 2>{400.0, 700.0};
  o.formula_samples = 301;
  const IndexSeries w = parseRefractiveIndexYaml(kBk7Yaml, "bk7.yml", o).modes[0];
  EXPECT_EQ(w.size(), 301u);
  EXPECT_DOUBLE_EQ(w.lambda_nm[1], 401.0);
  const Dispersion bk7 = Dispersion::sellmeier({1.03961212, 0.231792344, 1.01046945},
                                               {0.00600069867, 0.0200179144, 103.560653});
  EXPECT_NEAR(w.n[100], bk7.index(500.0), 1e-15);
}

// Older files: `range:` instead of `wavelength_range:`, `SPECS:`; several blocks merged; tabulated
// nk keeps n and drops k.
TEST(RefractiveIndexYaml, OldKeysTabulatedAndSeveralBlocks) {
  const char* text = R"(REFERENCES: old style
DATA:
  - type: tabulated nk
    data: |
        0.40 1.530 1e-7
        0.50 1.520 1e-8
  - type: tabulated n
    data: |
        0.45 1.525
  - type: formula 5
    range: 0.6 0.7
    coefficients: 1.5 0.004 -2
SPECS:
  n_absolute: true
  wavelength_vacuum: false
)";
  IndexReadOptions o;
  o.formula_samples = 3;
  const IndexData d = parseRefractiveIndexYaml(text, "old.yml", o);
  const IndexSeries& s = d.modes[0];
  EXPECT_EQ(s.lambda_nm, (std::vector<double>{400, 450, 500, 600, 650, 700}));
  EXPECT_DOUBLE_EQ(s.n[1], 1.525);
  EXPECT_NEAR(s.n[5], 1.5 + 0.004 / 0.49, 1e-14);
  EXPECT_EQ(d.warnings.size(), 1u);  // blocks out of order → sorted
}

// Database nk files often start in the EUV where n < 1: an error on its own, skipped when the
// caller's window excludes it.
TEST(RefractiveIndexYaml, WindowSkipsRowsOutsideBeforeChecks) {
  const char* text =
      "DATA:\n  - type: tabulated nk\n    data: |\n        0.03 0.93 0.08\n"
      "        0.45 1.47 0\n        0.55 1.46 0\n        0.65 1.456 0\n";
  EXPECT_THROW(parseRefractiveIndexYaml(text, "euv.yml"), std::invalid_argument);
  IndexReadOptions o;
  o.window_nm = std::array<double, 2>{400.0, 700.0};
  EXPECT_EQ(parseRefractiveIndexYaml(text, "euv.yml", o).modes[0].size(), 3u);
}

TEST(RefractiveIndexYaml, BadInputIsOneClearError) {
  auto yml = [](const std::string& text) {
    return [text] { parseRefractiveIndexYaml(text, "bad.yml"); };
  };
  expectError(yml(""), {"bad.yml", "empty"});
  expectError(yml("DATA: [\n  - type: formula 2\n"), {"bad.yml:", "malformed YAML"});
  expectError(yml("DATA:\n  - type: formula 2\n   coefficients: 1 2\n  x"),
              {"bad.yml", "malformed YAML"});
  expectError(yml("REFERENCES: x\n"), {"bad.yml", "no DATA"});
  expectError(
      yml("DATA:\n  - type: formula 12\n    wavelength_range: 0.4 0.7\n    coefficients: 1\n"),
      {"bad.yml:2: DATA[0].type", "formula 12"});
  expectError(yml("DATA:\n  - type: formula 2\n    coefficients: 0 1 0.01\n"),
              {"DATA[0]", "wavelength_range"});
  expectError(yml("DATA:\n  - type: formula 2\n    wavelength_range: 0.7 0.4\n    coefficients: 0 "
                  "1 0.01\n"),
              {"DATA[0].wavelength_range", "lo < hi"});
  expectError(yml("DATA:\n  - type: formula 2\n    wavelength_range: 0.4 0.7\n    coefficients: 0 "
                  "one 0.01\n"),
              {"DATA[0].coefficients", "'one'"});
  expectError(yml("DATA:\n  - type: tabulated n\n    data: |\n        0.5 1.5 3\n"),
              {"DATA[0].data row 1", "expected 2"});
  expectError(yml("DATA:\n  - type: tabulated n\n    data: |\n        0.5 1.5\n        0.5 1.6\n"),
              {"duplicate wavelength 500"});
  expectError(
      yml("DATA:\n  - type: tabulated k\n    data: |\n        0.5 1e-5\n        0.6 1e-5\n"),
      {"bad.yml", "no data points"});
  expectError(yml("DATA:\n  - type: spline\n"), {"DATA[0].type", "unsupported"});
  // A formula whose last term is given in part names the file and the line of the coefficients.
  expectError(yml("DATA:\n  - type: formula 2\n    wavelength_range: 0.3 2.5\n    coefficients: 0 "
                  "1\n"),
              {"bad.yml:4: DATA[0].coefficients", "odd number of coefficients, got 2"});
}

// A file holding just "," hung `eikon fit` forever: yaml-cpp 0.7 leaves a ',' outside a flow
// collection unread and answers every next document with an empty one at that same ','. Refused
// with the line and the column, promptly (the alarm turns a regression into a failure, not a hang).
TEST(RefractiveIndexYaml, CommaOutsideAFlowCollectionIsRefusedNotLoopedOn) {
  struct Case {
    const char* text;
    const char* where;
  };
  const Case cases[] = {{",", "bad.yml:1: malformed YAML: a ',' outside a flow list"},
                        {" ,", "bad.yml:1:"},
                        {"\n\n,", "bad.yml:3: malformed YAML: a ',' outside"},
                        {", DATA", "bad.yml:1: malformed YAML: a ',' outside"},
                        {"[a],", "(column 4)"},
                        {"\"x\",", "(column 4)"},
                        {"--- ,", "bad.yml:1: malformed YAML: a ',' outside"},
                        {"- a\n,", "bad.yml:2: malformed YAML: a ',' outside"},
                        {"DATA: x\n...\n,", "bad.yml:3: malformed YAML: a ',' outside"},
                        {"\xEF\xBB\xBF,", "bad.yml:1: malformed YAML: a ',' outside"}};
  ::alarm(20);
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text);
    expectError([&] { parseRefractiveIndexYaml(c.text, "bad.yml"); }, {c.where});
  }
  ::alarm(0);
  // A ',' inside a flow list, or inside a plain scalar, is no error of its own.
  expectError([] { parseRefractiveIndexYaml("[a, b]", "ok.yml"); }, {"ok.yml: expected a"});
  expectError([] { parseRefractiveIndexYaml("a, b", "ok.yml"); }, {"ok.yml: expected a"});
}

// The samples of all formula blocks together are bounded (blocks × samples ≤
// kMaxFormulaSamplesTotal), checked before any block is sampled: 300 blocks × 100000 samples in a
// 31 KB file used 3.6 GB.
TEST(RefractiveIndexYaml, TotalFormulaSamplesAreBounded) {
  std::string text = "DATA:\n";
  for (int i = 0; i < 300; ++i)
    text += "  - type: formula 2\n    wavelength_range: 0." + std::to_string(400 + i) + " 0." +
            std::to_string(700 + i) + "\n    coefficients: 0 1.2 0.01\n";
  IndexReadOptions o;
  o.formula_samples = kMaxFormulaSamples;
  expectError([&] { parseRefractiveIndexYaml(text, "many.yml", o); },
              {"many.yml: 300 formula blocks x 100000 samples each", "more than the 1000000"});
  o.formula_samples = 2;  // 600 samples in all: read
  EXPECT_EQ(parseRefractiveIndexYaml(text, "many.yml", o).modes[0].size(), 600u);
}

// yaml-cpp keeps every pair of a map whose key repeats and answers one: the other value was lost
// without a word. A repeated key is refused with its line and the first's, in any map of the file;
// keys repeated across maps, and an alias used twice, are not repeats.
TEST(RefractiveIndexYaml, DuplicateKeyIsRefusedWithItsLine) {
  auto yml = [](const std::string& text) {
    return [text] { parseRefractiveIndexYaml(text, "dup.yml"); };
  };
  expectError(yml("DATA:\n  - type: formula 2\n    type: tabulated n\n"
                  "    wavelength_range: 0.3 2.5\n    coefficients: 0 1 0.01\n"),
              {"dup.yml:3: duplicate key 'type' (first on line 2)"});
  expectError(yml("DATA:\n  - type: tabulated n\n    data: |\n        0.5 1.5\n        0.6 1.4\n"
                  "DATA:\n  - type: tabulated k\n"),
              {"dup.yml:6: duplicate key 'DATA' (first on line 1)"});
  expectError(yml("SPECS:\n  temperature: 20\n  temperature: 25\nDATA:\n  - type: tabulated n\n"
                  "    data: |\n        0.5 1.5\n        0.6 1.4\n"),
              {"dup.yml:3: duplicate key 'temperature' (first on line 2)"});
  expectError(yml("DATA: [{type: tabulated n, data: '0.5 1.5', type: x}]\n"),
              {"dup.yml:1: duplicate key 'type'"});
  const std::string fine =
      "SPECS: &s {a: 1, b: {a: 2}}\nMORE: *s\nALSO: *s\nDATA:\n  - type: tabulated n\n"
      "    data: |\n        0.5 1.5\n        0.6 1.4\n  - type: tabulated n\n"
      "    data: |\n        0.7 1.3\n        0.8 1.2\n";
  EXPECT_EQ(parseRefractiveIndexYaml(fine, "fine.yml").modes[0].size(), 4u);
}

// A byte order mark at the start of CSV text (Python's parse_index_csv) is skipped, as
// readTextFile skips it in a file.
TEST(IndexCsv, LeadingByteOrderMarkIsSkipped) {
  const IndexData d = parseIndexCsv("\xEF\xBB\xBFwavelength_nm,n\n500,1.5\n600,1.4\n", "bom.csv");
  EXPECT_EQ(d.modes[0].size(), 2u);
  EXPECT_EQ(parseRefractiveIndexYaml("\xEF\xBB\xBF"
                                     "DATA:\n  - type: tabulated n\n    data: |\n"
                                     "        0.5 1.5\n        0.6 1.4\n",
                                     "bom.yml")
                .modes[0]
                .size(),
            2u);
}

// An index above 10 (which no scene takes) is refused with its file and line, as one below 1 is.
TEST(IndexCsv, IndexAboveTenIsRefused) {
  expectError([] { parseIndexCsv("wavelength_nm,n\n500,9.5\n600,12\n", "big.csv"); },
              {"big.csv:3", "n must be <= 10, got 12"});
  EXPECT_EQ(parseIndexCsv("wavelength_nm,n\n500,10\n600,9.9\n", "ok.csv").modes[0].size(), 2u);
}

// Whole terms may be left out (they count as zero), never part of one: formula 2 with "0 1" was
// read as n² = 1 + 1·λ²/(λ² − 0), n = √2 at every wavelength.
TEST(RefractiveIndexFormula, ALastTermGivenInPartIsAnError) {
  for (int type : {1, 2, 3, 5, 6}) {
    EXPECT_THROW(RefractiveIndexFormula(type, {0, 1}), std::invalid_argument) << type;
    EXPECT_THROW(RefractiveIndexFormula(type, {0, 1, 0.01, 0.5}), std::invalid_argument) << type;
    EXPECT_NO_THROW(RefractiveIndexFormula(type, {1.5})) << type;
    EXPECT_NO_THROW(RefractiveIndexFormula(type, {0, 1, 0.01})) << type;
  }
  for (size_t n : {2, 3, 4, 6, 7, 8, 10})
    EXPECT_THROW(RefractiveIndexFormula(4, std::vector<double>(n, 0.5)), std::invalid_argument)
        << n;
  for (size_t n : {1, 5, 9, 11, 17})
    EXPECT_NO_THROW(RefractiveIndexFormula(4, std::vector<double>(n, 0.5))) << n;
  EXPECT_THROW(RefractiveIndexFormula(8, {0.3, 0.01}), std::invalid_argument);
  for (size_t n : {1, 3, 4})
    EXPECT_NO_THROW(RefractiveIndexFormula(8, std::vector<double>(n, 0.01))) << n;
  for (size_t n : {2, 4, 5})
    EXPECT_THROW(RefractiveIndexFormula(9, std::vector<double>(n, 0.5)), std::invalid_argument)
        << n;
  for (size_t n : {1, 3, 6})
    EXPECT_NO_THROW(RefractiveIndexFormula(9, std::vector<double>(n, 0.5))) << n;
  for (size_t n = 1; n <= 6; ++n)
    EXPECT_NO_THROW(RefractiveIndexFormula(7, std::vector<double>(n, 0.01))) << n;
}

// The writer `eikon fit --export-yaml` uses: free text with YAML's special characters is quoted by
// the emitter, and the entry reads back (our reader) as the formula it names. Formula 5 with
// "1.5 0.004 -2" is n = 1.5 + 0.004/λ² (λ in µm): 1.525 at 0.4, 1.5 + 0.004/0.36 at 0.6,
// 1.50625 at 0.8.
TEST(RefractiveIndexYaml, WrittenFormulaEntryReadsBack) {
  RefractiveIndexFormulaEntry entry;
  entry.references = "eikon fit of a: b.csv, model cauchy3 # not a comment";
  entry.comments = "1-sigma: A 1.0e-05, B: 2.0e-07; 'quoted'";
  entry.formula = 5;
  entry.wavelength_range = "0.4 0.8";
  entry.coefficients = "1.5 0.004 -2";
  const std::string text = formatRefractiveIndexYaml(entry);
  EXPECT_EQ(text.rfind("REFERENCES:", 0), 0u) << text;
  EXPECT_NE(text.find("type: formula 5"), std::string::npos) << text;
  EXPECT_EQ(text.back(), '\n');
  IndexReadOptions o;
  o.formula_samples = 3;
  const IndexData d = parseRefractiveIndexYaml(text, "fit.yml", o);
  ASSERT_EQ(d.modes.size(), 1u);
  const IndexSeries& s = d.modes[0];
  ASSERT_EQ(s.size(), 3u);
  EXPECT_NEAR(s.lambda_nm[0], 400.0, 1e-9);
  EXPECT_NEAR(s.lambda_nm[1], 600.0, 1e-9);
  EXPECT_NEAR(s.lambda_nm[2], 800.0, 1e-9);
  EXPECT_NEAR(s.n[0], 1.525, 1e-14);
  EXPECT_NEAR(s.n[1], 1.5 + 0.004 / 0.36, 1e-14);
  EXPECT_NEAR(s.n[2], 1.50625, 1e-14);
}

TEST(IndexData, CombineOrdinaryExtraordinary) {
  IndexData o = parseIndexCsv("wavelength_nm,n\n500,1.66\n600,1.655\n", "o.csv");
  IndexData e = parseIndexCsv("wavelength_nm,n\n500,1.49\n600,1.485\n", "e.csv");
  const IndexData c = combineOrdinaryExtraordinary(o, e);
  ASSERT_TRUE(c.uniaxial());
  EXPECT_EQ(c.modes[0].label, "n_o");
  EXPECT_EQ(c.modes[1].label, "n_e");
  EXPECT_DOUBLE_EQ(c.modes[1].n[0], 1.49);
}

// Arrays (Python's fit_dispersion) go through the files' rules: each point named by its index,
// sorted with one warning, the same complaints as a file's rows.
TEST(IndexSeries, ArraysAreCheckedAsAFilesRows) {
  std::vector<std::string> warnings;
  const IndexSeries s = checkIndexSeries(
      {"n", {600, 400, 500}, {1.51, 1.53, 1.52}, {1e-4, 2e-4, 3e-4}}, "data", warnings);
  EXPECT_EQ(s.lambda_nm, (std::vector<double>{400, 500, 600}));
  EXPECT_EQ(s.n, (std::vector<double>{1.53, 1.52, 1.51}));
  EXPECT_EQ(s.sigma, (std::vector<double>{2e-4, 3e-4, 1e-4}));
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0], "data: n points are not in ascending wavelength order; sorted them");
  auto check = [](IndexSeries s) {
    return [s] {
      std::vector<std::string> w;
      checkIndexSeries(s, "data", w);
    };
  };
  expectError(check({"n", {400, 500}, {1.5, 0.9}, {}}), {"point 1: n must be >= 1, got 0.9"});
  expectError(check({"n", {400, 500}, {1.5, 10.5}, {}}), {"point 1: n must be <= 10"});
  expectError(check({"n", {400, 500}, {1.5, 1.4}, {1e-4, 0}}),
              {"point 1: sigma of n must be a finite number > 0"});
  expectError(check({"n", {400, 500}, {1.5, 1.4}, {-1, 1e-4}}), {"point 0: sigma of n"});
  expectError(check({"n", {50, 500}, {1.5, 1.4}, {}}),
              {"point 0: wavelength 50 nm is outside [100, 100000] nm"});
  expectError(check({"n", {400, NAN}, {1.5, 1.4}, {}}), {"point 1: wavelength is not a finite"});
  expectError(check({"n", {400, 500, 400}, {1.5, 1.4, 1.5}, {}}),
              {"point 2: duplicate wavelength 400 nm (also at point 0)"});
  expectError(check({"n", {400}, {1.5}, {}}), {"data: only one data point"});
  expectError(check({"n", {400, 500}, {1.5}, {}}), {"data: 2 wavelengths, 1 indices"});
  expectError(check({"n", {400, 500}, {1.5, 1.4}, {1e-4}}), {"and 1 sigmas"});
}

}  // namespace
}  // namespace eikon
