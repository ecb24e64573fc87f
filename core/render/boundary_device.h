// The sharp-boundary field on the device: the VolumeSet's BoundaryField
// (core/volume/boundary.h) as a region image (R32_UINT), a distance image (R32_SFLOAT, voxels) and
// the shape table (vec4 records, layout in shaders/eikon_shared.h), bound at EIKON_B_REGION,
// EIKON_B_BOUNDARY_DIST and EIKON_B_SHAPES for the GLSL twins in shaders/boundary.glsl, and the
// medium table of the sharp march (core/volume/media.h packMediaTable) at EIKON_B_MEDIA.
//
//   eikon::BoundaryDevice dev(ctx, volume.boundary, volume.media);   // refuses clearly if too big
//   dev.bind(pipeline);                                // pipeline built with boundaryBindings()
//
// An empty field ("interfaces": "smoothed") uploads 1-voxel placeholders (region 0, distance =
// cap) and a one-entry table, so that kernels can always bind the three resources.
#pragma once

#include <string>
#include <vector>

#include "core/vk/context.h"
#include "core/vk/resources.h"
#include "core/volume/boundary.h"
#include "core/volume/media.h"
#include "shaders/eikon_shared.h"

namespace eikon {

/// The shape table of a field, packed as the GLSL reads it (eikon_shared.h, EIKON_SHAPE_*); one
/// zero entry when the field has no shapes.
std::vector<glm::vec4> packShapeTable(const BoundaryField& field);

/// Throw a one-line std::runtime_error (naming `file`) if the field cannot live on this device:
/// its image sides, the shape and medium tables' storage-buffer range.
void checkBoundaryFits(const vk::Context& ctx, const BoundaryField& field, const MediaTable& media,
                       const std::string& file);

/// The descriptor bindings of the four resources (add them to a pipeline's binding list).
std::vector<vk::BindingSpec> boundaryBindings();

/// The bindings of BoundaryDevice::bindUniformTables (the view and light kernels add them).
std::vector<vk::BindingSpec> uniformTableBindings();

/// EIKON_F_SMALL_MEDIA and EIKON_F_SMALL_SHAPES where the medium table and the shape table fit
/// the uniform blocks (bindUniformTables; march.glsl and wavefront.comp read them there then).
int uniformTableFlags(const BoundaryField& field, const MediaTable& media);

/// EIKON_F_CONVEX_APART and EIKON_F_EXACT where the field has them: the crossing dispatch of the
/// view and light kernels (sharp.glsl nextCrossing; with their kExact constant,
/// volumeExactConstant).
int crossingPathFlags(const BoundaryField& field);

class BoundaryDevice {
 public:
  BoundaryDevice() = default;
  /// voxels_read = false: the kernels bound read no voxel of the field (its regions are on the
  /// shapes, BoundaryField::regionsOnShapes, and the kernels have the exact path's constants):
  /// one-voxel placeholders instead of the region and distance images.
  BoundaryDevice(const vk::Context& ctx, const BoundaryField& field, const MediaTable& media,
                 const std::string& file = "", bool voxels_read = true);
  void bind(vk::ComputePipeline& pipeline) const;
  /// The view kernels' uniform blocks of the same tables (march.glsl; uniformTableBindings()):
  /// the shape table's first EIKON_EXACT_MAX_ROWS rows and the medium table's first
  /// EIKON_SMALL_MEDIA_REGIONS regions, zero-padded to the blocks' fixed sizes.
  void bindUniformTables(vk::ComputePipeline& pipeline) const;
  /// Write every region's n_o and n_e at λ (nm) into its record's v15 (core/volume/media.h), in
  /// both copies of the medium table: the index an RGB view render reads (sharp.glsl
  /// mediumIndex under EIKON_INDEX_AT_RENDER_WAVELENGTH). Nothing is written if λ is unchanged.
  void setRenderWavelength(double lambda_nm);
  bool present() const { return present_; }

 private:
  void writeMedia();
  vk::Image3D region_, distance_;
  vk::Buffer shapes_, media_;
  vk::Buffer exact_rows_, small_media_;
  MediaTable table_;           // the regions' dispersion (for setRenderWavelength)
  std::vector<float> packed_;  // packMediaTable's floats, v15 as last written
  double render_lambda_nm_ = -1.0;
  bool present_ = false;
};

/// Evaluate the GLSL boundary functions (shaders/boundary_probe.comp) for each query; the
/// crossing is bisected to `tolerance_voxels`. For the GPU-vs-CPU tests of the sharp twins.
std::vector<gpu::BoundaryAnswer> probeBoundary(vk::Context& ctx, const BoundaryField& field,
                                               const std::vector<gpu::BoundaryQuery>& queries,
                                               double tolerance_voxels = 1e-6);

}  // namespace eikon
