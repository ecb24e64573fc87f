// Faceted gems from a faceting diagram: tiers of facets given as a cutter gives
// them — the angle from the girdle plane, the index-gear positions and where the facet is cut to
// (a distance, cut to centre, meeting the girdle line, meeting a level line of an earlier tier or
// an earlier meet point) — cut in order from a rough block into a convex polyhedron, which then
// becomes an ordinary ConvexShape (so the voxeliser and the sharp boundaries see plain planes).
//
// Frame: the object's local frame with the table up (+y), the girdle plane y = 0 through the
// centre; index i on a gear of G teeth points along the azimuth φ = 2π·i/G measured from +x
// towards +z. A crown facet at angle θ has the outward normal (sinθ cosφ, cosθ, sinθ sinφ), a
// pavilion facet (sinθ cosφ, −cosθ, sinθ sinφ), a girdle facet (cosφ, 0, sinφ); the table and a
// flat culet ±y. GemCad's .asc text files (readGemCadAsc) give the same thing with explicit
// distances.
#pragma once

#include <array>
#include <istream>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/scene/shapes.h"

namespace eikon {

/// A design error, with the JSON path below the object (e.g. "/tiers/2/meet") or "/file" (the
/// message then names the .asc line) so that the scene parser can name where it is.
class FacetError : public std::invalid_argument {
 public:
  FacetError(std::string where, const std::string& what)
      : std::invalid_argument(what), where_(std::move(where)) {}
  const std::string& where() const { return where_; }

 private:
  std::string where_;
};

enum class FacetSide { Crown, Pavilion, Girdle, Table, Culet };

/// The girdle outline that "meet": "girdle" cuts to: round (diameter = length), oval (an ellipse of
/// axes length along x and width along z), rectangle (length × width, corners cut by `corner`
/// mm along both edges) or pear (a teardrop: the convex hull of the circle of diameter width
/// whose far side is at x = −length/2 and the point (length/2, 0), length > width), at heights
/// ±thickness/2.
struct GirdleOutline {
  enum class Kind { None, Round, Oval, Rectangle, Pear } kind = Kind::None;
  double length = 0, width = 0, corner = 0, thickness = 0;
};

struct FacetRef {
  std::string tier;
  int index = 0;
};

struct FacetTier {
  std::string name;
  FacetSide side = FacetSide::Crown;
  double angle_deg = 0;      ///< from the girdle plane, crown and pavilion only, in (0, 90)
  std::vector<int> indices;  ///< gear positions in [0, gear] (table and culet: one, ignored)
  enum class Place { Distance, ToCenter, MeetGirdle, MeetLevel, MeetPoint } place = Place::Distance;
  double value = 0;                ///< distance (mm), to-centre height or level height (mm)
  std::string level_tier;          ///< MeetLevel: the earlier tier met along the level line
  std::array<FacetRef, 3> meet{};  ///< MeetPoint: three earlier facets (for the first index)
  std::string path;                ///< JSON path of the tier below the object, for errors
};

struct FacetedDesign {
  int gear = 96;
  GirdleOutline girdle;
  std::vector<FacetTier> tiers;
};

struct FacetInfo {
  std::string tier;
  int index;
  FacetSide side;
  double angle_deg;
};

/// The cut stone: shape.planes[k] is facets[k] (in cutting order).
struct FacetedStone {
  ConvexShape shape;
  std::vector<FacetInfo> facets;
};

/// Outward unit normal of a facet (see the frame above).
glm::dvec3 facetNormal(FacetSide side, double angle_deg, int index, int gear);

/// Cut the design in order. Throws FacetError for a facet that cuts nothing, one that removes the
/// whole stone, a meet that cannot be met, a facet cut away by later ones, an open stone (the
/// rough block's faces remain) and inconsistent tiers (unknown names, duplicate names).
FacetedStone cutFaceted(const FacetedDesign& design);

/// Read a GemCad .asc file (the text export of GemCad: "g" gear line, "a angle distance index
/// [n name] index ..." facet lines, negative angles on the pavilion; H/F/I/y/G lines are notes).
/// Every facet becomes a Distance tier. Throws FacetError("/file", "FILE line N: ..."). The file's
/// text is quoted in a message only after a "GemCad" or "g" record has shown it to be GemCad's: an
/// unknown record before either is refused by its line number alone.
FacetedDesign readGemCadAsc(std::istream& in, const std::string& name);

}  // namespace eikon
