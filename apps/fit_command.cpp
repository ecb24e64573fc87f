// Placeholder until the subcommand lands; replaced in the same session.
#include "apps/commands.h"
namespace eikon::cli {
void addFitCommand(CLI::App& app) {
  auto* sub = app.add_subcommand("fit", "(not built yet)");
  sub->callback([] { throw CliError("'fit' is not built yet"); });
}
}  // namespace eikon::cli
