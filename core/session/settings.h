// The table of the user's render, light and trace settings: one descriptor per setting (its
// neutral name, kind, default, range or choices, help text and the request field it fills), from
// which every front end is made: the options of `eikon render`, `eikon trace` and `eikon view`
// (apps/: a loop over the table), the keywords of the Python module's Renderer.render,
// simulate_light and trace (python/: names, defaults and docstrings), and the range checks of
// core/session (checkViewRequest, checkLightRequest, checkThreads, ...), so that the CLI and
// Python refuse the same settings with the same words and their help cannot drift apart.
//
//   const eikon::Setting& w = eikon::setting("width");
//   eikon::checkSettingValue(w, 0);  // SettingError: "width must be in [1, 16384], got 0"
//   std::string help = eikon::settingHelp(w, eikon::SettingFront::RenderCli);
//
// A new setting is one row in kSettings (settings.cpp): its fill stores it in the requests.
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace eikon {

/// A setting out of its range, or an unknown name: what() is "<setting> <complaint>".
class SettingError : public std::invalid_argument {
 public:
  SettingError(const std::string& setting, const std::string& complaint)
      : std::invalid_argument(setting + " " + complaint),
        setting_(setting),
        complaint_(complaint) {}
  const std::string& setting() const { return setting_; }
  const std::string& complaint() const { return complaint_; }

 private:
  std::string setting_, complaint_;
};

enum class SettingKind {
  Integer,  ///< a whole number in [min, max] (or `special`)
  Number,   ///< a real number in [min, max] or (min, max] (or `special`)
  Choice,   ///< one of `choices`
  Flag,     ///< on or off (a CLI flag, a Python bool)
  Text,     ///< free text checked by its own parser (layers: a list of `choices`)
};

/// The front ends a setting belongs to (a bit mask).
namespace SettingFront {
inline constexpr unsigned RenderCli = 1;  ///< `eikon render --NAME`
inline constexpr unsigned TraceCli = 2;   ///< `eikon trace --NAME`
inline constexpr unsigned ViewCli = 4;    ///< `eikon view --NAME`
inline constexpr unsigned PyRender = 8;   ///< Renderer.render / eikon.render keyword
inline constexpr unsigned PyLight = 16;   ///< Renderer.simulate_light keyword
inline constexpr unsigned PyTrace = 32;   ///< Renderer.trace / trace_rays / trace_polarised keyword
inline constexpr unsigned Cli = RenderCli | TraceCli | ViewCli;
inline constexpr unsigned Python = PyRender | PyLight | PyTrace;
}  // namespace SettingFront

/// One value of a choice (or one item of a Text list) and what it means.
struct SettingChoice {
  const char* name;
  const char* means;
};

/// A default some front ends give instead of Setting::value (`eikon trace --step` 0.25; Python's
/// width=0 for "unset").
struct SettingDefault {
  unsigned fronts = 0;
  const char* value = "";
  const char* means = "";
  bool unset = false;  ///< `value` stands for unset (Python's width=0), outside the range
};

/// A setting's value as a front end read it (the CLI's options: addSettingOptions in apps/).
struct SettingValue {
  int integer = 0;
  double number = 0;
  std::string text;
  bool flag = false;
  bool given = false;  ///< given by the user, not the default
};
/// What the settings fill (core/session/session.h).
struct SettingRequests;

/// One setting. A default `value` of "" is unset, and `means` says what that means ("the scene
/// camera's"); a set value may say more in `means` ("0.5").
struct Setting {
  const char* name;  ///< SettingError's word and the CLI option without "--" ("light-splat")
  SettingKind kind;
  unsigned fronts;    ///< SettingFront bits
  const char* help;   ///< what it is; settingHelp adds the range or choices and the default
  const char* field;  ///< the request field it fills, in words
  /// Stores a checked value in the requests (fillSettings); a setting unset by default stores
  /// only a given value.
  void (*fill)(const SettingValue& v, SettingRequests& r);
  const char* value = "";   ///< the default as typed on the command line; "" unset
  const char* means = "";   ///< what the default (or unset) means, where the value does not say
  double min = 0, max = 0;  ///< Integer and Number: the range
  bool min_open = false;    ///< (min, max] instead of [min, max]
  const char* unit = "";    ///< "voxels", "nm": said after the range
  std::optional<double> special = {};       ///< a value outside the range that is taken too (0)
  const char* special_means = "";           ///< "for all cores": said after the range
  bool says_value = false;                  ///< the complaint ends ", got VALUE"
  std::vector<SettingChoice> choices = {};  ///< Choice: the values; Text: the list's items
  const char* keyword = "";  ///< Python's keyword ("splat"), or "march.step_voxels"; "" = name
  std::vector<SettingDefault> defaults = {};  ///< front ends whose default differs
};

/// Every setting, in the order the CLI checks them.
const std::vector<Setting>& settings();
/// The setting named `name`; std::logic_error for a name not in the table (a programming error).
const Setting& setting(std::string_view name);
/// The default of `s` on a front end (one SettingFront bit): its value ("" unset) and meaning.
SettingDefault settingDefault(const Setting& s, unsigned front);
/// Python's spelling of a setting (Setting::keyword, else its name with '-' as '_').
std::string settingKeyword(const Setting& s);
/// The setting whose keyword (or name) is Python's `keyword`; nullptr if none.
const Setting* settingByKeyword(std::string_view keyword);

/// A number as the messages and help print it: 16384, 0.25, 587.5618.
std::string settingNumber(double v);
/// "in [1, 16384]", "in (0, 4] voxels, or 0 for the default (0.5)"; "" for other kinds.
std::string settingRange(const Setting& s);
/// "a, b or c" of the choices (Choice), "a, b and c" (Text lists).
std::string settingChoiceList(const Setting& s, const char* last = " or ");
/// The help line of `s` on a front end: its help, its range or choices with their meanings, and
/// its default there.
std::string settingHelp(const Setting& s, unsigned front);

/// Whether `v` is in the range of an Integer or Number setting (NaN is not).
bool settingInRange(const Setting& s, double v);
/// SettingError(s.name, "must be in [1, 16384], got 0") when `v` is not in range.
void checkSettingValue(const Setting& s, double v);
/// SettingError(s.name, "must be a, b or c, got 'x'") when `v` is not one of the choices.
void checkSettingChoice(const Setting& s, const std::string& v);

}  // namespace eikon
