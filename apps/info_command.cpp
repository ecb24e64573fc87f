// Placeholder until the subcommand lands; replaced in the same session.
#include "apps/commands.h"
namespace eikon::cli {
void addInfoCommand(CLI::App& app) {
  auto* sub = app.add_subcommand("info", "(not built yet)");
  sub->callback([] { throw CliError("'info' is not built yet"); });
}
}  // namespace eikon::cli
