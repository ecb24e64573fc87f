#include "apps/commands.h"

#include <cmath>
#include <cstdlib>
#include <iterator>
#include <string>
#include <vector>

namespace eikon::cli {
namespace {

bool isDigit(char c) { return c >= '0' && c <= '9'; }

/// `s` is a decimal number: [+-] digits [. [digits]] or [+-] . digits, then [eE [+-] digits].
bool isDecimal(const std::string& s) {
  size_t i = 0, digits = 0;
  if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
  for (; i < s.size() && isDigit(s[i]); ++i) ++digits;
  if (i < s.size() && s[i] == '.')
    for (++i; i < s.size() && isDigit(s[i]); ++i) ++digits;
  if (digits == 0) return false;
  if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
    ++i;
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
    const size_t first = i;
    while (i < s.size() && isDigit(s[i])) ++i;
    if (i == first) return false;
  }
  return i == s.size();
}

std::string trimBlanks(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

}  // namespace

std::vector<double> parseNumberList(const std::string& value, const std::string& option,
                                    size_t count, const std::string& names) {
  const char* words[] = {"zero", "one", "two", "three", "four", "five", "six"};
  const std::string n = count < std::size(words) ? words[count] : std::to_string(count);
  auto refuse = [&](const std::string& why = "") {
    return CliError(option + " must be " + n + " finite numbers " + names + ", got '" + value +
                    "'" + why);
  };
  std::vector<double> out;
  size_t start = 0;
  for (;;) {  // every field, the empty ones too ("1,,0", "1,0,")
    const size_t comma = value.find(',', start);
    const std::string field = trimBlanks(
        value.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (!isDecimal(field)) throw refuse();
    // strtod, not stod: stod throws on a denormal such as 1e-320 (ERANGE), which is a finite
    // number (a --dir of 0,0,1e-320 is then refused as zero, not as "not finite").
    const double x = std::strtod(field.c_str(), nullptr);
    if (!std::isfinite(x)) throw refuse();  // 1e999
    out.push_back(x);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (out.size() != count) throw refuse(" (" + std::to_string(out.size()) + " given)");
  return out;
}

void addSettingOptions(CLI::App* sub, unsigned front, SettingValues& values) {
  for (const Setting& s : settings()) {
    if (!(s.fronts & front)) continue;
    SettingValue& v = values[s.name];
    const std::string option = std::string("--") + s.name, help = settingHelp(s, front);
    const std::string value = settingDefault(s, front).value;
    switch (s.kind) {
      case SettingKind::Integer:
        v.integer = value.empty() ? 0 : std::stoi(value);
        sub->add_option(option, v.integer, help);
        break;
      case SettingKind::Number:
        v.number = value.empty() ? 0.0 : std::stod(value);
        sub->add_option(option, v.number, help);
        break;
      case SettingKind::Choice:
      case SettingKind::Text:
        v.text = value;
        sub->add_option(option, v.text, help);
        break;
      case SettingKind::Flag:
        sub->add_flag(option, v.flag, help);
        break;
    }
  }
}

void markGivenSettings(const CLI::App& sub, SettingValues& values) {
  for (auto& [name, v] : values) v.given = sub.count("--" + name) > 0;
}

}  // namespace eikon::cli
