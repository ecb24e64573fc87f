// `eikon sweep SWEEP.json -o DIR`: many renders of one kind on Dask distributed. The sweep is
// Python (python/eikon/sweeps, docs/sweep.md): this command runs `python3 -m eikon.sweeps` with
// its arguments, the interpreter and module of this build, and the exit status it gives.
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "apps/commands.h"

namespace eikon::cli {

void addSweepCommand(CLI::App& app) {
  CLI::App* sub = app.add_subcommand(
      "sweep", "Many renders of one kind on Dask: SWEEP.json's items into DIR/results.csv");
  sub->allow_extras();
  sub->prefix_command();
}

int runSweepCommand(int argc, char** argv) {
  const std::string python = EIKON_SWEEP_PYTHON, module_dir = EIKON_SWEEP_PYTHONPATH;
  std::error_code ec;
  if (!std::filesystem::exists(python, ec))
    throw CliError("eikon sweep needs " + python + " (the Debian interpreter the module is for)");
  if (!std::filesystem::is_directory(module_dir, ec))
    throw CliError("eikon sweep needs the eikon Python module, not built in " + module_dir +
                   " (build the target eikon_python)");
  const char* old = std::getenv("PYTHONPATH");
  const std::string path = module_dir + (old && *old ? ":" + std::string(old) : "");
  setenv("PYTHONPATH", path.c_str(), 1);
  std::vector<char*> args{const_cast<char*>(python.c_str()), const_cast<char*>("-m"),
                          const_cast<char*>("eikon.sweeps")};
  for (int i = 2; i < argc; ++i) args.push_back(argv[i]);
  args.push_back(nullptr);
  execv(python.c_str(), args.data());
  throw CliError("cannot run " + python + ": " + std::generic_category().message(errno));
}

}  // namespace eikon::cli
