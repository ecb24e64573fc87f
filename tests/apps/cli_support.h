// Running the real `eikon` binary (EIKON_BINARY) as a user would, for the CLI tests.
#pragma once

#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>

namespace eikon::test {

struct Outcome {
  int code;
  std::string out, err;
};

/// `s` as one single-quoted shell word (the runners pass their arguments through the shell).
inline std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Run `[env] PROGRAM ARGS` (ARGS as the shell splits them), capturing stdout and stderr through
/// files in `io_dir`. code is the exit status, or -1 when the program was killed by a signal.
inline Outcome runProgram(const std::string& program, const std::string& args,
                          const std::filesystem::path& io_dir, const std::string& env = "") {
  const std::string cmd = env + (env.empty() ? "" : " ") + program + " " + args + " >" +
                          (io_dir / "stdout").string() + " 2>" + (io_dir / "stderr").string() +
                          " </dev/null";
  const int st = std::system(cmd.c_str());
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, slurp(io_dir / "stdout"), slurp(io_dir / "stderr")};
}

/// runProgram with every file the program writes limited to `max_file_bytes` (RLIMIT_FSIZE, with
/// SIGXFSZ ignored so that a write beyond it fails with EFBIG): a full disk, reproducibly.
inline Outcome runProgramWithFileLimit(const std::string& program, const std::string& args,
                                       const std::filesystem::path& io_dir, long max_file_bytes) {
  const std::string cmd = program + " " + args + " >" + (io_dir / "stdout").string() + " 2>" +
                          (io_dir / "stderr").string() + " </dev/null";
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::signal(SIGXFSZ, SIG_IGN);  // ignored signals stay ignored across exec
    const rlimit lim{rlim_t(max_file_bytes), rlim_t(max_file_bytes)};
    ::setrlimit(RLIMIT_FSIZE, &lim);
    ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  int st = 0;
  if (pid < 0 || ::waitpid(pid, &st, 0) != pid) return {-1, "", ""};
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, slurp(io_dir / "stdout"), slurp(io_dir / "stderr")};
}

/// Start `PROGRAM ARGS` in the background (the shell execs it, so the id returned is the program's,
/// for kill(2)), its stdout and stderr captured through files in `io_dir`; with `max_file_bytes`
/// > 0 every file it writes is limited to that size, as runProgramWithFileLimit does. Collect it
/// with waitProgram.
inline pid_t startProgram(const std::string& program, const std::string& args,
                          const std::filesystem::path& io_dir, long max_file_bytes = 0) {
  const std::string cmd = "exec " + program + " " + args + " >" + (io_dir / "stdout").string() +
                          " 2>" + (io_dir / "stderr").string() + " </dev/null";
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (max_file_bytes > 0) {
      ::signal(SIGXFSZ, SIG_IGN);
      const rlimit lim{rlim_t(max_file_bytes), rlim_t(max_file_bytes)};
      ::setrlimit(RLIMIT_FSIZE, &lim);
    }
    ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  return pid;
}

/// Wait for a program startProgram started; code -1 when a signal killed it.
inline Outcome waitProgram(pid_t pid, const std::filesystem::path& io_dir) {
  int st = 0;
  if (pid < 0 || ::waitpid(pid, &st, 0) != pid) return {-1, "", ""};
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, slurp(io_dir / "stdout"), slurp(io_dir / "stderr")};
}

/// Run `[env] eikon ARGS`, capturing stdout and stderr through files in `io_dir`.
inline Outcome runEikon(const std::string& args, const std::filesystem::path& io_dir,
                        const std::string& env = "") {
  return runProgram(EIKON_BINARY, args, io_dir, env);
}

/// A fresh folder under the system's temporary directory, named `stem_XXXXXX`, with an `io`
/// subfolder for the runners' captured output; removed with everything in it when it goes.
class TempDir {
 public:
  explicit TempDir(const std::string& stem) {
    std::string tmpl = (std::filesystem::temp_directory_path() / (stem + "_XXXXXX")).string();
    if (::mkdtemp(tmpl.data()) == nullptr)
      throw std::runtime_error("cannot create a temporary folder " + tmpl);
    path_ = tmpl;
    std::filesystem::create_directories(path_ / "io");
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace eikon::test
