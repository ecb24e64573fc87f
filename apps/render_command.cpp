// Placeholder until the subcommand lands; replaced in the same session.
#include "apps/commands.h"
namespace eikon::cli {
void addRenderCommand(CLI::App& app) {
  auto* sub = app.add_subcommand("render", "(not built yet)");
  sub->callback([] { throw CliError("'render' is not built yet"); });
}
}  // namespace eikon::cli
