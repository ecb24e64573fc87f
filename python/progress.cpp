// Progress of the module's long calls on stderr: see progress.h.
#include "python/progress.h"

#include <cmath>
#include <cstdlib>
#include <stdexcept>

namespace eikon::python {

PyProgressMode pyProgressMode(const py::object& progress) {
  if (!progress.is_none()) {
    if (!py::isinstance<py::bool_>(progress))
      throw py::type_error("progress must be True, False or None, got " +
                           py::str(py::type::of(progress).attr("__name__")).cast<std::string>());
    return progress.cast<bool>() ? PyProgressMode::Always : PyProgressMode::Never;
  }
  const char* env = std::getenv("EIKON_PROGRESS");
  const std::string word = env ? env : "auto";
  if (word == "auto" || word.empty()) return PyProgressMode::Auto;
  if (word == "always" || word == "1") return PyProgressMode::Always;
  if (word == "never" || word == "0") return PyProgressMode::Never;
  throw std::invalid_argument("EIKON_PROGRESS must be auto, always or never (or 1, 0), got '" +
                              word + "'");
}

PyProgress::PyProgress(PyProgressMode mode) : mode_(mode) {
  if (mode_ == PyProgressMode::Never) return;
  try {
    tqdm_ = py::module_::import("tqdm").attr("tqdm");
  } catch (const py::error_already_set&) {
    tqdm_ = py::none();  // plain lines
  }
}

PyProgress::~PyProgress() {
  try {
    close();
  } catch (...) {  // never out of a destructor
  }
}

SessionProgress PyProgress::callbacks() {
  if (mode_ == PyProgressMode::Never) return {};
  return {[this](const char* what, double f) { report(what, f); },
          [this](const char* what) { report(what, -1.0); }};
}

void PyProgress::report(const std::string& stage, double fraction) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (failed_) return;
  const auto now = Clock::now();
  const bool new_stage = stage != stage_;
  const bool ends = fraction >= 1.0 && fraction_ < 1.0;
  if (!new_stage && !ends && now - last_ < std::chrono::milliseconds(100)) {
    fraction_ = std::max(fraction_, fraction);
    return;
  }
  last_ = now;
  if (new_stage) {
    stage_ = stage;
    stage_start_ = now;
    printed_fraction_ = -1;
    fraction_ = 0;
  }
  fraction_ = fraction < 0 ? fraction : std::max(fraction_, std::min(fraction, 1.0));
  py::gil_scoped_acquire gil;
  try {
    draw(stage, fraction_, new_stage);
  } catch (const py::error_already_set&) {
    failed_ = true;  // a closed or broken stderr: the call goes on without progress
  }
}

void PyProgress::draw(const std::string& stage, double fraction, bool new_stage) {
  const auto now = Clock::now();
  const double in_stage = std::chrono::duration<double>(now - stage_start_).count();
  if (!tqdm_.is_none()) {
    if (new_stage) {
      if (bar_) bar_.attr("close")();
      // Per mille, so that the bar moves smoothly; auto waits a second before showing a bar.
      bar_ = tqdm_(py::arg("total") = 1000, py::arg("desc") = "eikon: " + stage,
                   py::arg("leave") = true, py::arg("dynamic_ncols") = true,
                   py::arg("delay") = mode_ == PyProgressMode::Auto ? 1.0 : 0.0,
                   py::arg("bar_format") =
                       fraction < 0 ? "{desc}  {elapsed}"
                                    : "{desc} {percentage:5.1f}%|{bar}| {elapsed}<{remaining}");
    }
    if (fraction >= 0) {
      const long n = std::lround(fraction * 1000.0), at = bar_.attr("n").cast<long>();
      if (n > at) bar_.attr("update")(n - at);
    } else {
      bar_.attr("refresh")();
    }
    return;
  }
  // Plain lines: a stage's first report and its end, each 10% (at most one a second) or after
  // 10 s without a line; auto only once the call has run a second.
  if (new_stage) stage_printed_ = false;
  if (mode_ == PyProgressMode::Auto && now - start_ < std::chrono::seconds(1)) return;
  const bool end = fraction >= 1.0 && printed_fraction_ < 1.0;
  const bool step = fraction >= 0 && now - printed_ >= std::chrono::seconds(1) &&
                    std::floor(fraction * 10) > std::floor(printed_fraction_ * 10);
  if (stage_printed_ && !end && !step && now - printed_ < std::chrono::seconds(10)) return;
  if (stage_printed_ && fraction >= 1.0 && !end) return;  // the end once
  char line[256];
  if (fraction < 0)
    std::snprintf(line, sizeof line, "eikon: %s  %.1f s\n", stage.c_str(), in_stage);
  else
    std::snprintf(line, sizeof line, "eikon: %s %5.1f%%  %.1f s\n", stage.c_str(),
                  std::floor(fraction * 1000) / 10, in_stage);
  py::module_::import("sys").attr("stderr").attr("write")(std::string(line));
  printed_ = now;
  printed_fraction_ = fraction;
  stage_printed_ = true;
}

void PyProgress::close() {
  if (!bar_) return;
  py::object bar = std::move(bar_);
  bar_ = py::object();
  bar.attr("close")();
}

}  // namespace eikon::python
