// eikon — eikonal rendering of refractive, dispersive and birefringent objects.
#include <cstdio>
#include <exception>
#include <new>
#include <string>

#include "apps/commands.h"
#include "core/scene/messages.h"
#include "core/session/session.h"

int main(int argc, char** argv) {
  CLI::App app{"eikon: eikonal rendering of gems, prisms and crystals (see README.md)", "eikon"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "eikon 0.1.0");
  eikon::cli::addRenderCommand(app);
  eikon::cli::addTraceCommand(app);
  eikon::cli::addInfoCommand(app);
  eikon::cli::addFitCommand(app);
  eikon::cli::addViewCommand(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    std::fputs(eikon::errorLine(std::string(e.what()) + " (run with --help)").c_str(), stderr);
    return 2;
  } catch (const eikon::SettingError& e) {  // the session's range checks: the option as typed
    std::fputs(eikon::errorLine("--" + std::string(e.what())).c_str(), stderr);
    return 1;
  } catch (const eikon::cli::CliError& e) {
    std::fputs(eikon::errorLine(e.what()).c_str(), stderr);
    return e.exit_code;
  } catch (const std::bad_alloc&) {  // the checks before allocating missed a case: say so
    std::fputs(eikon::errorLine("out of host memory (std::bad_alloc); lower the image size, the "
                                "layers or the volume's resolution")
                   .c_str(),
               stderr);
    return 1;
  } catch (const std::exception& e) {
    std::fputs(eikon::errorLine(e.what()).c_str(), stderr);
    return 1;
  }
  return 0;
}
