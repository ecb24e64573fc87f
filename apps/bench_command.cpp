// Placeholder until the subcommand lands; replaced in the same session.
#include "apps/commands.h"
namespace eikon::cli {
void addBenchCommand(CLI::App& app) {
  auto* sub = app.add_subcommand("bench", "(not built yet)");
  sub->callback([] { throw CliError("'bench' is not built yet"); });
}
}  // namespace eikon::cli
