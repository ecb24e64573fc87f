#include "fitting/index_data.h"

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "anisotropic/units.h"
#include "core/io/text_file.h"
#include "fitting/refractiveindex_formula.h"

namespace eikon {
namespace {

std::string trim(std::string_view s) {
  size_t b = 0, e = s.size();
  while (b < e && (s[b] == ' ' || s[b] == '\t' || s[b] == '\r')) ++b;
  while (e > b && (s[e - 1] == ' ' || s[e - 1] == '\t' || s[e - 1] == '\r')) --e;
  return std::string(s.substr(b, e - b));
}

std::vector<std::string> splitCommas(const std::string& line) {
  std::vector<std::string> out;
  size_t start = 0;
  for (;;) {
    size_t comma = line.find(',', start);
    out.push_back(trim(std::string_view(line).substr(
        start, comma == std::string::npos ? std::string::npos : comma - start)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

// Parses the whole field as a double or returns nullopt (no partial parses, no locale).
std::optional<double> parseNumber(const std::string& s) {
  if (s.empty()) return std::nullopt;
  const char* b = s.data();
  if (*b == '+') ++b;  // from_chars rejects a leading '+'
  double v = 0.0;
  auto [ptr, ec] = std::from_chars(b, s.data() + s.size(), v);
  if (ec != std::errc() || ptr != s.data() + s.size()) return std::nullopt;
  return v;
}

// A regular file of at most 64 MiB without NUL bytes (core/io/text_file.h): /dev/zero or a link
// to it was read without end.
std::string readFile(const std::string& path) {
  return readTextFile(path, "a data file (CSV or YAML)");
}

std::string fmt(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

// `text` without a leading UTF-8 byte order mark (Excel's "CSV UTF-8"): readTextFile leaves it out
// of a file, and text given as it is (Python's parse_index_csv) is read the same. Left in, it
// stuck to the first word (a CSV header's, a YAML key's).
std::string withoutByteOrderMark(const std::string& text) {
  return startsWithByteOrderMark(text) ? text.substr(3) : text;
}

// A series under construction: values plus where each point came from, for messages.
// Points outside the caller's window are dropped before the physical checks (a database file's
// EUV rows with n < 1 must not stop a visible-range fit), but never before the finiteness checks.
struct Pending {
  IndexSeries series;
  std::vector<std::string> where;
  std::optional<std::array<double, 2>> window_nm;
  const char* outside_hint =
      " (--range-nm leaves rows out)";  ///< after "the wavelengths a fit takes"
  const char* rows = "rows";            ///< what a point is, in messages

  void add(double lambda_nm, double n, std::optional<double> sigma, const std::string& at) {
    if (!std::isfinite(lambda_nm))
      throw std::invalid_argument(at + ": wavelength is not a finite number");
    if (!std::isfinite(n))
      throw std::invalid_argument(at + ": " + series.label + " is not a finite number");
    if (lambda_nm <= 0.0)
      throw std::invalid_argument(at + ": wavelength must be > 0, got " + fmt(lambda_nm));
    if (window_nm && (lambda_nm < (*window_nm)[0] || lambda_nm > (*window_nm)[1])) return;
    if (!(lambda_nm >= kMinFitWavelengthNm && lambda_nm <= kMaxFitWavelengthNm))
      throw std::invalid_argument(at + ": wavelength " + fmt(lambda_nm) + " nm is outside [" +
                                  fmt(kMinFitWavelengthNm) + ", " + fmt(kMaxFitWavelengthNm) +
                                  "] nm, the wavelengths a fit takes" + outside_hint);
    if (n < kMinFitIndex)
      throw std::invalid_argument(at + ": " + series.label + " must be >= 1, got " + fmt(n));
    if (n > kMaxFitIndex)
      throw std::invalid_argument(at + ": " + series.label + " must be <= 10, got " + fmt(n) +
                                  " (a scene takes indices in [1, 10])");
    if (sigma) {
      if (!std::isfinite(*sigma) || *sigma <= 0.0)
        throw std::invalid_argument(at + ": sigma of " + series.label +
                                    " must be a finite number > 0");
      series.sigma.push_back(*sigma);
    }
    series.lambda_nm.push_back(lambda_nm);
    series.n.push_back(n);
    where.push_back(at);
  }
};

// Window filter, sort (with a warning), duplicate check, minimum size.
IndexSeries finish(Pending p, const std::string& name, const IndexReadOptions& opt,
                   std::vector<std::string>& warnings) {
  const IndexSeries& s = p.series;
  if (s.size() == 0)
    throw std::invalid_argument(name + ": no data points" +
                                (opt.window_nm ? " inside the wavelength window" : ""));
  if (s.size() < 2)
    throw std::invalid_argument(name + ": only one data point (" + p.where[0] +
                                "); a dispersion fit needs at least 2");
  std::vector<size_t> order(s.size());
  std::iota(order.begin(), order.end(), size_t{0});
  const bool sorted = std::is_sorted(s.lambda_nm.begin(), s.lambda_nm.end());
  if (!sorted) {
    std::stable_sort(order.begin(), order.end(),
                     [&](size_t a, size_t b) { return s.lambda_nm[a] < s.lambda_nm[b]; });
  }
  for (size_t k = 1; k < order.size(); ++k) {
    if (s.lambda_nm[order[k]] == s.lambda_nm[order[k - 1]])
      throw std::invalid_argument(p.where[order[k]] + ": duplicate wavelength " +
                                  fmt(s.lambda_nm[order[k]]) + " nm (also at " +
                                  p.where[order[k - 1]] + ")");
  }
  if (!sorted) {
    IndexSeries out;
    out.label = s.label;
    for (size_t i : order) {
      out.lambda_nm.push_back(s.lambda_nm[i]);
      out.n.push_back(s.n[i]);
      if (s.weighted()) out.sigma.push_back(s.sigma[i]);
    }
    warnings.push_back(name + ": " + out.label + " " + p.rows +
                       " are not in ascending wavelength order; sorted them");
    return out;
  }
  return s;
}

void checkOptions(const IndexReadOptions& opt) {
  if (opt.window_nm && !((*opt.window_nm)[0] > 0 && (*opt.window_nm)[1] > (*opt.window_nm)[0]))
    throw std::invalid_argument("wavelength window must satisfy 0 < lo < hi (nm)");
  if (opt.formula_samples < 2 || opt.formula_samples > kMaxFormulaSamples)
    throw std::invalid_argument("formula_samples must be in [2, " +
                                std::to_string(kMaxFormulaSamples) + "], got " +
                                std::to_string(opt.formula_samples));
}

}  // namespace

IndexSeries checkIndexSeries(const IndexSeries& series, const std::string& name,
                             std::vector<std::string>& warnings) {
  const size_t N = series.lambda_nm.size();
  if (series.n.size() != N || (series.weighted() && series.sigma.size() != N))
    throw std::invalid_argument(name + ": " + std::to_string(N) + " wavelengths, " +
                                std::to_string(series.n.size()) + " indices" +
                                (series.weighted()
                                     ? " and " + std::to_string(series.sigma.size()) + " sigmas"
                                     : std::string()) +
                                ": each point needs one of each");
  Pending p;
  p.series.label = series.label;
  p.outside_hint = "";
  p.rows = "points";
  for (size_t i = 0; i < N; ++i)
    p.add(series.lambda_nm[i], series.n[i],
          series.weighted() ? std::optional<double>(series.sigma[i]) : std::nullopt,
          "point " + std::to_string(i));
  return finish(std::move(p), name, IndexReadOptions{}, warnings);
}

IndexData parseIndexCsv(const std::string& text, const std::string& name,
                        const IndexReadOptions& opt) {
  checkOptions(opt);
  IndexData data;
  data.source = name;
  std::istringstream in(withoutByteOrderMark(text));
  std::string raw;
  int line_no = 0;
  std::vector<std::string> header;
  int header_line = 0;
  double unit_to_nm = 0.0;
  bool crystal = false, has_sigma = false;
  Pending a, b;
  a.window_nm = b.window_nm = opt.window_nm;
  while (std::getline(in, raw)) {
    ++line_no;
    const std::string line = trim(raw);
    if (line.empty() || line[0] == '#') continue;
    const std::string at = name + ":" + std::to_string(line_no);
    auto fields = splitCommas(line);
    if (header.empty()) {
      header = fields;
      header_line = line_no;
      if (header[0] == "wavelength_nm")
        unit_to_nm = 1.0;
      else if (header[0] == "wavelength_um")
        unit_to_nm = 1000.0;
      else if (parseNumber(header[0]))
        throw std::invalid_argument(
            at +
            ": missing header; the first line must be "
            "'wavelength_nm,n[,sigma]' or 'wavelength_nm,n_o,n_e[,sigma_o,sigma_e]' "
            "(or wavelength_um)");
      else
        throw std::invalid_argument(
            at +
            ": first column must be 'wavelength_nm' or 'wavelength_um' (the unit "
            "is never guessed), got '" +
            header[0] + "'");
      std::vector<std::string> rest(header.begin() + 1, header.end());
      using V = std::vector<std::string>;
      if (rest == V{"n"}) {
      } else if (rest == V{"n", "sigma"}) {
        has_sigma = true;
      } else if (rest == V{"n_o", "n_e"}) {
        crystal = true;
      } else if (rest == V{"n_o", "n_e", "sigma_o", "sigma_e"}) {
        crystal = has_sigma = true;
      } else {
        throw std::invalid_argument(at + ": unrecognised header '" + line +
                                    "'; expected wavelength_nm,n[,sigma] or "
                                    "wavelength_nm,n_o,n_e[,sigma_o,sigma_e]");
      }
      a.series.label = crystal ? "n_o" : "n";
      b.series.label = "n_e";
      continue;
    }
    if (fields.size() != header.size())
      throw std::invalid_argument(at + ": expected " + std::to_string(header.size()) +
                                  " fields (as in the header on line " +
                                  std::to_string(header_line) + "), got " +
                                  std::to_string(fields.size()));
    std::vector<double> v(fields.size());
    for (size_t i = 0; i < fields.size(); ++i) {
      auto x = parseNumber(fields[i]);
      if (!x)
        throw std::invalid_argument(at + ": " + header[i] + " '" + fields[i] + "' is not a number");
      v[i] = *x;
    }
    const double lnm = v[0] * unit_to_nm;
    if (!crystal) {
      a.add(lnm, v[1], has_sigma ? std::optional(v[2]) : std::nullopt, at);
    } else {
      a.add(lnm, v[1], has_sigma ? std::optional(v[3]) : std::nullopt, at);
      b.add(lnm, v[2], has_sigma ? std::optional(v[4]) : std::nullopt, at);
    }
  }
  if (header.empty()) throw std::invalid_argument(name + ": empty file (no header, no data)");
  data.modes.push_back(finish(std::move(a), name, opt, data.warnings));
  if (crystal) {
    data.modes.push_back(finish(std::move(b), name, opt, data.warnings));
    // Sorting o and e from the same rows warns twice; once is enough.
    if (data.warnings.size() == 2) data.warnings.pop_back();
  }
  return data;
}

IndexData readIndexCsv(const std::string& path, const IndexReadOptions& opt) {
  return parseIndexCsv(readFile(path), path, opt);
}

namespace {

// yaml-cpp keeps every pair of a map whose key repeats and answers blk["type"] with one of them:
// the other value was dropped without a word (a scene's JSON refuses a repeated key). The file's
// events are walked once (an alias is one event, not the tree it names), and the second key of a
// map that repeats one is refused with its line: "name:LINE: duplicate key 'type' (first on line
// L)".
//
// The same walk guards against yaml-cpp 0.7's endless loop: a token that cannot start a node where
// a document's node is expected (a ',' outside [ ] and { }, as in a file holding just ",") is left
// unread by the parser, which then answers every next HandleNextDocument with an empty document at
// that same token, forever (upstream fixed it by stopping a parse that makes no progress). A
// document that starts where the one before it started is that loop: refused with its line.
class DuplicateKeyCheck final : public YAML::EventHandler {
 public:
  DuplicateKeyCheck(const std::string& name, const std::string& text) : name_(name), text_(text) {}
  void OnDocumentStart(const YAML::Mark& mark) override {
    if (started_ && mark.pos == last_start_) refuseStuck(mark);
    started_ = true;
    last_start_ = mark.pos;
  }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override { node(nullptr, {}); }
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override { node(nullptr, {}); }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                const std::string& value) override {
    node(&value, mark);
  }
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {
    open_.push_back({false, true, {}});
  }
  void OnSequenceEnd() override { close(); }
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {
    open_.push_back({true, true, {}});
  }
  void OnMapEnd() override { close(); }

 private:
  struct Collection {
    bool map;
    bool key_next;                     ///< a map's next node is a key (else a value)
    std::map<std::string, int> lines;  ///< a map's scalar keys so far, with their lines
  };
  /// A node has ended (a scalar, null or alias, or a collection just closed): a key or a value of
  /// the enclosing map.
  void node(const std::string* scalar, const YAML::Mark& mark) {
    if (open_.empty() || !open_.back().map) return;
    Collection& m = open_.back();
    if (m.key_next && scalar) {
      const int line = mark.line + 1;
      const auto [it, fresh] = m.lines.emplace(*scalar, line);
      if (!fresh)
        throw std::invalid_argument(name_ + ":" + std::to_string(line) + ": duplicate key '" +
                                    *scalar + "' (first on line " + std::to_string(it->second) +
                                    "); a key may appear once in a map");
    }
    m.key_next = !m.key_next;
  }
  void close() {
    open_.pop_back();
    node(nullptr, {});
  }
  /// The parser is stuck at `mark`: say which character stopped it, never quoting more of the file.
  [[noreturn]] void refuseStuck(const YAML::Mark& mark) const {
    const std::string at = name_ + ":" + std::to_string(mark.line + 1) + ": malformed YAML: ";
    const size_t pos = size_t(std::max(mark.pos, 0));
    if (pos < text_.size() && text_[pos] == ',')
      throw std::invalid_argument(at + "a ',' outside a flow list [ ] or map { } (column " +
                                  std::to_string(mark.column + 1) + ")");
    throw std::invalid_argument(at + "the parser cannot go on at column " +
                                std::to_string(mark.column + 1));
  }
  const std::string& name_;
  const std::string& text_;
  std::vector<Collection> open_;
  bool started_ = false;
  int last_start_ = 0;
};

void checkDuplicateKeys(const std::string& text, const std::string& name) {
  std::istringstream in(text);
  YAML::Parser parser(in);
  DuplicateKeyCheck check(name, text);
  while (parser.HandleNextDocument(check)) {
  }
}

}  // namespace

// The samples of all formula blocks together (blocks × formula_samples), bounded before any
// block is sampled; every formula block counts, even one the window leaves out.
static void checkFormulaSampleTotal(const YAML::Node& blocks, const std::string& name,
                                    const IndexReadOptions& opt) {
  long long formula_blocks = 0;
  for (size_t i = 0; i < blocks.size(); ++i)
    if (const YAML::Node blk = blocks[i];
        blk.IsMap() && blk["type"] && blk["type"].IsScalar() &&
        trim(blk["type"].as<std::string>()).rfind("formula", 0) == 0)
      ++formula_blocks;
  if (formula_blocks * opt.formula_samples > kMaxFormulaSamplesTotal)
    throw std::invalid_argument(
        name + ": " + std::to_string(formula_blocks) + " formula blocks x " +
        std::to_string(opt.formula_samples) +
        " samples each = " + std::to_string(formula_blocks * opt.formula_samples) +
        " samples, more than the " + std::to_string(kMaxFormulaSamplesTotal) +
        " a file may be sampled to in all; take fewer samples per block (--samples)");
}

IndexData parseRefractiveIndexYaml(const std::string& text, const std::string& name,
                                   const IndexReadOptions& opt) {
  checkOptions(opt);
  YAML::Node root;
  try {
    // The event walk first: it refuses the input that yaml-cpp's document loop never leaves.
    checkDuplicateKeys(withoutByteOrderMark(text), name);
    root = YAML::Load(withoutByteOrderMark(text));
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(name + ":" + std::to_string(e.mark.line + 1) +
                                ": malformed YAML: " + e.msg);
  }
  if (!root || root.IsNull()) throw std::invalid_argument(name + ": empty file");
  if (!root.IsMap())
    throw std::invalid_argument(name + ": expected a refractiveindex.info file (a map with DATA)");
  const YAML::Node blocks = root["DATA"];
  if (!blocks)
    throw std::invalid_argument(name + ": no DATA key (not a refractiveindex.info file?)");
  if (!blocks.IsSequence() || blocks.size() == 0)
    throw std::invalid_argument(name + ": DATA must be a non-empty list of blocks");

  checkFormulaSampleTotal(blocks, name, opt);

  IndexData data;
  data.source = name;
  Pending p;
  p.series.label = "n";
  p.window_nm = opt.window_nm;
  for (size_t i = 0; i < blocks.size(); ++i) {
    const std::string path = name + ": DATA[" + std::to_string(i) + "]";
    const YAML::Node blk = blocks[i];
    auto scalar = [&](const char* key) -> std::string {
      const YAML::Node v = blk[key];
      if (!v || !v.IsScalar())
        throw std::invalid_argument(path + "." + key + ": missing or not a scalar");
      return v.as<std::string>();
    };
    // "name:LINE: DATA[i].key": the line of the key's value (of the block if the key is absent).
    auto at = [&](const char* key) {
      const YAML::Node v = blk.IsMap() ? blk[key] : YAML::Node();
      const int line = (v ? v.Mark() : blk.Mark()).line;
      return (line >= 0 ? name + ":" + std::to_string(line + 1) : name) + ": DATA[" +
             std::to_string(i) + "]." + key;
    };
    auto numbers = [&](const std::string& s, const std::string& where) {
      std::vector<double> out;
      std::istringstream ss(s);
      std::string tok;
      while (ss >> tok) {
        auto x = parseNumber(tok);
        if (!x) throw std::invalid_argument(where + ": '" + tok + "' is not a number");
        out.push_back(*x);
      }
      return out;
    };
    if (!blk.IsMap()) throw std::invalid_argument(path + ": expected a map with 'type'");
    const std::string type = trim(scalar("type"));
    if (type == "tabulated n" || type == "tabulated nk") {
      const size_t cols = type == "tabulated n" ? 2 : 3;
      std::istringstream rows(scalar("data"));
      std::string row;
      int r = 0;
      while (std::getline(rows, row)) {
        if (trim(row).empty()) continue;
        const std::string where = path + ".data row " + std::to_string(++r);
        auto v = numbers(row, where);
        if (v.size() != cols)
          throw std::invalid_argument(where + ": expected " + std::to_string(cols) + " numbers (" +
                                      type + "), got " + std::to_string(v.size()));
        p.add(v[0] * 1000.0, v[1], std::nullopt, where);  // database λ is in µm
      }
      if (r == 0) throw std::invalid_argument(path + ".data: no rows");
    } else if (type == "tabulated k") {
      continue;  // extinction only: nothing to fit n to
    } else if (type.rfind("formula ", 0) == 0) {
      int k = 0;
      const std::string num = trim(type.substr(8));
      auto [ptr, ec] = std::from_chars(num.data(), num.data() + num.size(), k);
      if (ec != std::errc() || ptr != num.data() + num.size() || k < 1 || k > 9)
        throw std::invalid_argument(at("type") + ": unknown formula '" + type +
                                    "' (expected formula 1 to 9)");
      const char* range_key = blk["wavelength_range"] ? "wavelength_range"
                              : blk["range"]          ? "range"
                                                      : nullptr;
      if (!range_key)
        throw std::invalid_argument(path + ": formula without 'wavelength_range' (or 'range')");
      auto range = numbers(scalar(range_key), at(range_key));
      if (range.size() != 2 || !(range[0] > 0 && range[1] > range[0]))
        throw std::invalid_argument(at(range_key) + ": expected two wavelengths 0 < lo < hi (µm)");
      std::vector<double> coeffs = numbers(scalar("coefficients"), at("coefficients"));
      std::optional<RefractiveIndexFormula> f;
      try {
        f.emplace(k, coeffs);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(at("coefficients") + ": " + e.what());
      }
      double lo = range[0] * 1000.0, hi = range[1] * 1000.0;
      if (opt.window_nm) {
        lo = std::max(lo, (*opt.window_nm)[0]);
        hi = std::min(hi, (*opt.window_nm)[1]);
        if (!(hi > lo)) continue;  // block entirely outside the window
      }
      const int m = opt.formula_samples;
      for (int j = 0; j < m; ++j) {
        const double lnm = lo + (hi - lo) * j / double(m - 1);
        p.add(lnm, f->index(micrometresFromNanometres(lnm)), std::nullopt,
              path + " (" + type + " at " + fmt(lnm) + " nm)");
      }
    } else {
      throw std::invalid_argument(
          path + ".type: unsupported type '" + type +
          "' (expected tabulated n, tabulated nk, tabulated k, formula 1..9)");
    }
  }
  data.modes.push_back(finish(std::move(p), name, opt, data.warnings));
  return data;
}

IndexData readRefractiveIndexYaml(const std::string& path, const IndexReadOptions& opt) {
  return parseRefractiveIndexYaml(readFile(path), path, opt);
}

IndexData readIndexData(const std::string& path, const IndexReadOptions& opt) {
  auto ends = [&](const char* ext) {
    std::string e(ext);
    if (path.size() < e.size()) return false;
    std::string tail = path.substr(path.size() - e.size());
    std::transform(tail.begin(), tail.end(), tail.begin(),
                   [](unsigned char ch) { return char(std::tolower(ch)); });
    return tail == e;
  };
  if (ends(".csv")) return readIndexCsv(path, opt);
  if (ends(".yml") || ends(".yaml")) return readRefractiveIndexYaml(path, opt);
  throw std::invalid_argument(
      path + ": unknown data format (expected a .csv or a refractiveindex.info .yml file)");
}

std::string formatRefractiveIndexYaml(const RefractiveIndexFormulaEntry& entry) {
  YAML::Emitter e;
  e << YAML::BeginMap;
  e << YAML::Key << "REFERENCES" << YAML::Value << entry.references;
  e << YAML::Key << "COMMENTS" << YAML::Value << entry.comments;
  e << YAML::Key << "DATA" << YAML::Value << YAML::BeginSeq << YAML::BeginMap;
  e << YAML::Key << "type" << YAML::Value << ("formula " + std::to_string(entry.formula));
  e << YAML::Key << "wavelength_range" << YAML::Value << entry.wavelength_range;
  e << YAML::Key << "coefficients" << YAML::Value << entry.coefficients;
  e << YAML::EndMap << YAML::EndSeq << YAML::EndMap;
  return std::string(e.c_str()) + "\n";
}

IndexData combineOrdinaryExtraordinary(IndexData o, IndexData e) {
  if (o.modes.size() != 1 || e.modes.size() != 1)
    throw std::invalid_argument(
        "ordinary and extraordinary data must each be a single isotropic series (" + o.source +
        ", " + e.source + ")");
  IndexData out;
  out.source = o.source + " + " + e.source;
  out.modes = {std::move(o.modes[0]), std::move(e.modes[0])};
  out.modes[0].label = "n_o";
  out.modes[1].label = "n_e";
  out.warnings = std::move(o.warnings);
  out.warnings.insert(out.warnings.end(), e.warnings.begin(), e.warnings.end());
  return out;
}

}  // namespace eikon
