// Progress on stderr for long work: "eikon: rendering  42%  3.1 s, ETA 4.3 s".
//
// One printer for every stage of a command. The work reports (stage, fraction) as often as it
// likes, from any thread (the voxeliser per slab, the light simulators per time step, the view
// renderer per band of rows); the printer rate-limits what it prints:
//  * on a terminal (auto or --progress always) one line per stage, redrawn in place at most 4
//    times a second on updates and at least once a second by a ticker thread, so the elapsed time
//    and the ETA move even while a piece of work runs long; a stage's first report and its 100%
//    are always shown;
//  * not on a terminal (a file, a pipe, a CI log) plain lines, no carriage returns: a stage's
//    first report, a line each time it passes another 10% (at most one a second) or after 10 s
//    without one, and its 100%. With --progress always from the start; with auto only once the
//    command has run 10 s, or at once after a cost line said the work is long (note()), so a
//    short command prints nothing but its summary;
//  * -q / --progress never: nothing (note() lines included).
// ETA = (1 − f) / (the rate f rose at over the last 10 s), counted down between reports: a
// recent rate follows work that slows down, where elapsed·(1 − f)/f would promise "0 s" for a
// minute. "ETA --" until half a second of progress is seen, when the countdown ran out with the
// stage unfinished, or when the recent rate and the stage's mean rate differ more than 4 times
// (the fraction is then a poor measure of the work left).
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

/// How often lines are printed where stderr is not a terminal (tests shorten the times).
struct ProgressPacing {
  std::chrono::milliseconds quiet_for{10000};   ///< auto: nothing before the command ran this long
  std::chrono::milliseconds line_every{10000};  ///< a line after this long without one
  std::chrono::milliseconds line_gap{1000};     ///< at most one line per gap (but a stage's 100%)
  double step = 0.1;                            ///< and a line each time a stage passes a step
};

class Progress {
 public:
  explicit Progress(ProgressMode mode, ProgressPacing pacing = {}, std::FILE* out = stderr,
                    bool tty = ::isatty(2) != 0)
      : out_(out),
        tty_(tty),
        live_(mode == ProgressMode::Always || (mode == ProgressMode::Auto && tty_)),
        lines_(!tty_ && mode == ProgressMode::Auto),
        pacing_(pacing),
        grace_(mode == ProgressMode::Auto && tty_ ? std::chrono::milliseconds(1000)
                                                  : std::chrono::milliseconds(0)),
        start_(Clock::now()) {
    if (live_ || lines_) ticker_ = std::thread([this] { tick(); });
  }
  ~Progress() { finish(); }
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  /// A stage whose fraction is not known (building GPU pipelines, uploading volumes): shown with
  /// its elapsed time only, "eikon: preparing the GPU  2.1 s", redrawn each second.
  void working(const std::string& stage) { update(stage, kUnknown); }

  /// Report `fraction` (0..1) of `stage`. Thread-safe; cheap when nothing is printed.
  void update(const std::string& stage, double fraction) {
    if (!live_ && !lines_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    const auto now = Clock::now();
    const bool new_stage = stage != stage_;
    if (new_stage) {
      if (printed_ && tty_) std::fputc('\n', out_);  // keep the finished stage's last line
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
    if (!showing(now)) return;
    if (now - start_ < grace_ && !finishing) return;
    if (fraction_ >= 1.0 && !finishing) return;
    if (new_stage || !printed_ || finishing) return draw(now);
    if (tty_) {
      if (now - drawn_ >= std::chrono::milliseconds(250)) draw(now);
    } else if (now - drawn_ >= pacing_.line_gap && fraction_ != kUnknown &&
               std::floor(fraction_ / pacing_.step) > std::floor(drawn_fraction_ / pacing_.step)) {
      draw(now);  // another 10% passed
    }
  }

  /// A line of its own ("eikon: cost: ..."), printed unless progress is off (-q, --progress never);
  /// `long_work`: the line announces long work, so auto without a terminal starts its progress
  /// lines now instead of after its quiet time.
  void note(const std::string& line, bool long_work) {
    if (!live_ && !lines_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    if (long_work) awake_ = true;
    if (!live_ && !awake_) return;
    if (printed_ && tty_) std::fputs("\r\033[K", out_);  // the progress line is redrawn after it
    std::fprintf(out_, "eikon: %s\n", line.c_str());
    std::fflush(out_);
    printed_ = false;
  }

  /// End the progress line (on a terminal) and stop the ticker. Called before summary lines.
  void finish() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (done_) return;
      done_ = true;
      if (printed_ && tty_) std::fputc('\n', out_);
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

  /// Whether lines are printed now: always live ones; auto's plain lines once the command has run
  /// its quiet time or a note announced long work.
  bool showing(Clock::time_point now) {
    if (live_) return true;
    if (!awake_ && now - start_ >= pacing_.quiet_for) awake_ = true;
    return awake_;
  }

  void draw(Clock::time_point now) {
    auto secs = [](Clock::duration d) { return std::chrono::duration<double>(d).count(); };
    drawn_ = now;
    drawn_fraction_ = fraction_;
    printed_ = true;
    const std::string in_stage = seconds(secs(now - stage_start_));
    if (fraction_ == kUnknown) {  // no fraction, no ETA: the elapsed time shows it is alive
      std::fprintf(out_, tty_ ? "\r\033[Keikon: %s  %s" : "eikon: %s  %s\n", stage_.c_str(),
                   in_stage.c_str());
      std::fflush(out_);
      return;
    }
    std::string eta = "ETA --";
    if (fraction_ >= 1.0) {
      eta = "ETA " + seconds(0.0);
    } else if (!samples_.empty()) {
      const double span = secs(reported_ - samples_.front().first),
                   rise = fraction_ - samples_.front().second;
      double left =
          span >= 0.5 && rise > 0 ? (1.0 - fraction_) * span / rise - secs(now - reported_) : -1.0;
      // A recent rate more than 4 times the stage's mean rate, or less than a quarter of it, says
      // the fraction is a poor measure of the work (the light simulator's last patches carry a
      // fraction of a percent of the flux for half of its time): no ETA then, rather than one
      // that jumps between seconds and an hour.
      const double stage = secs(reported_ - stage_start_),
                   whole = fraction_ > 0 ? (1.0 - fraction_) * stage / fraction_ : -1.0;
      if (left > 0 && whole > 0 && (left > 4.0 * whole || 4.0 * left < whole)) left = -1.0;
      if (left > 0) eta = "ETA " + seconds(left);
    }
    const double pct = std::floor(fraction_ * 1000.0) / 10.0;  // 99.9% until it is done
    std::fprintf(out_, tty_ ? "\r\033[Keikon: %s %5.1f%%  %s, %s" : "eikon: %s %5.1f%%  %s, %s\n",
                 stage_.c_str(), pct, in_stage.c_str(), eta.c_str());
    std::fflush(out_);
  }

  /// On a terminal redraw once a second, so that elapsed time and ETA move while a piece of work
  /// runs long; elsewhere a line after line_every without one.
  void tick() {
    std::unique_lock<std::mutex> lock(mutex_);
    const auto period = tty_ ? std::chrono::milliseconds(900) : pacing_.line_every;
    while (!done_) {
      wake_.wait_for(lock, tty_ ? std::chrono::milliseconds(1000)
                                : std::min<Clock::duration>(pacing_.line_every,
                                                            std::chrono::milliseconds(1000)));
      const auto now = Clock::now();
      // A finished stage is not redrawn while the next has not started ("100%, ETA 0 s" for
      // seconds said nothing); the commands mark such gaps with working().
      if (done_ || stage_.empty() || fraction_ >= 1.0 || now - start_ < grace_) continue;
      if (!showing(now)) continue;
      if (!printed_ || now - drawn_ >= period) draw(now);
    }
  }

  std::FILE* const out_;
  const bool tty_, live_, lines_;  ///< lines_: auto without a terminal (after its quiet time)
  const ProgressPacing pacing_;
  const Clock::duration grace_;
  const Clock::time_point start_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::thread ticker_;
  std::string stage_;
  double fraction_ = 0.0, drawn_fraction_ = 0.0;
  std::deque<std::pair<Clock::time_point, double>> samples_;  ///< (time, fraction), ≥ 0.25 s apart
  Clock::time_point stage_start_{}, reported_{}, drawn_{};
  bool printed_ = false, done_ = false, awake_ = false;
};

}  // namespace eikon::cli
