// Progress lines on stderr for work longer than a second: "eikon: rendering  42%".
#pragma once

#include <chrono>
#include <cstdio>
#include <string>
#include <unistd.h>

namespace eikon::cli {

class Progress {
 public:
  explicit Progress(bool quiet = false) : quiet_(quiet), tty_(::isatty(2)), start_(Clock::now()) {}
  /// Report `fraction` (0..1) of `stage`. Silent during the first second, then at most 4 lines/s
  /// (or in place on a terminal).
  void update(const std::string& stage, double fraction) {
    if (quiet_) return;
    auto now = Clock::now();
    if (now - start_ < std::chrono::seconds(1)) return;
    if (stage == last_stage_ && fraction < 1.0 && now - last_ < std::chrono::milliseconds(250)) return;
    last_ = now;
    last_stage_ = stage;
    int pct = int(fraction * 100.0 + 0.5);
    if (tty_) std::fprintf(stderr, "\r\033[Keikon: %s %3d%%", stage.c_str(), pct);
    else std::fprintf(stderr, "eikon: %s %3d%%\n", stage.c_str(), pct);
    printed_ = true;
  }
  void finish() {
    if (printed_ && tty_) std::fprintf(stderr, "\n");
    printed_ = false;
  }
  double elapsed() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }

 private:
  using Clock = std::chrono::steady_clock;
  bool quiet_, tty_;
  Clock::time_point start_, last_{};
  std::string last_stage_;
  bool printed_ = false;
};

}  // namespace eikon::cli
