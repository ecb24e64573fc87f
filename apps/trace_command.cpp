// Placeholder until the subcommand lands; replaced in the same session.
#include "apps/commands.h"
namespace eikon::cli {
void addTraceCommand(CLI::App& app) {
  auto* sub = app.add_subcommand("trace", "(not built yet)");
  sub->callback([] { throw CliError("'trace' is not built yet"); });
}
}  // namespace eikon::cli
