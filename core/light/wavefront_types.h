// The wavefront both light simulators share (docs/design.md §2 "Light simulator",
// docs/light-simulator.md): its settings, its patches, the statistics of a run and the result
// volumes. The CPU twin (core/reference/wavefront.h, WavefrontSimulator, double precision) and the
// GPU twin (core/render/light_simulator.h, GpuWavefront) take the same settings and return the
// same result, which is how the tests hold one to the other; both start from the same seed patches
// (core/light/seeding.h). The method and the units are described in core/reference/wavefront.h.
//
//   eikon::WavefrontSettings s;          // s.wavelength_nm, s.mode, s.splat, …
//   eikon::WavefrontResult r = simulator.run(scene.lights[0]);   // either twin
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <functional>
#include <glm/glm.hpp>
#include <vector>

namespace eikon {

struct WavefrontSettings {
  enum class Splat {
    Accumulate,  ///< Σ over steps of flux·Δs / voxel volume: fluence rate (scalar irradiance),
                 ///< W/mm²
    HighestEnergy,  ///< the largest patch irradiance flux/area (W/mm²) whose centre visited the
                    ///< voxel
  };
  double dt = 0.0;  ///< time step (mm of light travel in vacuum); ≤ 0: 0.5·h of the splat grid
  int max_steps = 20000;  ///< hard cap on the number of steps
  /// Kill a patch whose flux falls below this fraction of its seed's flux, by attenuation or by
  /// splitting (a split halves or quarters it): 1e-4 allows ~6 generations of quarters (~13 of
  /// halves) without absorption.
  /// This also ends patches trapped in whispering-gallery orbits, which stretch and split forever.
  double min_energy_fraction = 1e-4;
  double split_span_voxels =
      1.0;                        ///< split a patch when an edge is longer than this (splat voxels)
  double seed_span_voxels = 0.5;  ///< edge of the seed patches (directional: in the launch plane)
  /// true: a patch stretched past the split span along one pair of opposite edges only is split
  /// into two halves across them (with both pairs too long, into four quarters). false (the
  /// default): every split makes quarters. Halves make fewer patches where a fan ends before the
  /// energy threshold (sharp caustic_sphere 128³: 0.78× the patches, 0.9× the time) but carry the
  /// long fans of light grazing a smoothed interface on to 10⁴ children per seed where quarters
  /// reach the threshold at ~100 across (smoothed caustic_sphere 32³: 1.2× the patches, 2.3× the
  /// time; docs/light-simulator.md "Split"). light_bench --split halves,quarters compares them.
  bool split_halves = false;
  Splat splat = Splat::Accumulate;
  double wavelength_nm = 587.56;  ///< index and attenuation band are evaluated here
  int max_patches = 1 << 20;      ///< live patches never exceed this: splits beyond it are refused
  /// Point lights: radius of the launch sphere (mm; ≤ 0: 0.5·h) and cube-sphere cells per face
  /// edge.
  double point_radius = 0.0;
  int point_cells_per_face = 16;
  /// Optional probe plane {x : x[probe_axis] = probe_position} (axis −1: none). The net flux whose
  /// patch centres cross it in the +axis direction is reported in stats.flux_probe.
  int probe_axis = -1;
  double probe_position = 0.0;
  /// Propagated mode: 0 = ordinary (or isotropic: the index `Field::index`), 1 = extraordinary
  /// (uniaxial media: n_o, n_e = `Field::indexE`, the axis `Field::axisField`, attenuation
  /// σ(θ)·cos ρ from `medium`/`mediumE`). A single run carries one mode; for unpolarised light
  /// run both and give each half of the light's power (no Fresnel, so nothing couples the modes).
  int mode = 0;
  /// Narrow beams and spots: at least this many seed-patch edges across the beam radius
  /// (directional light with beam_radius > 0: seed edge = min(seed_span_voxels·h, beam_radius /
  /// beam_min_cells)) or across the cone's radius on the unit cube (spot: cells per face edge
  /// N ≥ max(point_cells_per_face, ⌈2·beam_min_cells / tan(half-angle)⌉), at most 4096).
  int beam_min_cells = 8;
  /// Fold caustics: false (Tevs; the default here) ends a patch whose orientation flips, counting
  /// its flux under `caustic`; true lets it cross with its orientation reference reversed, as
  /// geometric optics has it (the ray tube goes through the focal line and opens again), counted
  /// in stats.caustic_crossings (CPU only). Renders use true: otherwise the light beyond a focus,
  /// a cone in smoke or the halo round a ball lens's spot, is missing. Accumulate splats stay
  /// finite through a caustic (flux·Δs); HighestEnergy (flux/area) peaks there.
  bool pass_caustics = false;
  /// Straight steps across homogeneous regions: when the centre and all four corners lie in
  /// voxels of skip distance D ≥ 2 (`Field::skipDistance`; VolumeSet: every field is constant
  /// within D − 1 voxels), the patch advances k constant-time steps at once along straight lines
  /// (x += k·dt·dx/dt, w unchanged), exact there. k keeps every point within (D − 1.5) voxels of
  /// its start and stops at the first step where single steps would split, kill (caustic, left,
  /// energy) or reach max_steps, so events fall on the same steps; the centre's path is splatted
  /// into every voxel it crosses (flux·length/h³). See docs/light-simulator.md, "Straight steps".
  bool skip_empty = true;
  /// Threads of run() (0: hardware concurrency, at most 8; 1: single-threaded). Each step's
  /// patch list is cut into `threads` contiguous chunks, chunk c always on thread c, each with
  /// its own splat volumes (40 bytes per splat voxel for each thread after the first) and
  /// statistics, reduced in chunk order at the end: a given thread count gives bit-identical
  /// results run to run. For any count the patch lists, steps, splits, refused splits, kills by
  /// reason and max_live are those of one thread (a step in which the patch budget binds redoes
  /// its splitting serially); flux sums and volumes differ from one thread's only by summation
  /// order (a sum of m terms by up to ~2m·2⁻⁵³ relative; glass-sphere test: ≤ 5e-12). The Field
  /// must allow concurrent calls (VolumeField does; an AnalyticField's function must too).
  int threads = 0;
  /// Sharp interfaces (docs/light-simulator.md, "Sharp interfaces"): GpuWavefront
  /// refracts at the volume's exact boundaries where they apply (a boundary field, i.e.
  /// "interfaces": "sharp", and a homogeneous medium in every region: sharpLightApplies,
  /// core/light/lighting.h) instead of bending through the smoothed field. The CPU twin takes its
  /// SharpInterfaces explicitly (WavefrontSimulator's constructor) and ignores this flag; the
  /// lighting drivers of both twins set it from LightingOptions::sharp_interfaces.
  bool sharp_interfaces = false;
  /// Sharp interfaces whose crossings are found on the shapes or their planes (BoundaryField::
  /// exact or convex_apart): a straight step may run each corner up to just before its next
  /// boundary, searched along its straight line (true), not only (D − 1.5) voxels on the skip
  /// distances (false: for comparison). Exact either way; it changes how many steps a run takes.
  bool straight_to_boundary = true;
  /// Sharp interfaces: reflected generations followed (docs/light-simulator.md, "Reflected
  /// wavefronts"). Where a patch's corners transmit at a crossing, the reflected part R of the flux
  /// becomes a reflected copy of the patch, one generation deeper, up to this depth; past it the
  /// reflected power is dropped into stats.flux_reflected. 0: no reflected wavefronts (the
  /// transmitted path alone). LightingOptions::max_reflection_generations sets it for renders.
  int max_reflection_generations = 0;
  /// Called after every time step (CPU) or dispatch of steps (GPU) with an estimate of the run's
  /// fraction done (wavefrontRunFraction), from the thread that called run(); may be empty.
  /// Not part of the physics (not in the light cache key).
  std::function<void(double)> progress;
};

/// Estimated fraction of a run done, for progress: the larger of the flux fraction that has ended
/// (left the volume, absorbed, killed) and the front's travel against the volume diagonal (the
/// front moves dt/n mm per step, so in a dense medium the travel estimate runs ahead: capped at
/// 0.95 until the flux says otherwise). Non-decreasing over a run.
inline double wavefrontRunFraction(long long steps, double dt, const glm::dvec3& extent,
                                   double flux_ended, double flux_emitted) {
  const double travel = std::min(0.95, double(steps) * dt / std::max(glm::length(extent), 1e-12));
  const double ended = flux_emitted > 0 ? std::clamp(flux_ended / flux_emitted, 0.0, 1.0) : 0.0;
  return std::max(travel, ended);
}

/// One wavefront element. Corners are in bilinear order (0,0), (1,0), (1,1), (0,1) of the patch's
/// ray-label parameters. `energy` is the flux carried by the tube (W = light unit·mm² for a
/// directional light, light unit·sr for a point light); `area0` the area (mm²) at launch.
struct Patch {
  std::array<glm::dvec3, 4> x{};  ///< corner positions (mm)
  std::array<glm::dvec3, 4> w{};  ///< corner wave vectors w = n·t̂
  double energy = 0.0;            ///< flux (W)
  double area0 = 0.0;             ///< launch area (mm²) of the tube this patch carries
  // Bookkeeping (not part of the physics state):
  double transmittance = 1.0;  ///< exp(−∫σ ds) so far
  double seed_energy = 0.0;    ///< flux of the seed patch this one descends from
  int orientation = 1;         ///< sign of (normal · mean w) at launch; a change is a caustic
  bool entered = false;        ///< the centre has been inside the field's bounds
  int probe_side = 0;          ///< −1 / +1: side of the probe plane the centre is on
  int steps = 0;               ///< time steps taken (a straight step of k counts k)
  /// Sharp interfaces: each corner's region of the boundary field, and a bit per corner set after
  /// an odd number of total internal reflections (a mirror reverses the orientation).
  std::array<int, 4> region{};
  unsigned mirrored = 0;
  /// Sharp interfaces: each corner's count of boundary events (region changes and total internal
  /// reflections). The corners of a patch that one boundary is crossing differ by at most one, and
  /// those with equal counts agree on region and mirror; otherwise the patch is torn (see
  /// WavefrontStats::tears).
  std::array<int, 4> events{};
  /// Sharp interfaces: each corner's digest of the polyhedron faces it crossed (faceDigest, 6
  /// bits; unchanged by crossings whose face the search does not give).
  /// Corners of equal event counts but different digests crossed different facets: torn too.
  std::array<int, 4> faces{};
  /// Sharp interfaces, reflected wavefronts (WavefrontSettings::max_reflection_generations): the
  /// reflection depth (0: the light's own wavefront; a reflected copy is one deeper); the corners
  /// that turn back at their next crossing instead of going through (bit k: corner k of a reflected
  /// copy that has not reached the interface yet); `shadow`, the flux still to be reflected into
  /// the patch as those corners reflect (the flux its transmitted twin carries, attenuated as this
  /// patch is: each pending corner's crossing moves shadow·(1 − T^¼) into `energy`); `armed`: the
  /// copy for the crossing the patch is about to take has been made (its next step makes none).
  int generation = 0;
  unsigned pending = 0;
  double shadow = 0.0;
  bool armed = false;
  /// Set by a step that spawns a reflected copy, for the emission after it (not carried on).
  bool spawn = false;
};

/// The face digest of a corner (Patch::faces) after it crossed plane `face` (≥ 0) of region
/// `owner`'s polyhedron: 6 bits, as the GPU twin keeps it in its corner word (wavefront.comp
/// faceDigest). Faces of one shape differ in their first crossing; later collisions (1 in 64)
/// only leave a tear unseen.
inline int faceDigest(int h, int owner, int face) { return (h * 17 + 7 * owner + face + 1) & 63; }

struct WavefrontStats {
  int steps = 0;  ///< most time steps taken by one patch (a straight step of k counts k)
  size_t straight_steps = 0;       ///< straight steps taken (each covering k ≥ 1 time steps)
  size_t straight_time_steps = 0;  ///< time steps covered by them (Σ k)
  size_t seeded = 0;               ///< patches launched toward the volume
  size_t max_live = 0;             ///< most live patches at once
  size_t splits = 0;               ///< parents split into four (quarters)
  /// parents split into two halves (stretched along one pair of opposite edges only;
  /// WavefrontSettings::split_halves). Patches made: seeded + 4·splits + 2·halvings.
  size_t halvings = 0;
  size_t splits_refused = 0;  ///< splits not done because max_patches would be exceeded
  /// Sharp interfaces: torn patches (corners that met different boundaries, or one boundary with
  /// different outcomes) replaced by four pencils, one along each corner's ray (counted in
  /// `splits` too: each adds three patches)
  size_t tears = 0;
  /// Sharp interfaces: reflected copies made (max_reflection_generations; a copy the patch budget
  /// refuses counts in splits_refused)
  size_t reflections = 0;
  size_t kills_left = 0, kills_caustic = 0, kills_energy = 0, kills_opaque = 0;
  size_t live_at_end = 0;    ///< patches still alive when max_steps ran out (0 if the loop ended)
  double flux_emitted = 0;   ///< Σ seed flux (only seeds whose centre ray meets the volume)
  double flux_left = 0;      ///< carried out of the volume
  double flux_caustic = 0;   ///< carried by patches killed at an orientation flip
  double flux_energy = 0;    ///< carried by patches killed below the energy threshold
  double flux_absorbed = 0;  ///< removed by exp(−σΔs) along the way, plus opaque kills
  /// Sharp interfaces: Fresnel reflection (1 − T) at them not followed as a reflected wavefront
  /// (beyond max_reflection_generations, or a copy refused by the patch budget): the flux lost at
  /// the crossings less the flux the reflected copies took up
  double flux_reflected = 0;
  double flux_live_at_end = 0;
  double flux_probe = 0;  ///< net flux crossing the probe plane in the +axis direction
  /// Flux of patches that ended (any reason, or still live at max_steps) on the upstream side of
  /// the probe plane. Without absorption, flux_probe + flux_ended_before_probe = flux_emitted.
  double flux_ended_before_probe = 0;
  size_t caustic_crossings = 0;  ///< orientation flips passed (pass_caustics; CPU reference only)
  size_t interface_events = 0;   ///< sharp interfaces: corner refractions and reflections
  glm::dvec3 caustic_centroid{
      0.0};  ///< flux-weighted mean centre of the patches killed at caustics
  /// Probe plane: (net) flux-weighted mean of the points where patch centres cross it (mm; the
  /// centre's path over the step, interpolated linearly to the plane), and the flux-weighted mean
  /// unit direction of the centres' motion there (the ray, i.e. energy, direction; not
  /// normalised: its length is < 1 where directions differ). Zero if nothing crossed.
  glm::dvec3 probe_centroid{0.0};
  glm::dvec3 probe_direction{0.0};
};

/// Volumes on the splat grid (x-fastest, Grid::index order).
struct WavefrontResult {
  /// Accumulate: fluence rate (W/mm²) = Σ over steps and patches whose step midpoint lies in the
  /// voxel of flux·Δs_path / h³ — for a single collimated beam this is the irradiance across the
  /// beam. HighestEnergy: the highest patch irradiance flux/area (W/mm²) seen in the voxel.
  std::vector<float> irradiance;
  /// xyz: flux·Δs-weighted mean of the unit propagation direction (length < 1 where directions
  /// disagree); w: the weight Σ flux·Δs / h³ (W/mm², the Accumulate value whatever the mode).
  std::vector<glm::vec4> direction;
  WavefrontStats stats;
};

}  // namespace eikon
