// eikon — eikonal rendering of refractive, dispersive and birefringent objects.
#include <cstdio>
#include <exception>

#include "apps/commands.h"

int main(int argc, char** argv) {
  CLI::App app{"eikon: eikonal rendering of gems, prisms and crystals (see README.md)", "eikon"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "eikon 0.1.0");
  eikon::cli::addRenderCommand(app);
  eikon::cli::addTraceCommand(app);
  eikon::cli::addInfoCommand(app);
  eikon::cli::addFitCommand(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    std::fprintf(stderr, "eikon: error: %s (run with --help)\n", e.what());
    return 2;
  } catch (const eikon::cli::CliError& e) {
    std::fprintf(stderr, "eikon: error: %s\n", e.what());
    return e.exit_code;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "eikon: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
