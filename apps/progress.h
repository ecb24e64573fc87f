// Progress on stderr for long work: "eikon: rendering  42%  3.1 s, ETA 4.3 s".
//
// One printer for every stage of a command. The work reports (stage, fraction) as often as it
// likes, from any thread (the voxeliser per slab, the light simulators per time step, the view
// renderer per band of rows); the printer rate-limits what it prints:
//  * on a terminal (or with --progress always) one line per stage, redrawn in place at most 4
//    times a second on updates and at least once a second by a ticker thread, so the elapsed time
//    and the ETA move even while a piece of work runs long; a stage's first report and its 100%
//    are always shown. Without a terminal (--progress always into a file or pipe) each redraw is
//    a line of its own;
//  * otherwise (stderr not a terminal, or -q / --progress never) nothing: the command's summary
//    lines on stdout are all it prints.
// ETA = (1 − f) / (the rate f rose at over the last 10 s), counted down between reports: a
// recent rate follows work that slows down (the light simulator's last steps carry little flux
// but many small patches), where elapsed·(1 − f)/f would promise "0 s" for a minute. "ETA --"
// until half a second of progress is seen, or when the countdown ran out with the stage unfinished.
#pragma once

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <utility>

#include "apps/commands.h"

namespace eikon::cli {

enum class ProgressMode { Auto, Always, Never };

/// "auto" (a terminal on stderr decides), "always" or "never"; -q means never.
inline ProgressMode progressMode(const std::string& option, bool quiet) {
  // Checked even with --quiet: a bad word is refused, never ignored.
  if (option != "auto" && option != "always" && option != "never")
    throw CliError("--progress must be auto, always or never, got '" + option + "'");
  if (quiet || option == "never") return ProgressMode::Never;
  return option == "always" ? ProgressMode::Always : ProgressMode::Auto;
}

class Progress {
 public:
  explicit Progress(ProgressMode mode)
      : tty_(::isatty(2) != 0),
        live_(mode == ProgressMode::Always || (mode == ProgressMode::Auto && tty_)),
        grace_(mode == ProgressMode::Auto ? std::chrono::milliseconds(1000)
                                          : std::chrono::milliseconds(0)),
        start_(Clock::now()) {
    if (live_) ticker_ = std::thread([this] { tick(); });
  }
  ~Progress() { finish(); }
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  /// A stage whose fraction is not known (building GPU pipelines, uploading volumes): shown with
  /// its elapsed time only, "eikon: preparing the GPU  2.1 s", redrawn each second.
  void working(const std::string& stage) { update(stage, kUnknown); }

  /// Report `fraction` (0..1) of `stage`. Thread-safe; cheap when nothing is printed.
  void update(const std::string& stage, double fraction) {
    if (!live_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    const auto now = Clock::now();
    const bool new_stage = stage != stage_;
    if (new_stage) {
      if (printed_ && tty_) std::fputc('\n', stderr);  // keep the finished stage's last line
      stage_ = stage;
      stage_start_ = now;
      printed_ = false;
      samples_.clear();
    }
    const double before = new_stage ? 0.0 : fraction_;
    fraction_ = fraction == kUnknown ? kUnknown : std::clamp(fraction, 0.0, 1.0);
    const bool finishing = fraction_ >= 1.0 && before < 1.0;  // 100% is drawn once per stage
    reported_ = now;
    if (samples_.empty() || now - samples_.back().first >= std::chrono::milliseconds(250))
      samples_.emplace_back(now, fraction_);
    while (samples_.size() > 2 && now - samples_[1].first > std::chrono::seconds(10))
      samples_.pop_front();
    if (now - start_ < grace_ && !finishing) return;
    if (fraction_ >= 1.0 && !finishing) return;
    if (new_stage || !printed_ || finishing || now - drawn_ >= std::chrono::milliseconds(250))
      draw(now);
  }

  /// End the progress line (on a terminal) and stop the ticker. Called before summary lines.
  void finish() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (done_) return;
      done_ = true;
      if (printed_ && tty_) std::fputc('\n', stderr);
      printed_ = false;
    }
    wake_.notify_all();
    if (ticker_.joinable()) ticker_.join();
  }

 private:
  using Clock = std::chrono::steady_clock;
  static constexpr double kUnknown = -1.0;

  static std::string seconds(double s) {
    char buf[32];
    if (s < 60)
      std::snprintf(buf, sizeof buf, "%.1f s", s);
    else
      std::snprintf(buf, sizeof buf, "%d min %02d s", int(s / 60), int(s) % 60);
    return buf;
  }

  void draw(Clock::time_point now) {
    auto secs = [](Clock::duration d) { return std::chrono::duration<double>(d).count(); };
    if (fraction_ == kUnknown) {  // no fraction, no ETA: the elapsed time shows it is alive
      const std::string in_stage = seconds(secs(now - stage_start_));
      std::fprintf(stderr, tty_ ? "\r\033[Keikon: %s  %s" : "eikon: %s  %s\n", stage_.c_str(),
                   in_stage.c_str());
      std::fflush(stderr);
      drawn_ = now;
      printed_ = true;
      return;
    }
    std::string eta = "ETA --";
    if (fraction_ >= 1.0) {
      eta = "ETA " + seconds(0.0);
    } else if (!samples_.empty()) {
      const double span = secs(reported_ - samples_.front().first),
                   rise = fraction_ - samples_.front().second;
      const double left =
          span >= 0.5 && rise > 0 ? (1.0 - fraction_) * span / rise - secs(now - reported_) : -1.0;
      if (left > 0) eta = "ETA " + seconds(left);
    }
    const double pct = std::floor(fraction_ * 1000.0) / 10.0;  // 99.9% until it is done
    const std::string in_stage = seconds(secs(now - stage_start_));
    if (tty_)
      std::fprintf(stderr, "\r\033[Keikon: %s %5.1f%%  %s, %s", stage_.c_str(), pct,
                   in_stage.c_str(), eta.c_str());
    else
      std::fprintf(stderr, "eikon: %s %5.1f%%  %s, %s\n", stage_.c_str(), pct, in_stage.c_str(),
                   eta.c_str());
    std::fflush(stderr);
    drawn_ = now;
    printed_ = true;
  }

  /// Redraw once a second, so that elapsed time and ETA move while a piece of work runs long.
  void tick() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!done_) {
      wake_.wait_for(lock, std::chrono::seconds(1));
      const auto now = Clock::now();
      // A finished stage is not redrawn while the next has not started ("100%, ETA 0 s" for
      // seconds said nothing); the commands mark such gaps with working().
      if (done_ || stage_.empty() || fraction_ >= 1.0 || now - start_ < grace_) continue;
      if (now - drawn_ >= std::chrono::milliseconds(900)) draw(now);
    }
  }

  const bool tty_, live_;
  const Clock::duration grace_;
  const Clock::time_point start_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::thread ticker_;
  std::string stage_;
  double fraction_ = 0.0;
  std::deque<std::pair<Clock::time_point, double>> samples_;  ///< (time, fraction), ≥ 0.25 s apart
  Clock::time_point stage_start_{}, reported_{}, drawn_{};
  bool printed_ = false, done_ = false;
};

}  // namespace eikon::cli
