// Shared between C++ and GLSL (vk_mini_path_tracer style): binding numbers, workgroup sizes and
// the parameter/record structs of the view and trace kernels, declared once. vec4/ivec4 members
// only, so std430 (GLSL) and C++ agree without padding rules; the C++ side static_asserts sizes.
// GLSL reads this file too, and its tables of offsets are aligned by hand:
// clang-format off
#ifndef EIKON_SHARED_H
#define EIKON_SHARED_H

#ifdef __cplusplus
#include <glm/glm.hpp>
#include <cstdint>
namespace eikon::gpu {
using vec4 = glm::vec4;
using ivec4 = glm::ivec4;
using uvec4 = glm::uvec4;
#endif

#define EIKON_WG_X 8
#define EIKON_WG_Y 8
#define EIKON_TRACE_WG 64

// Descriptor bindings (set 0).
#define EIKON_B_PARAMS 0
#define EIKON_B_INDEX_O_A 1
#define EIKON_B_INDEX_O_B 2
#define EIKON_B_INDEX_O_C 3
#define EIKON_B_INDEX_E_A 4
#define EIKON_B_INDEX_E_B 5
#define EIKON_B_INDEX_E_C 6
#define EIKON_B_MEDIUM_O 7
#define EIKON_B_MEDIUM_E 8
#define EIKON_B_EMISSION 9
#define EIKON_B_AXIS 10
#define EIKON_B_ENV_IMAGE 11
#define EIKON_B_TABLES 12
#define EIKON_B_OUTPUT 13
#define EIKON_B_RAYS 14
#define EIKON_B_SCATTER 15        // (albedo rgb, HG g) — VolumeSet::scatter
#define EIKON_B_LIGHT_FLUENCE 16  // (φ_r, φ_g, φ_b, φ_Y) simulated fluence rate — VolumeSet::light_fluence
#define EIKON_B_LIGHT_FLUX 17     // (F_x, F_y, F_z, 0) net flux vector of φ_Y — VolumeSet::light_flux
// The sharp-boundary field (core/volume/boundary.h; shaders/boundary.glsl): region ids (R32_UINT),
// distances in voxels (R32_SFLOAT) and the shape table (vec4 records, layout below). A smoothed
// scene binds 1-voxel placeholders (region 0, distance = cap) and an empty table.
#define EIKON_B_REGION 18
#define EIKON_B_BOUNDARY_DIST 19
#define EIKON_B_SHAPES 20
#define EIKON_B_BOUNDARY_QUERIES 21  // boundary_probe.comp only (tests: GPU vs CPU twin)
// The medium table of the sharp march (core/volume/media.h packMediaTable): EIKON_MEDIUM_VEC4S
// vec4s per region; flag bits of row 7's w as kMedium* there.
#define EIKON_B_MEDIA 22
#define EIKON_MEDIUM_VEC4S 22
// The same two tables as uniform blocks for the view kernels (march.glsl), padded to fixed sizes
// within Vulkan's guaranteed 16 KiB: the shape table's first EIKON_EXACT_MAX_ROWS rows (all of it on
// the exact path) and the medium table when it has at most EIKON_SMALL_MEDIA_REGIONS regions
// (EIKON_F_SMALL_MEDIA). llvmpipe reads a storage buffer one lane at a time in a loop, a uniform
// block with a vector gather, or one load where the index is constant.
#define EIKON_B_EXACT_ROWS 24
#define EIKON_B_SMALL_MEDIA 25
// view.comp, stratified spectral renders whose passes march one wavelength each (crystals, opaque
// or attenuating scenes): per pixel of the image, 1 where the pixel sample's first pass found its
// path independent of λ and added every wavelength from its lookups (the later passes skip it).
#define EIKON_B_SHARED_PATHS 26
#define EIKON_EXACT_MAX_ROWS 256
#define EIKON_SMALL_MEDIA_REGIONS 46  // 46 · 22 vec4s · 16 bytes ≤ 16 KiB
#define EIKON_MEDIUM_HOMOGENEOUS 1
#define EIKON_MEDIUM_UNIAXIAL 2
#define EIKON_MEDIUM_RADIAL_AXIS 4
#define EIKON_MEDIUM_GRIN 8
#define EIKON_MEDIUM_OPAQUE 16
#define EIKON_MEDIUM_BIAXIAL 32

// ViewParams.flags bits.
#define EIKON_F_DISPERSIVE 1
#define EIKON_F_UNIAXIAL 2
#define EIKON_F_SPECTRAL 4
#define EIKON_F_NO_SKIP 8
#define EIKON_F_NO_FRESNEL 16
#define EIKON_F_ATTENUATION 32  // some σ ≠ 0: sample the medium images
#define EIKON_F_EMISSION 64     // some emission ≠ 0
#define EIKON_F_OPACITY 128     // some opaque object
#define EIKON_F_SCATTER 256     // some material has an albedo (in-scatter or a diffuse surface)
#define EIKON_F_LIT 512         // light volumes from the light simulator are bound
#define EIKON_F_SHARP 1024      // sharp interfaces: march region by region (shaders/sharp.glsl)
#define EIKON_F_VARYING 2048    // sharp: some region's medium varies in space (GRIN, radial axis)
#define EIKON_F_CONVEX 4096     // sharp: some region's shape is a convex polyhedron (plane loops)
#define EIKON_F_MESH 8192       // sharp: some region's shape is a non-convex mesh (BVH traversal)
// sharp: every shape is a convex polyhedron, apart from the others (core/volume/boundary.h
// convex_apart): crossings come from the planes (boundary.glsl convexCrossing), no cell walk.
#define EIKON_F_CONVEX_APART 16384
// sharp: every shape is analytic and they are not convex_apart (core/volume/boundary.h exact):
// crossings and regions on the shapes (boundary.glsl exactCrossingOutOf), no voxel read.
#define EIKON_F_EXACT 32768
// The scene's environment kind (march.glsl environmentRgb): none of the two is the checkerboard.
// Scene features like the others, so that a kernel holds the lookup of its own kind only (lavapipe
// runs every branch: the latlong lookup's four storage-buffer reads cost the others as much).
#define EIKON_F_ENV_CONSTANT 65536
#define EIKON_F_ENV_LATLONG 131072
// sharp: the medium table has at most EIKON_SMALL_MEDIA_REGIONS regions (read from its uniform
// block, EIKON_B_SMALL_MEDIA)
#define EIKON_F_SMALL_MEDIA 262144
// sharp: the shape table has at most EIKON_EXACT_MAX_ROWS rows (no mesh): the view kernels read it
// from its uniform block (EIKON_B_EXACT_ROWS) everywhere, the convex planes' loops included
#define EIKON_F_SMALL_SHAPES 524288
// sharp: some region is a biaxial crystal (EIKON_MEDIUM_BIAXIAL): two modes, fast (0) and slow (1),
// solved in sharp.glsl from the region's dielectric tensor
#define EIKON_F_BIAXIAL 1048576
// The scene's marches have two modes (o/e in uniaxial crystals, fast/slow in biaxial ones).
#define EIKON_F_TWO_MODES (EIKON_F_UNIAXIAL | EIKON_F_BIAXIAL)

// ViewParams.pass.w bits: how one pass of the view kernel samples and what it writes (shaders/
// view.comp; set by ViewRenderer::render).
#define EIKON_PASS_HERO 1          // hero wavelength sampling: all bins from one march
#define EIKON_PASS_LAYERS 2        // write the per-channel layers after the band's pixels
#define EIKON_PASS_LAYER_MODES 4   // the layers keep the two modes apart
#define EIKON_PASS_MODES_SHIFT 3   // (pass.w >> 3) & EIKON_PASS_MODES_MASK: both (0), o (1), e (2)
#define EIKON_PASS_MODES_MASK 3
#define EIKON_PASS_AOV 32          // the AOV layer: keys the pipeline only (the kernel reads kAov)
#define EIKON_PASS_SHARED 64       // sharing across stratified passes (view.comp stratifiedAdd)

// Integrators (ViewParams.march.w).
#define EIKON_INT_EULER 0
#define EIKON_INT_MIDPOINT 1
#define EIKON_INT_RK4 2

// Environment types.
#define EIKON_ENV_CHECKER 0
#define EIKON_ENV_CONSTANT 1
#define EIKON_ENV_LATLONG 2

// Table layout in the EIKON_B_TABLES buffer (vec4 entries): CIE 1931 x̄ȳz̄ at 1 nm from 360 nm,
// then the RGB→spectrum basis at 5 nm from 380 nm, then the 3 rows of the spectral→sRGB matrix.
#define EIKON_CMF_OFFSET 0
#define EIKON_CMF_COUNT 471
#define EIKON_BASIS_OFFSET 471
#define EIKON_BASIS_COUNT 81
#define EIKON_MATRIX_OFFSET 552
#define EIKON_TABLE_COUNT 555

// Shape table (EIKON_B_SHAPES; packed by core/render/boundary_device.cpp): the shape of region
// r ≥ 1 is the record at vec4 index EIKON_SHAPE_STRIDE·(r − 1):
//   [0] (kind EIKON_SHAPE_*, first plane (vec4 index), plane count, number of shapes)   integers stored as floats
//   [1] (centre (mm), 0)
//   [2..4] the columns of the local → world rotation R (local p = Rᵀ(x − c): p_i = col_i · (x − c))
//   [5] sphere: (radius, 0, 0, 0); box: (size/2, 0); rounded box: (size/2 − radius, radius);
//       mesh: (triangle count, hierarchy depth, first face colour (vec4 index), bounding radius)
// then the planes of the convex shapes, (local unit outward normal, d): inside where n·p ≤ d,
// and after every plane the meshes (a mesh's [0] is (EIKON_SHAPE_MESH, first node, node count, first triangle)):
// its bounding-volume hierarchy (core/scene/mesh.h MeshDistance), node k at first node + 2k:
//   (box min (local mm, padded outward), inner: the right child k' / leaf: its first triangle),
//   (box max, 0 for an inner node (the left child is k + 1) / the leaf's triangle count ≤ 4);
// and its triangles in the leaves' order, triangle j at first triangle + 3j: (corner 0, n.x),
// (corner 1, n.y), (corner 2, n.z), n the unit outward normal, corners counter-clockwise outside;
// then its triangles' face colours in the same order (MeshDistance::faceColours), four to a vec4:
// triangle j's at component j % 4 of first face colour + j / 4.
#define EIKON_SHAPE_STRIDE 6
#define EIKON_SHAPE_SPHERE 0
#define EIKON_SHAPE_BOX 1
#define EIKON_SHAPE_ROUNDED_BOX 2
#define EIKON_SHAPE_CONVEX 3
#define EIKON_SHAPE_MESH 4
// A mesh's traversal (shaders/boundary.glsl meshFirstHit; MeshDistance::firstHit): the stack
// holds depth + 1 nodes (packing refuses deeper hierarchies), a leaf holds at most
// EIKON_MESH_LEAF triangles (one unrolled pass), and a search visits at most
// EIKON_MESH_MAX_PASSES nodes (lavapipe's loop budget; past it the field's crossing stands).
#define EIKON_MESH_STACK 24
#define EIKON_MESH_LEAF 4
#define EIKON_MESH_MAX_PASSES 256

struct ViewParams {
  vec4 cam_pos;      // xyz: eye (mm); w: tan(fov_y / 2)
  vec4 cam_forward;  // xyz: unit forward; w: aspect (width / height)
  vec4 cam_right;    // xyz: unit right
  vec4 cam_up;       // xyz: unit up
  vec4 grid_origin;  // xyz: bounds_min (mm); w: voxel edge h (mm)
  vec4 grid_extent;  // xyz: dims·h (mm); w: 1/h
  ivec4 grid_dims;   // xyz: voxels per axis; w: flags (EIKON_F_*)
  vec4 march;        // x: step (voxels); y: interface threshold |∇n|·h; z: ambient index; w: integrator
  ivec4 limits;      // x: max steps per ray; y: spp; z: wavelengths per sample (spectral); w: skip cap
  vec4 env;          // x: type; y: checker squares; z: intensity; w: unused
  vec4 env_a;        // checker colour a / constant radiance (linear sRGB)
  vec4 env_b;        // checker colour b
  ivec4 env_size;    // latlong width, height
  ivec4 image;       // x: width; y: height; z: first row of this dispatch; w: rows in this dispatch
  vec4 wavelength;   // x: λ (µm) of the non-spectral mode; y: 1/λ²; z: 1/λ⁴
  ivec4 pass;        // x: the pixel sample of this dispatch; y: its first wavelength; z: wavelengths
  ivec4 transport;   // x: 1 full transport (MarchSettings::transport); y: max reflections; z:
                     // 1 split the first choice (split_first_choice; both kernels); w: unused
};

// One ray for the trace kernel: origin and unit direction in world space, λ in µm.
struct TraceRay {
  vec4 origin;     // xyz, w: λ (µm)
  vec4 direction;  // xyz unit
};

// What the trace kernel reports for one ray (one mode).
struct TraceResult {
  vec4 exit_point;      // xyz (mm); w: 1 if the ray left the volume, 0 if stopped (opaque/steps)
  vec4 exit_direction;  // xyz unit ray direction; w: optical path length (mm)
  vec4 wave_normal;     // xyz unit wave normal; w: transmittance
  vec4 stats;           // x: steps; y: max | |w| − n | (invariant drift); z: interfaces; w: TIR count
};

// One query of boundary_probe.comp: the GLSL boundary functions at a point and on a segment.
struct BoundaryQuery {
  vec4 a;  // xyz: point / segment start (mm); w: the region r of φ_r(a) (boundaryPhi)
  vec4 b;  // xyz: segment end (mm); w: 1 = analytic refinement on the crossed shape
  vec4 s;  // x: a region ≥ 1 whose shape's signed distance and gradient are evaluated at a
};

// Its answer (the CPU twins: boundaryPhi, boundaryRegion, locateCrossing, Shape::signedDistance,
// Shape::distanceGradient).
struct BoundaryAnswer {
  vec4 phi;       // x: φ_r(a) (mm); yzw: ∇φ_r(a)
  ivec4 regions;  // x: boundaryRegion(a); y: crossing found (0/1); z: from; w: to
  vec4 crossing;  // xyz: crossing point (mm); w: t along [a, b]
  vec4 normal;    // xyz: unit normal from `from` into `to`; w: mesh traversal passes (meshFirstHit)
  vec4 shape;     // x: signed distance of shape s at a (mm); yzw: its gradient (world)
};

// ---- The polarised trace (polarised_trace.comp; CPU twin core/reference/polarised_trace.h) ----
// Its own bindings on top of the trace kernel's: the polariser sheets and the trace settings.
#define EIKON_B_SHEETS 23
#define EIKON_POL_MAX_SHEETS 8    // polariser sheets a scene may hold for the GPU twin
#define EIKON_POL_MAX_LEAVES 12   // o/e ray-tree leaves (exit branches) per ray
#define EIKON_POL_MAX_STACK 12    // branches waiting to be followed
#define EIKON_POL_MAX_EVENTS 48   // interface events per branch
#define EIKON_POL_MAX_PIECES 96   // straight pieces per ray, all branches together (loop budget)
#define EIKON_POL_MAX_BEAMS 6     // output beams per ray (exit directions: the first choice
                                  // reflected, and four o/e pairs converted inside a crystal)
#define EIKON_POL_MAX_GROUPED 4   // branch mode codes reported per beam
#define EIKON_POL_GROUP 8         // rays per workgroup of polarised_trace.comp (a SIMD group)
// Sheets buffer: [0] = (sheet count, bandwidth_nm, source_angle_rad, reflect_at bit mask), then
// per sheet (center, width), (unit normal, height), (unit transmission axis, 0).

// One ray of the polarised trace: origin, unit direction, λ and the input Stokes vector (in
// stokesBasis(direction)).
struct PolarisedRay {
  vec4 origin;     // xyz (mm), w: λ (µm)
  vec4 direction;  // xyz unit; w: the seed of Transport::Full's choices, as its bits (gSeed)
  vec4 stokes;     // S0..S3
};

// One beam leaving the scene (the CPU's PolarisedBeam).
struct PolarisedBeamOut {
  vec4 exit_point;  // xyz (mm); w: branches added into it
  vec4 direction;   // xyz unit energy direction; w: coherent groups
  vec4 frame_x;     // xyz the Stokes reference direction stokesBasis(direction)
  vec4 stokes;      // S0..S3
  ivec4 modes;      // per branch (up to EIKON_POL_MAX_GROUPED): (length << 16) | o/e bits (e = 1,
                    // first crystal first), −1 where none
};

struct PolarisedResult {
  ivec4 head;  // x: beams; y: 1 if the ray tree was cut (branches, events, loop budget);
               // z: an unsupported (varying) region + 1, or 0; w: 1 if it entered inside an object
  PolarisedBeamOut beams[EIKON_POL_MAX_BEAMS];
};

// ---- Light simulator (wavefront.comp; CPU twin core/reference/wavefront.h) ----
#define EIKON_WAVE_WG 64
// Descriptor bindings of the wavefront pipeline (its own set 0).
#define EIKON_WB_PARAMS 0
#define EIKON_WB_INDEX_A 1
#define EIKON_WB_INDEX_B 2
#define EIKON_WB_INDEX_C 3
#define EIKON_WB_MEDIUM 4
#define EIKON_WB_PATCHES 5
#define EIKON_WB_SPLAT 6
#define EIKON_WB_PATCHES_B 7  // second patch list (ping-pong with EIKON_WB_PATCHES)
#define EIKON_WB_SCAN 8       // uint per patch: output count, then its exclusive prefix sum (scan.comp)
#define EIKON_WB_TALLY 9      // one WaveTally per workgroup of the count pass
// e-mode (WaveParams.control.w = 1; uniaxial volumes): n_e Cauchy A/B/C, σ_e bands, optic axis.
// Bound to the o-mode images when the volume is isotropic (never read then).
#define EIKON_WB_INDEX_E_A 10
#define EIKON_WB_INDEX_E_B 11
#define EIKON_WB_INDEX_E_C 12
#define EIKON_WB_MEDIUM_E 13
#define EIKON_WB_AXIS 14  // (a, 0) uniform axis or (centre, −1) radial field; zero where isotropic
#define EIKON_WB_SKIP 15  // the VolumeSet's emission image: w = skip distance D (voxels) for straight steps
// wavefront.comp passes (WavePush.control.y).
#define EIKON_WM_PROPAGATE 0     // advance ALIVE patches by up to steps_per_dispatch steps
#define EIKON_WM_COUNT 1         // scan[i] = 0 (dead / out of steps), 1 (keep), 4 (split); tally per workgroup
#define EIKON_WM_COUNT_SPLITS 2  // scan[i] = 1 if the patch asks for a split (its rank after the scan)
#define EIKON_WM_COUNT_BUDGET 3  // scan[i] as COUNT, but only splits of rank < control.z are granted
#define EIKON_WM_SCATTER 4       // write survivors and children to the other list at scan[i]
// Scan (scan.comp): a block of EIKON_SCAN_WG threads scans 2·EIKON_SCAN_WG elements in shared memory.
#define EIKON_SCAN_WG 256
#define EIKON_SCAN_BLOCK 512
// WavePatch.state.x: what the kernel decided for the patch.
#define EIKON_PATCH_ALIVE 0     // still propagating (or out of steps: state.w == max_steps)
#define EIKON_PATCH_SPLIT 1     // alive, stopped because edges of both pairs exceed the split span: quarters
#define EIKON_PATCH_LEFT 2      // killed: centre left the bounds (or its ray misses them)
#define EIKON_PATCH_CAUSTIC 3   // killed: orientation flip (fold caustic)
#define EIKON_PATCH_ENERGY 4    // killed: flux below min_energy_fraction of its seed's
#define EIKON_PATCH_OPAQUE 5    // killed: centre in an opaque voxel (flux counted as absorbed)
#define EIKON_PATCH_TORN 6      // alive, torn by a boundary (sharp): becomes four pencils, as a split
#define EIKON_PATCH_REFLECT 7   // alive, its step undone (sharp): becomes itself and its reflected copy
#define EIKON_PATCH_HALVE_U 8   // alive, stopped because a u edge (0→1, 3→2) alone exceeds the split span: halves
#define EIKON_PATCH_HALVE_V 9   // alive, stopped because a v edge (1→2, 0→3) alone exceeds the split span: halves
// Splat buffer: per voxel 4 signed 64-bit fixed-point sums as (lo, hi) uint pairs, in the order
// weight, and the biased weight·(1 + dir.x), ·(1 + dir.y), ·(1 + dir.z) (every term ≥ 0; the host
// subtracts the weight) (EIKON_SPLAT_ACC_WORDS words per voxel), then one uint per voxel
// holding the float bits of the highest patch irradiance (atomicMax on non-negative floats).
#define EIKON_SPLAT_ACC_WORDS 8

struct WaveParams {
  vec4 grid_origin;  // xyz: bounds_min (mm); w: voxel edge h (mm)
  vec4 grid_max;     // xyz: bounds_max (mm); w: 1/h
  ivec4 grid_dims;   // xyz: voxels per axis; w: flags (EIKON_F_DISPERSIVE | _ATTENUATION | _OPACITY)
  vec4 step;         // x: dt (mm); y: split edge (mm); z: min energy fraction; w: 1/h³
  vec4 wavelength;   // x: λ (µm); y: 1/λ²; z: 1/λ⁴; w: splat scale (fixed-point units per W/mm²)
  ivec4 control;     // x: probe axis (−1: none); y: steps per dispatch; z: max_steps; w: mode (0 o, 1 e)
  vec4 probe;        // x: probe plane position (mm); y: 1 = halves for a patch stretched one way
                     // (split_halves), 0 = quarters always; zw: unused
  ivec4 options;     // x: 1 = straight steps across homogeneous regions (skip_empty); y: 1 = pass_caustics;
                     // z: 1 = straight steps up to the next boundary (straight_to_boundary);
                     // w: reflected generations followed (max_reflection_generations)
};

// Push constants of wavefront.comp. control: x: patches in the source list; y: pass (EIKON_WM_*);
// z: granted splits (COUNT_BUDGET) or the scan's total slot (SCATTER); w: bit 0: the source list
// is EIKON_WB_PATCHES_B (the destination of SCATTER is the other one).
struct WavePush {
  uvec4 control;
};

// Push constants of scan.comp. x: first element of the level; y: elements; z: where block b's sum
// goes (pass 0) or comes from (pass 1): element z + b; w: pass (0: scan blocks, 1: add block sums).
struct ScanPush {
  uvec4 control;
};

// Per-workgroup sums of the COUNT pass (the host adds them in double): what ended where.
struct WaveTally {
  vec4 flux_a;    // flux of patches killed: left, caustic, energy, opaque
  vec4 flux_b;    // x: absorbed by attenuation in the last dispatch (Σ flux.w); y: flux live at max_steps
  vec4 caustic_sum;  // xyz: Σ flux·centre of caustic kills; w: torn patches asking for pencils
  uvec4 count_a;  // kills: left, caustic, energy, opaque
  uvec4 count_b;  // x: live at max_steps; y: patches asking for a split; z: survivors (count ≥ 1); w: max steps
  vec4 probe_pos;  // probe plane crossings in the last dispatch: xyz: Σ ±flux·crossing point; w: Σ ±flux
  vec4 probe_dir;  // xyz: Σ ±flux·unit direction of the centre's motion at the crossing;
                   // w: sharp interfaces: Σ flux lost to Fresnel reflection in the last dispatch,
                   // less the flux reflected copies took up
  uvec4 count_c;   // x: reflected copies asked for (EIKON_PATCH_REFLECT); y: splits into halves
                   // asked for (EIKON_PATCH_HALVE_U, _V); zw: unused
};

// One patch: four corners in bilinear order (0,0), (1,0), (1,1), (0,1).
// x[k].w, w[k].w: the probe sums of the last propagation (x[0..2].w: Σ ±flux·crossing point,
// x[3].w: Σ ±flux, w[0..2].w: Σ ±flux·direction) and w[3].w the flux lost to Fresnel reflection
// in it (sharp interfaces), read by the COUNT pass.
struct WavePatch {
  vec4 x[4];    // xyz: corner position (mm)
  vec4 w[4];    // xyz: corner wave vector w = p (o-mode |w| = n; e-mode wᵀM_e w = 1)
  vec4 flux;    // x: flux (W); y: area0 (mm²); z: seed flux (W); w: flux absorbed in this dispatch
  ivec4 state;  // x: EIKON_PATCH_*; y: launch orientation (±1, 0); z: entered (0/1); w: steps done
  vec4 refl;    // reflected wavefronts (sharp): x: shadow flux still to be reflected into the patch
                // (Patch::shadow); y: generation; z: armed (1: the copy for this crossing is made)
  ivec4 region; // sharp interfaces: corner k's region (bits 0–14; −1: not located yet), its
                // pending bit EIKON_CORNER_PENDING (a reflected copy's corner that turns back at
                // its next crossing), its mirror bit EIKON_CORNER_MIRRORED (odd number of total
                // internal reflections) and its boundary events modulo 256 (bits 17–24: region
                // changes and mirrors; a patch whose corners disagree is torn, Patch::events) and
                // its face digest (bits 25–30)
};
#define EIKON_CORNER_REGION 0x7FFF
#define EIKON_CORNER_PENDING 0x8000
#define EIKON_CORNER_MIRRORED 0x10000
#define EIKON_CORNER_EVENT_SHIFT 17
#define EIKON_CORNER_EVENT 0x20000
#define EIKON_CORNER_EVENTS 0x1FE0000
// Bits 25–30: a 6-bit digest of the polyhedron faces the corner crossed (Patch::faces,
// faceDigest in core/light/wavefront_types.h and wavefront.comp).
#define EIKON_CORNER_FACE_SHIFT 25
#define EIKON_CORNER_FACES 0x7E000000

#ifdef __cplusplus
static_assert(sizeof(ViewParams) == 17 * 16, "ViewParams must be vec4-packed");
static_assert(sizeof(TraceRay) == 32 && sizeof(TraceResult) == 64, "trace records must be vec4-packed");
static_assert(sizeof(PolarisedRay) == 48 && sizeof(PolarisedBeamOut) == 80 &&
                  sizeof(PolarisedResult) == 16 + 80 * EIKON_POL_MAX_BEAMS,
              "polarised trace records must be vec4-packed");
static_assert(sizeof(BoundaryQuery) == 48 && sizeof(BoundaryAnswer) == 80,
              "boundary probe records must be vec4-packed");
static_assert(sizeof(WavePush) == 16 && sizeof(ScanPush) == 16 && sizeof(WaveTally) == 8 * 16,
              "wavefront push/tally records must be vec4-packed");
static_assert(sizeof(WaveParams) == 8 * 16 && sizeof(WavePatch) == 12 * 16, "wavefront records must be vec4-packed");
}  // namespace eikon::gpu
#else
// π for every kernel (C++ takes std::numbers::pi).
const float kPi = 3.14159265358979323846;
#endif

#endif  // EIKON_SHARED_H
// clang-format on
