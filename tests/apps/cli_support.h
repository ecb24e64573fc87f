// Running the real `eikon` binary (EIKON_BINARY) as a user would, for the CLI tests.
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace eikon::test {

struct Outcome {
  int code;
  std::string out, err;
};

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Run `[env] PROGRAM ARGS` (ARGS as the shell splits them), capturing stdout and stderr through
/// files in `io_dir`. code is the exit status, or -1 when the program was killed by a signal.
inline Outcome runProgram(const std::string& program, const std::string& args, const std::filesystem::path& io_dir,
                          const std::string& env = "") {
  const std::string cmd = env + (env.empty() ? "" : " ") + program + " " + args + " >" + (io_dir / "stdout").string() +
                          " 2>" + (io_dir / "stderr").string() + " </dev/null";
  const int st = std::system(cmd.c_str());
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, slurp(io_dir / "stdout"), slurp(io_dir / "stderr")};
}

/// Run `[env] eikon ARGS`, capturing stdout and stderr through files in `io_dir`.
inline Outcome runEikon(const std::string& args, const std::filesystem::path& io_dir, const std::string& env = "") {
  return runProgram(EIKON_BINARY, args, io_dir, env);
}

}  // namespace eikon::test
