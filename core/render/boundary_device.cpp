#include "core/render/boundary_device.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <type_traits>
#include <variant>

#include "core/scene/mesh.h"
#include "shaders/boundary_probe.spv.h"

namespace eikon {
namespace {

static_assert(MeshDistance::kLeafTriangles == EIKON_MESH_LEAF &&
                  MeshDistance::kMaxTraversalPasses == EIKON_MESH_MAX_PASSES,
              "a mesh's traversal is declared twice (mesh.h, eikon_shared.h)");

// A mesh's hierarchy and triangles (eikon_shared.h, EIKON_SHAPE_MESH) appended to `extra`, whose
// first entry has vec4 index `base`; its record's head and parameters. The node boxes are
// widened by 2e-5 of the bounding radius (≥ 100 float ulps), so that the GPU's float slab test
// cannot drop a triangle that touches its box; the triangles are tested exactly as stored.
void packMesh(const MeshShape& m, int base, std::vector<glm::vec4>& extra, glm::vec4& head,
              glm::vec4& par) {
  const MeshDistance& d = *m.distance;
  const auto& nodes = d.nodes();
  const int first_node = base + int(extra.size());
  const int first_tri = first_node + 2 * int(nodes.size());
  head =
      glm::vec4(float(EIKON_SHAPE_MESH), float(first_node), float(nodes.size()), float(first_tri));
  const int first_colour = first_tri + 3 * int(d.triangles().size());
  par = glm::vec4(float(d.triangles().size()), float(d.depth()), float(first_colour),
                  float(d.boundingRadius()));
  const double pad = 2e-5 * std::max(d.boundingRadius(), 1.0);
  for (const MeshDistance::Node& n : nodes) {
    extra.push_back(glm::vec4(glm::vec3(n.lo - pad), float(n.first)));
    extra.push_back(glm::vec4(glm::vec3(n.hi + pad), float(n.count)));
  }
  for (uint32_t t : d.leafOrder()) {
    const glm::dvec3 n = d.faceNormals()[t];
    for (int k = 0; k < 3; ++k)
      extra.push_back(glm::vec4(glm::vec3(d.vertices()[d.triangles()[t][size_t(k)]]), float(n[k])));
  }
  const auto& order = d.leafOrder();
  for (size_t j = 0; j < order.size(); j += 4) {
    glm::vec4 c(0.0f);
    for (size_t k = 0; k < 4 && j + k < order.size(); ++k)
      c[int(k)] = float(d.faceColours()[order[j + k]]);
    extra.push_back(c);
  }
}

// The shape record of one shape (eikon_shared.h): header, centre, rotation columns, parameters.
// Its planes go to `planes`, a mesh's hierarchy and triangles to `meshes` (vec4 indices counted
// from the table's start by the caller: the meshes after every plane, so that the exact path's
// first rows hold all records and planes).
void packShape(const Shape& shape, int first_plane, int first_mesh, std::vector<glm::vec4>& out,
               std::vector<glm::vec4>& planes, std::vector<glm::vec4>& meshes) {
  glm::vec4 head(0.0f), par(0.0f);
  std::visit(
      [&](const auto& g) {
        using T = std::decay_t<decltype(g)>;
        if constexpr (std::is_same_v<T, SphereShape>) {
          head.x = EIKON_SHAPE_SPHERE;
          par.x = float(g.radius);
        } else if constexpr (std::is_same_v<T, BoxShape>) {
          head.x = EIKON_SHAPE_BOX;
          par = glm::vec4(glm::vec3(0.5 * g.size), 0.0f);
        } else if constexpr (std::is_same_v<T, RoundedBoxShape>) {
          head.x = EIKON_SHAPE_ROUNDED_BOX;
          par = glm::vec4(glm::vec3(0.5 * g.size - glm::dvec3(g.radius)), float(g.radius));
        } else if constexpr (std::is_same_v<T, MeshShape>) {
          packMesh(g, first_mesh, meshes, head, par);
        } else {
          head = glm::vec4(float(EIKON_SHAPE_CONVEX), float(first_plane + int(planes.size())),
                           float(g.planes.size()), 0.0f);
          for (const Plane& p : g.planes)
            planes.push_back(glm::vec4(glm::vec3(p.normal), float(p.d)));
        }
      },
      shape.geometry());
  out.push_back(head);
  out.push_back(glm::vec4(glm::vec3(shape.center()), 0.0f));
  for (int c = 0; c < 3; ++c) out.push_back(glm::vec4(glm::vec3(shape.rotation()[c]), 0.0f));
  out.push_back(par);
}

}  // namespace

std::vector<glm::vec4> packShapeTable(const BoundaryField& field) {
  std::vector<glm::vec4> table, planes, meshes;
  const int first_plane = EIKON_SHAPE_STRIDE * int(field.shapes.size());
  const int first_mesh = exactTableRows(field.shapes);  // records and planes
  for (const Shape& s : field.shapes) packShape(s, first_plane, first_mesh, table, planes, meshes);
  // Every record's header w: the number of shapes (boundary.glsl convexCrossing loops over them),
  // except a mesh's, whose w is its first triangle (convexCrossing never runs with a mesh).
  for (size_t r = 0; r < field.shapes.size(); ++r)
    if (int(table[r * EIKON_SHAPE_STRIDE].x) != EIKON_SHAPE_MESH)
      table[r * EIKON_SHAPE_STRIDE].w = float(field.shapes.size());
  table.insert(table.end(), planes.begin(), planes.end());
  table.insert(table.end(), meshes.begin(), meshes.end());
  if (table.empty()) table.push_back(glm::vec4(0.0f));
  return table;
}

void checkBoundaryFits(const vk::Context& ctx, const BoundaryField& field, const MediaTable& media,
                       const std::string& file) {
  const auto& lim = ctx.limits();
  const std::string where = (file.empty() ? std::string("scene") : file) + ": /objects: ";
  if (field.hasVoxels())
    for (int a = 0; a < 3; ++a)
      if (uint32_t(field.grid.dims[size_t(a)]) > lim.max_image_dimension_3d)
        throw std::runtime_error(where + "the boundary field needs " +
                                 std::to_string(field.grid.dims[size_t(a)]) +
                                 " voxels per side but the device allows at most " +
                                 std::to_string(lim.max_image_dimension_3d));
  // Records, planes and meshes, counted without packing: 6 vec4 per shape, one per plane, two per
  // mesh node, three per triangle and one per four triangles' face colours.
  double entries = EIKON_SHAPE_STRIDE * double(field.shapes.size());
  for (const Shape& s : field.shapes) {
    if (const auto* c = std::get_if<ConvexShape>(&s.geometry()))
      entries += double(c->planes.size());
    if (const auto* m = std::get_if<MeshShape>(&s.geometry())) {
      const double tris = double(m->distance->triangles().size());
      entries += 2.0 * double(m->distance->nodes().size()) + 3.0 * tris + std::ceil(tris / 4.0);
      if (m->distance->depth() + 1 > EIKON_MESH_STACK)
        throw std::runtime_error(
            where + "a mesh's hierarchy is " + std::to_string(m->distance->depth()) +
            " levels deep, more than the GPU's traversal holds (" +
            std::to_string(EIKON_MESH_STACK - 1) + "; or set \"interfaces\": \"smoothed\")");
    }
  }
  // Indices are stored as floats: exact below 2^24.
  if (entries >= 16777216.0)
    throw std::runtime_error(where + "the shape table needs " + std::to_string(int64_t(entries)) +
                             " entries, more than its float indices reach (16777216; or set "
                             "\"interfaces\": \"smoothed\")");
  const double bytes = 16.0 * std::max(entries, 1.0);
  if (bytes > double(lim.max_storage_buffer_range))
    throw std::runtime_error(where + "the shape table needs " + std::to_string(int64_t(bytes)) +
                             " bytes but the device's storage buffers hold at most " +
                             std::to_string(lim.max_storage_buffer_range) +
                             " (or set \"interfaces\": \"smoothed\")");
  const double media_bytes =
      std::max<double>(16.0 * kMediumVec4s, 4.0 * double(packMediaTable(media).size()));
  if (media_bytes > double(lim.max_storage_buffer_range))
    throw std::runtime_error(
        where + "the medium table needs " + std::to_string(int64_t(media_bytes)) +
        " bytes but the device's storage buffers hold at most " +
        std::to_string(lim.max_storage_buffer_range) + " (or set \"interfaces\": \"smoothed\")");
}

std::vector<vk::BindingSpec> boundaryBindings() {
  return {{EIKON_B_REGION, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE},
          {EIKON_B_BOUNDARY_DIST, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE},
          {EIKON_B_SHAPES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
          {EIKON_B_MEDIA, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}};
}

std::vector<vk::BindingSpec> uniformTableBindings() {
  return {{EIKON_B_EXACT_ROWS, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER},
          {EIKON_B_SMALL_MEDIA, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER}};
}

int uniformTableFlags(const BoundaryField& field, const MediaTable& media) {
  bool mesh = false;
  for (const Shape& s : field.shapes)
    mesh = mesh || std::holds_alternative<MeshShape>(s.geometry());
  int flags = 0;
  if (media.regions.size() <= size_t(EIKON_SMALL_MEDIA_REGIONS)) flags |= EIKON_F_SMALL_MEDIA;
  if (!mesh && exactTableRows(field.shapes) <= EIKON_EXACT_MAX_ROWS) flags |= EIKON_F_SMALL_SHAPES;
  return flags;
}

int crossingPathFlags(const BoundaryField& field) {
  return (field.convex_apart ? EIKON_F_CONVEX_APART : 0) | (field.exact ? EIKON_F_EXACT : 0);
}

BoundaryDevice::BoundaryDevice(const vk::Context& ctx, const BoundaryField& field,
                               const MediaTable& media, const std::string& file, bool voxels_read) {
  static_assert(
      kMediumVec4s == EIKON_MEDIUM_VEC4S && kMediumHomogeneous == EIKON_MEDIUM_HOMOGENEOUS &&
          kMediumUniaxial == EIKON_MEDIUM_UNIAXIAL &&
          kMediumRadialAxis == EIKON_MEDIUM_RADIAL_AXIS && kMediumGrin == EIKON_MEDIUM_GRIN &&
          kMediumOpaque == EIKON_MEDIUM_OPAQUE && kMediumBiaxial == EIKON_MEDIUM_BIAXIAL,
      "the medium table's layout is declared twice (media.h, eikon_shared.h)");
  checkBoundaryFits(ctx, field, media, file);
  // Else placeholders (regions on the shapes: none is read).
  present_ = voxels_read && field.hasVoxels();
  std::array<uint32_t, 3> ext{1, 1, 1};
  if (present_)
    ext = {uint32_t(field.grid.dims[0]), uint32_t(field.grid.dims[1]),
           uint32_t(field.grid.dims[2])};
  const std::vector<float> cap{field.cap};
  const auto& dist = present_ ? field.distance : cap;
  // R32_UINT, not R16_UINT: 16-bit storage images need the optional
  // shaderStorageImageExtendedFormats feature; 32-bit uint is a format every device must offer.
  const std::vector<uint32_t> reg =
      present_ ? std::vector<uint32_t>(field.region.begin(), field.region.end())
               : std::vector<uint32_t>{0u};
  region_ = vk::Image3D(ctx, ext, VK_FORMAT_R32_UINT, "boundary region");
  region_.upload(ctx, reg.data(), reg.size() * sizeof(uint32_t));
  distance_ = vk::Image3D(ctx, ext, VK_FORMAT_R32_SFLOAT, "boundary distance");
  distance_.upload(ctx, dist.data(), dist.size() * sizeof(float));
  const std::vector<glm::vec4> table = packShapeTable(field);
  shapes_ = vk::Buffer(ctx, table.size() * sizeof(glm::vec4), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                       "shape table");
  shapes_.write(table.data(), table.size() * sizeof(glm::vec4));
  table_ = media;
  packed_ = packMediaTable(media);
  if (packed_.empty()) packed_.assign(size_t(kMediumVec4s) * 4, 0.0f);
  media_ = vk::Buffer(ctx, packed_.size() * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                      "medium table");
  // The uniform blocks: fixed sizes (4 KiB and 15.8 KiB, within every device's 16 KiB range).
  static_assert(EIKON_SMALL_MEDIA_REGIONS * kMediumVec4s * 16 <= 16384,
                "the small medium table must fit Vulkan's guaranteed uniform range");
  static_assert(kExactMaxRows == EIKON_EXACT_MAX_ROWS,
                "the exact path's row cap is declared twice");
  std::vector<glm::vec4> rows(size_t(EIKON_EXACT_MAX_ROWS), glm::vec4(0.0f));
  std::copy_n(table.begin(), std::min(table.size(), rows.size()), rows.begin());
  exact_rows_ = vk::Buffer(ctx, rows.size() * sizeof(glm::vec4), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT,
                           "shape table rows (uniform)");
  exact_rows_.write(rows.data(), rows.size() * sizeof(glm::vec4));
  small_media_ =
      vk::Buffer(ctx, size_t(EIKON_SMALL_MEDIA_REGIONS) * kMediumVec4s * 4 * sizeof(float),
                 VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, "medium table (uniform)");
  writeMedia();
}

void BoundaryDevice::writeMedia() {
  media_.write(packed_.data(), packed_.size() * sizeof(float));
  std::vector<float> small(size_t(EIKON_SMALL_MEDIA_REGIONS) * kMediumVec4s * 4, 0.0f);
  std::copy_n(packed_.begin(), std::min(packed_.size(), small.size()), small.begin());
  small_media_.write(small.data(), small.size() * sizeof(float));
}

void BoundaryDevice::setRenderWavelength(double lambda_nm) {
  if (lambda_nm == render_lambda_nm_ || !media_.handle()) return;
  render_lambda_nm_ = lambda_nm;
  for (size_t r = 0; r < table_.regions.size(); ++r) {
    float* v15 = packed_.data() + (r * kMediumVec4s + 15) * 4;
    v15[0] = float(mediumIndex(table_.regions[r].n_o, lambda_nm));
    v15[1] = float(mediumIndex(table_.regions[r].n_e, lambda_nm));
    v15[2] = float(mediumIndex(table_.regions[r].n_beta, lambda_nm));
  }
  writeMedia();
}

void BoundaryDevice::bindUniformTables(vk::ComputePipeline& p) const {
  p.bindBuffer(EIKON_B_EXACT_ROWS, exact_rows_);
  p.bindBuffer(EIKON_B_SMALL_MEDIA, small_media_);
}

void BoundaryDevice::bind(vk::ComputePipeline& p) const {
  p.bindImage(EIKON_B_REGION, region_);
  p.bindImage(EIKON_B_BOUNDARY_DIST, distance_);
  p.bindBuffer(EIKON_B_SHAPES, shapes_);
  p.bindBuffer(EIKON_B_MEDIA, media_);
}

std::vector<gpu::BoundaryAnswer> probeBoundary(vk::Context& ctx, const BoundaryField& field,
                                               const std::vector<gpu::BoundaryQuery>& queries,
                                               double tolerance_voxels) {
  if (queries.empty()) return {};
  if (field.empty()) throw std::invalid_argument("probeBoundary: the boundary field is empty");
  BoundaryDevice dev(ctx, field, MediaTable{});
  auto bindings = boundaryBindings();
  for (uint32_t b :
       {uint32_t(EIKON_B_PARAMS), uint32_t(EIKON_B_BOUNDARY_QUERIES), uint32_t(EIKON_B_OUTPUT)})
    bindings.push_back({b, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER});
  vk::ComputePipeline pipe(
      ctx, std::span<const uint32_t>(k_boundary_probe_spv, sizeof(k_boundary_probe_spv) / 4),
      bindings, 0, "boundary probe");
  gpu::ViewParams p{};
  const Grid& g = field.grid;
  p.grid_origin = glm::vec4(glm::vec3(g.origin), float(g.h));
  p.grid_extent = glm::vec4(glm::vec3(g.extent), float(1.0 / g.h));
  p.grid_dims = glm::ivec4(g.dims[0], g.dims[1], g.dims[2], 0);
  p.march = glm::vec4(float(tolerance_voxels), 0.0f, 0.0f, 0.0f);
  p.image = glm::ivec4(int(queries.size()), 1, 0, 1);
  vk::Buffer params(ctx, sizeof p, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "probe params");
  params.write(&p, sizeof p);
  vk::Buffer qb(ctx, queries.size() * sizeof(gpu::BoundaryQuery),
                VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "boundary queries");
  qb.write(queries.data(), queries.size() * sizeof(gpu::BoundaryQuery));
  vk::Buffer ab(ctx, queries.size() * sizeof(gpu::BoundaryAnswer),
                VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "boundary answers");
  dev.bind(pipe);
  pipe.bindBuffer(EIKON_B_PARAMS, params);
  pipe.bindBuffer(EIKON_B_BOUNDARY_QUERIES, qb);
  pipe.bindBuffer(EIKON_B_OUTPUT, ab);
  ctx.submitAndWait([&](VkCommandBuffer cmd) {
    pipe.dispatch(cmd, uint32_t((queries.size() + EIKON_TRACE_WG - 1) / EIKON_TRACE_WG), 1, 1,
                  nullptr);
  });
  std::vector<gpu::BoundaryAnswer> out(queries.size());
  ab.read(out.data(), out.size() * sizeof(gpu::BoundaryAnswer));
  return out;
}

}  // namespace eikon
