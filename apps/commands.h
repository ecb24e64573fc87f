// The `eikon` command is a CLI11 app with one subcommand per file (*_command.cpp).
// Each add*Command registers its subcommand and callback; the callback throws eikon::CliError
// (message already formatted for the user) or any std::exception on failure, and main() prints
// "eikon <sub>: error: <message>" on one line and exits non-zero.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "core/scene/messages.h"
#include "core/session/settings.h"

namespace eikon::cli {

/// A user-facing error: printed as one line, exit status `code`.
struct CliError : std::runtime_error {
  explicit CliError(const std::string& what, int code = 1)
      : std::runtime_error(what), exit_code(code) {}
  int exit_code;
};

/// Said on stderr when a scene's lights are left unsimulated because no material has an albedo
/// (Scene::anyScattering): the light volumes would show nowhere in the picture.
inline constexpr const char* kLightsNotSimulatedNote =
    "eikon: note: the lights are not simulated: no material has an albedo, so no medium scatters "
    "their light and no diffuse surface shows it\n";

/// --exposure of the PNG preview and the viewer: stops in [-64, 64] (2^±64 spans every radiance a
/// float holds); NaN and infinities are refused, not turned into a black or white image.
inline void checkExposure(double stops) {
  if (!(stops >= -64 && stops <= 64))
    throw CliError("--exposure must be in [-64, 64] stops, got " + formatNumber(stops));
}

/// The value of a comma-separated number option (--origin x,y,z, --stokes S0,S1,S2,S3,
/// --range-nm LO,HI): exactly `count` finite decimal numbers ("-1.5", "2e-3", blanks around each
/// allowed), separated by single commas. Anything else is refused, never read in part: an empty
/// value, an empty field ("1,,0"), a trailing comma, hexadecimal, inf or nan, words. Throws
/// CliError "OPTION must be COUNT finite numbers NAMES, got 'VALUE'".
std::vector<double> parseNumberList(const std::string& value, const std::string& option,
                                    size_t count, const std::string& names);

/// A command's settings by name (core/session/settings.h), as addSettingOptions reads them.
using SettingValues = std::map<std::string, SettingValue, std::less<>>;
/// One option --NAME per setting of `front` (a SettingFront bit), made from the settings table:
/// its kind, help and default; it reads into values[NAME]. The callback calls markGivenSettings.
void addSettingOptions(CLI::App* sub, unsigned front, SettingValues& values);
/// values[NAME].given for each setting option the user gave.
void markGivenSettings(const CLI::App& sub, SettingValues& values);
/// The option --NAME of the setting `name` read into the command's own `variable` (an int, a
/// double or a std::string), with the table's help and default for `front` (an unset default
/// leaves the variable as it is).
template <class T>
CLI::Option* addSettingOption(CLI::App* sub, const char* name, unsigned front, T& variable) {
  const Setting& s = setting(name);
  if (const std::string value = settingDefault(s, front).value; !value.empty()) {
    if constexpr (std::is_same_v<T, int>)
      variable = std::stoi(value);
    else if constexpr (std::is_same_v<T, double>)
      variable = std::stod(value);
    else
      variable = value;
  }
  return sub->add_option(std::string("--") + name, variable, settingHelp(s, front));
}

void addRenderCommand(CLI::App& app);
void addTraceCommand(CLI::App& app);
void addInfoCommand(CLI::App& app);
void addFitCommand(CLI::App& app);
void addViewCommand(CLI::App& app);
void addGemCommand(CLI::App& app);
/// `eikon sweep` (apps/sweep_command.cpp) is listed among the commands, but main() hands its
/// arguments to runSweepCommand before parsing: it runs `python3 -m eikon.sweeps` (and returns
/// only by throwing CliError).
void addSweepCommand(CLI::App& app);
int runSweepCommand(int argc, char** argv);

}  // namespace eikon::cli
