// Progress of the module's long calls (render, simulate_light) on stderr, as Python users expect
// it: a tqdm bar per stage ("voxelising", "light 1 light x 12 bands x 1 mode", "rendering"), or,
// where tqdm is not installed, plain lines ("eikon: rendering  40%  3.1 s") at each 10% or after
// 10 s without one.
//
// The keyword `progress=` of those calls: None (the default) takes $EIKON_PROGRESS ("auto",
// "always" or "never"; unset: auto), True is always, False never. auto shows a stage only once it
// has run a second (tqdm's delay), so quick calls print nothing; always shows every stage at
// once.
//
// The session reports from its worker threads while the calling thread has released the GIL
// (Prepared::run): each report is rate-limited here (a stage's start and end, else at most ten
// a second) before the GIL is taken to draw it. An error while drawing (a closed stderr) turns
// the progress off for the rest of the call, never fails the call.
#pragma once

#include <pybind11/pybind11.h>

#include <chrono>
#include <memory>
#include <mutex>
#include <string>

#include "core/session/session.h"

namespace eikon::python {
namespace py = pybind11;

enum class PyProgressMode { Auto, Always, Never };

/// The mode of a call's `progress=` keyword (None, True or False; see above). A bad
/// $EIKON_PROGRESS is a ValueError naming it.
PyProgressMode pyProgressMode(const py::object& progress);

class PyProgress {
 public:
  /// Made and destroyed with the GIL held (the call's own thread).
  explicit PyProgress(PyProgressMode mode);
  ~PyProgress();
  PyProgress(const PyProgress&) = delete;
  PyProgress& operator=(const PyProgress&) = delete;

  /// The callbacks to hand the session (empty ones for Never).
  SessionProgress callbacks();
  /// Close the last stage's bar (GIL held); the destructor calls it too.
  void close();

 private:
  using Clock = std::chrono::steady_clock;
  void report(const std::string& stage, double fraction);
  void draw(const std::string& stage, double fraction, bool new_stage);  // GIL held

  PyProgressMode mode_;
  std::mutex mutex_;
  py::object tqdm_;  ///< the tqdm class, or None for plain lines
  py::object bar_;   ///< the current stage's bar
  std::string stage_;
  double fraction_ = 0, printed_fraction_ = -1;
  Clock::time_point start_ = Clock::now(), stage_start_ = start_, last_ = {}, printed_ = {};
  bool failed_ = false, stage_printed_ = false;
};

/// Runs f with the session's progress set to `progress` and cleared afterwards (also when f
/// throws), so that a session shared by module-level calls never keeps a finished call's printer.
template <class F>
decltype(auto) withProgress(Session& s, PyProgress& progress, F&& f) {
  struct Clear {
    Session& s;
    ~Clear() { s.setProgress({}); }
  } clear{s};
  s.setProgress(progress.callbacks());
  return f();
}

}  // namespace eikon::python
