// The `eikon` command is a CLI11 app with one subcommand per file (*_command.cpp).
// Each add*Command registers its subcommand and callback; the callback throws eikon::CliError
// (message already formatted for the user) or any std::exception on failure, and main() prints
// "eikon <sub>: error: <message>" on one line and exits non-zero.
#pragma once

#include <CLI/CLI.hpp>
#include <stdexcept>
#include <string>

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

void addRenderCommand(CLI::App& app);
void addTraceCommand(CLI::App& app);
void addInfoCommand(CLI::App& app);
void addFitCommand(CLI::App& app);
void addViewCommand(CLI::App& app);

}  // namespace eikon::cli
