// What both twins of the polarised trace take and give (docs/polarisation.md): the
// settings, the beams leaving the scene and the check of a request. The CPU twin is
// core/reference/polarised_trace.h (tracePolarised), the GPU twin ViewRenderer::tracePolarised
// (shaders/polarised_trace.comp); both fill these plain structs so that tests and front ends
// (eikon trace --stokes, Python) drive and compare them the same way.
//
// Frames: an input Stokes vector is given in Mitsuba 3's stokesBasis of the ray direction, each
// beam's in the stokesBasis of its own direction (anisotropic/polarization.h).
#pragma once

#include <string>
#include <vector>

#include "anisotropic/polarization.h"
#include "core/contract/march_types.h"

namespace eikon {

struct PolarisedTraceSettings {
  double bandwidth_nm = 10.0;      ///< spectral width of one sample: coherence length λ²/Δλ
  double source_angle_rad = 1e-3;  ///< angular size of one light/environment sample
  int max_branches = 64;           ///< o/e ray-tree leaves (the GPU twin: at most 12)
  int max_events = 256;            ///< interface events per branch (the GPU twin: at most 48)
  std::vector<int> reflect_at;     ///< interface events (0-based per branch) that take the
                                   ///< reflected beam instead of the transmitted one (GPU: < 24)
  /// Renders (core/contract/polarised_render.h): each beam's `stokes` is the first ROW of its
  /// Mueller matrix (M00, M01, M02, M03: S0 out per input basis state) instead of M·input.
  bool mueller_row = false;
  /// What each branch follows at a crossing that transmits (docs/polarisation.md "Interfaces"):
  /// Single, the transmitted beam(s); Full, the reflected or the transmitted beam(s), chosen at
  /// random with the branch's unpolarised reflected power fraction p (transportUniform of the
  /// trace's seed; fields scaled by 1/√p or 1/√(1 − p), so every Mueller quantity stays unbiased),
  /// at most max_reflections choices per branch, transmitted only after them. A single trace
  /// (eikon trace --polarised) is Single and deterministic; renders take MarchSettings::transport.
  Transport transport = Transport::Single;
  int max_reflections = 32;  ///< Full: choices per branch, in [0, 1024] (MarchSettings's)
  /// Full: the path's first choice is split (both the reflected and the transmitted beams, their
  /// exact fields, the two sides added incoherently; FirstChoice) rather than drawn, as the scalar
  /// march's (MarchSettings::split_first_choice; renders take that one).
  bool split_first_choice = true;
};

/// One beam leaving the scene.
struct PolarisedBeam {
  glm::dvec3 exit_point{0.0};  ///< last point in the volume (the origin's line if it missed it)
  glm::dvec3 direction{0.0};   ///< unit energy direction
  glm::dvec3 frame_x{0.0};     ///< the Stokes reference direction, stokesBasis(direction)
  Stokes stokes{0.0};
  int branches = 0;         ///< o/e paths added into it
  int coherent_groups = 0;  ///< groups added incoherently (1: fully coherent sum)
  std::string modes;        ///< the branches' mode sequences, e.g. "o,e" ("-": no crystal)
};

struct PolarisedTrace {
  std::vector<PolarisedBeam> beams;  ///< by decreasing S0
  glm::dvec3 frame_x_in{0.0};        ///< the input Stokes reference direction
  bool truncated = false;            ///< max_branches or max_events cut the ray tree
  /// Σ S0 of the beams (what leaves the scene in all directions).
  double totalPower() const {
    double p = 0.0;
    for (const PolarisedBeam& b : beams) p += b.stokes[0];
    return p;
  }
};

/// Throws std::invalid_argument (one line) on a bad ray (zero or non-finite direction,
/// wavelength ≤ 0), input Stokes vector (S0 ≤ 0, non-finite, √(S1² + S2² + S3²) > S0) or settings
/// (bandwidth_nm finite > 0, source_angle_rad in (0, π], max_reflections in [0, 1024], each
/// named).
void checkPolarisedTrace(const TraceRequest& ray, const Stokes& input,
                         const PolarisedTraceSettings& settings);

}  // namespace eikon
