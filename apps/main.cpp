// eikon — eikonal rendering of refractive, dispersive and birefringent objects.
#include <cstdio>
#include <exception>
#include <new>
#include <string>

#include "apps/commands.h"
#include "core/io/cache_limit.h"
#include "core/scene/messages.h"
#include "core/session/session.h"

namespace {

/// The commands, "render, trace, info, fit, view, gem, sweep", in the order they were added.
std::string commandList(const CLI::App& app) {
  std::string list;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
    list += (list.empty() ? "" : ", ") + sub->get_name();
  return list;
}

/// Every option that takes a number refuses an empty value ("--width ''"), which CLI11 converts
/// to 0 and so reported as "--width must be in [1, 16384], got 0" (or, for --exposure, took).
void refuseEmptyNumbers(CLI::App& app) {
  for (CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
    for (CLI::Option* opt : sub->get_options()) {
      const std::string type = opt->get_type_name();
      if (type != "INT" && type != "UINT" && type != "FLOAT" && type != "NUMBER") continue;
      opt->check(CLI::Validator(
          [](std::string& value) {
            return value.find_first_not_of(" \t") == std::string::npos
                       ? std::string("the value is empty, expected a number")
                       : std::string();
          },
          "", "non-empty number"));
    }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"eikon: eikonal rendering of gems, prisms and crystals (see README.md)", "eikon"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "eikon 0.1.0");
  eikon::cli::addRenderCommand(app);
  eikon::cli::addTraceCommand(app);
  eikon::cli::addInfoCommand(app);
  eikon::cli::addFitCommand(app);
  eikon::cli::addViewCommand(app);
  eikon::cli::addGemCommand(app);
  eikon::cli::addSweepCommand(app);
  refuseEmptyNumbers(app);
  // "eikon bogus": CLI11 says only "A subcommand is required".
  if (argc > 1 && argv[1][0] != '-' &&
      app.get_subcommands([&](const CLI::App* sub) { return sub->check_name(argv[1]); }).empty()) {
    std::fputs(eikon::errorLine("'" + std::string(argv[1]) + "' is not an eikon command (" +
                                commandList(app) + "; run with --help)")
                   .c_str(),
               stderr);
    return 2;
  }
  // `eikon sweep`'s options are Python's (python/eikon/sweeps/run.py), its --help too.
  if (argc > 1 && std::string(argv[1]) == "sweep") {
    try {
      return eikon::cli::runSweepCommand(argc, argv);
    } catch (const eikon::cli::CliError& e) {
      std::fputs(eikon::errorLine(e.what()).c_str(), stderr);
      return e.exit_code;
    }
  }
  // A bad cache cap is refused before any work, not met when the first entry is saved.
  if (std::string error; !eikon::cacheMaxBytesSetting(&error)) {
    std::fputs(eikon::errorLine(error).c_str(), stderr);
    return 2;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::RequiredError& e) {
    if (!app.get_subcommands().empty()) {  // a command's own required option or argument
      std::fputs(eikon::errorLine(std::string(e.what()) + " (run with --help)").c_str(), stderr);
      return 2;
    }
    std::fputs(eikon::errorLine("a command is required: " + commandList(app) + " (run with --help)")
                   .c_str(),
               stderr);
    return 2;
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
