#include "core/scene/faceted.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <sstream>

namespace eikon {
namespace {
constexpr size_t kMaxFacets = 512;  // cutting is O(n³) in the facet count: ~1 s at this size
// A .asc distance's bound, the JSON tiers' (scene.cpp kMaxCoordinateMm): the rough block is sized
// from the largest distance, so 1e300 made every other facet fail on its line instead.
constexpr double kMaxAscDistanceMm = 1e12;

std::string num(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

/// The polygon of plane i of a bounded set of planes: a square of half-size L about the foot of
/// the origin on the plane, clipped by every other plane (Sutherland–Hodgman).
std::vector<glm::dvec3> facePolygon(const std::vector<Plane>& P, size_t i, double L, double tol) {
  const glm::dvec3 n = P[i].normal, o = n * P[i].d;
  const glm::dvec3 e1 = glm::normalize(std::abs(n.x) < 0.9 ? glm::cross(n, glm::dvec3(1, 0, 0))
                                                           : glm::cross(n, glm::dvec3(0, 1, 0)));
  const glm::dvec3 e2 = glm::cross(n, e1);
  std::vector<glm::dvec3> poly = {o - L * e1 - L * e2, o + L * e1 - L * e2, o + L * e1 + L * e2,
                                  o - L * e1 + L * e2},
                          next;
  for (size_t j = 0; j < P.size() && !poly.empty(); ++j) {
    if (j == i) continue;
    next.clear();
    for (size_t k = 0; k < poly.size(); ++k) {
      const glm::dvec3& A = poly[k];
      const glm::dvec3& B = poly[(k + 1) % poly.size()];
      const double sa = glm::dot(P[j].normal, A) - P[j].d, sb = glm::dot(P[j].normal, B) - P[j].d;
      if (sa <= tol) {
        next.push_back(A);
        if (sb > tol) next.push_back(A + (B - A) * (sa / (sa - sb)));
      } else if (sb <= tol) {
        next.push_back(A + (B - A) * (sa / (sa - sb)));
      }
    }
    poly.swap(next);
    if (poly.size() < 3) poly.clear();
  }
  return poly;
}

double polygonArea(const std::vector<glm::dvec3>& poly) {
  glm::dvec3 s(0.0);
  for (size_t k = 0; k < poly.size(); ++k) s += glm::cross(poly[k], poly[(k + 1) % poly.size()]);
  return 0.5 * glm::length(s);
}

/// Support function of the girdle outline in the horizontal direction (ux, uz) (any length):
/// max over the outline's points p of ux·p.x + uz·p.z.
double outlineSupport(const GirdleOutline& g, double ux, double uz) {
  const double a = 0.5 * g.length, b = 0.5 * g.width;
  switch (g.kind) {
    case GirdleOutline::Kind::Round:
      return a * std::hypot(ux, uz);
    case GirdleOutline::Kind::Oval:
      return std::hypot(a * ux, b * uz);
    case GirdleOutline::Kind::Rectangle: {
      const double c = g.corner;
      const double x = std::abs(ux), z = std::abs(uz);
      return std::max(x * a + z * (b - c), x * (a - c) + z * b);
    }
    case GirdleOutline::Kind::Pear:  // the round end's circle (centre −a + b) or the point a
      return std::max(ux * (b - a) + b * std::hypot(ux, uz), ux * a);
    case GirdleOutline::Kind::None:
      break;
  }
  return 0.0;
}

const char* sideName(FacetSide s) {
  switch (s) {
    case FacetSide::Crown:
      return "crown";
    case FacetSide::Pavilion:
      return "pavilion";
    case FacetSide::Girdle:
      return "girdle";
    case FacetSide::Table:
      return "table";
    case FacetSide::Culet:
      return "culet";
  }
  return "?";
}

/// The stone being cut: the rough block's six planes, then the facets cut so far.
class Cutter {
 public:
  Cutter(const FacetedDesign& d, double scale) : design_(d), S_(scale), tol_(1e-9 * scale) {
    for (int a = 0; a < 3; ++a)
      for (double s : {1.0, -1.0}) {
        glm::dvec3 n(0.0);
        n[a] = s;
        planes_.push_back({n, S_});
      }
  }

  void cutTier(size_t t) {
    const FacetTier& tier = design_.tiers[t];
    for (size_t k = 0; k < tier.indices.size(); ++k) {
      const int index = tier.indices[k];
      // Where errors point: the tier, and the index when the tier has several.
      const std::string idx =
          tier.indices.size() > 1 ? " (index " + std::to_string(index) + ")" : std::string();
      const std::string at = tier.path + idx;
      const glm::dvec3 n = facetNormal(tier.side, tier.angle_deg, index, design_.gear);
      const double d = distance(tier, n, index, index - tier.indices[0], idx);
      checkCut(n, d, at);
      planes_.push_back({n, d});
      facets_.push_back({tier.name, index, tier.side, tier.angle_deg});
      where_[{tier.name, normIndex(index)}] = planes_.size() - 1;
      paths_.push_back(at);
    }
  }

  FacetedStone finish() {
    const double L = 8.0 * S_;
    for (size_t i = 0; i < planes_.size(); ++i) {
      const double area = polygonArea(facePolygon(planes_, i, L, tol_));
      const bool present = area > 1e-10 * S_ * S_;
      if (i < 6 && present)
        throw FacetError("/tiers",
                         "the tiers do not close the stone: the rough block's face "
                         "towards " +
                             std::string(i % 2 ? "-" : "+") + "xyz"[i / 2] +
                             " is still there (add a table, a culet or tiers that meet)");
      if (i >= 6 && !present)
        throw FacetError(paths_[i - 6], std::string("the ") + sideName(facets_[i - 6].side) +
                                            " facet of tier '" + facets_[i - 6].tier +
                                            "' at index " + std::to_string(facets_[i - 6].index) +
                                            " leaves no face (later facets cut it away)");
    }
    FacetedStone stone;
    stone.shape.planes.assign(planes_.begin() + 6, planes_.end());
    stone.facets = facets_;
    finishConvex(stone.shape);
    return stone;
  }

 private:
  int normIndex(int i) const { return ((i % design_.gear) + design_.gear) % design_.gear; }

  /// `name` if it names a table or culet tier, "" otherwise.
  std::string tableName(const std::string& name) const {
    for (const auto& t : design_.tiers)
      if (t.name == name && (t.side == FacetSide::Table || t.side == FacetSide::Culet)) return name;
    return {};
  }

  /// Every vertex of the current stone.
  std::vector<glm::dvec3> vertices() const {
    std::vector<glm::dvec3> v;
    for (size_t i = 0; i < planes_.size(); ++i) {
      auto p = facePolygon(planes_, i, 8.0 * S_, tol_);
      v.insert(v.end(), p.begin(), p.end());
    }
    return v;
  }

  bool onStone(const glm::dvec3& p) const {
    for (const auto& pl : planes_)
      if (glm::dot(pl.normal, p) - pl.d > 1e-7 * S_) return false;
    return true;
  }

  void checkCut(const glm::dvec3& n, double d, const std::string& at) const {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const auto& v : vertices()) {
      lo = std::min(lo, glm::dot(n, v) - d);
      hi = std::max(hi, glm::dot(n, v) - d);
    }
    if (hi <= tol_)
      throw FacetError(at, "the facet cuts nothing (it lies " + num(-hi) +
                               " mm outside the stone cut so far; distance " + num(d) + " mm)");
    if (lo >= -tol_)
      throw FacetError(at, "the facet removes the whole stone (distance " + num(d) + " mm)");
  }

  double distance(const FacetTier& tier, const glm::dvec3& n, int index, int offset,
                  const std::string& idx) const {
    const GirdleOutline& g = design_.girdle;
    switch (tier.place) {
      case FacetTier::Place::Distance:
        return tier.value;
      case FacetTier::Place::ToCenter:
        return n.y * tier.value;
      case FacetTier::Place::MeetGirdle:
        if (g.kind == GirdleOutline::Kind::None)
          throw FacetError(tier.path + "/meet", "meets the girdle, but the object has no girdle");
        return 0.5 * g.thickness * std::abs(n.y) + outlineSupport(g, n.x, n.z);
      case FacetTier::Place::MeetLevel:
        return meetLevel(tier, n, index, tier.path + "/meet" + idx);
      case FacetTier::Place::MeetPoint:
        return meetPoint(tier, n, offset, tier.path + "/meet", idx);
    }
    return 0.0;
  }

  /// The facet meets the same-index facet of an earlier tier along the level line at height h
  /// (a step cut's step line).
  double meetLevel(const FacetTier& tier, const glm::dvec3& n, int index,
                   const std::string& at) const {  // at: the JSON path of the meet
    auto it = where_.find({tier.level_tier, normIndex(index)});
    if (it == where_.end())
      throw FacetError(at, "cannot be met: no facet of an earlier tier '" + tier.level_tier +
                               "' at index " + std::to_string(index));
    const Plane& prev = planes_[it->second];
    const double phi = 2.0 * std::numbers::pi * index / design_.gear;
    const glm::dvec3 u(std::cos(phi), 0.0, std::sin(phi));
    const double h = tier.value;
    const double nu = glm::dot(prev.normal, u);
    if (!(nu > 1e-9) || glm::length(glm::cross(prev.normal, n)) < 1e-9)
      throw FacetError(at, "cannot be met: the facet is parallel to tier '" + tier.level_tier +
                               "' there, or that tier is flat");
    // The two planes share the azimuth, so they meet in a horizontal line: any of its points
    // gives the distance. It is met if that facet's face on the stone reaches height h.
    const glm::dvec3 p = u * ((prev.d - h * prev.normal.y) / nu) + glm::dvec3(0.0, h, 0.0);
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const auto& v : facePolygon(planes_, it->second, 8.0 * S_, tol_)) {
      lo = std::min(lo, v.y);
      hi = std::max(hi, v.y);
    }
    if (!(h >= lo - tol_ && h <= hi + tol_))
      throw FacetError(at, "cannot be met: tier '" + tier.level_tier + "' does not reach height " +
                               num(h) + " mm there (its face spans " + num(lo) + " to " + num(hi) +
                               " mm)");
    return glm::dot(n, p);
  }

  /// The facet passes through the meet point of three earlier facets (indices shifted with the
  /// facet's own offset from the tier's first index).
  double meetPoint(const FacetTier& tier, const glm::dvec3& n, int offset, const std::string& at,
                   const std::string& idx) const {
    glm::dmat3 A;
    glm::dvec3 b;
    for (int r = 0; r < 3; ++r) {
      const FacetRef& ref = tier.meet[size_t(r)];
      // The table and a culet have no azimuth: they are met wherever the facet is.
      const bool flat = ref.tier == tableName(ref.tier);
      const int ri = flat ? 0 : normIndex(ref.index + offset);
      auto it = where_.find({ref.tier, ri});
      if (it == where_.end())
        throw FacetError(at + "/" + std::to_string(r) + idx,
                         "cannot be met: no facet of an earlier tier '" + ref.tier + "' at index " +
                             std::to_string(ri));
      const Plane& pl = planes_[it->second];
      A[0][r] = pl.normal.x;  // row r of A (glm is column-major)
      A[1][r] = pl.normal.y;
      A[2][r] = pl.normal.z;
      b[r] = pl.d;
    }
    if (std::abs(glm::determinant(A)) < 1e-9)
      throw FacetError(at + idx, "cannot be met: the three facets do not meet in one point");
    const glm::dvec3 p = glm::inverse(A) * b;
    if (!onStone(p))
      throw FacetError(at + idx, "cannot be met: the three facets' meet point (" + num(p.x) + ", " +
                                     num(p.y) + ", " + num(p.z) +
                                     ") is not on the stone cut so far");
    return glm::dot(n, p);
  }

  const FacetedDesign& design_;
  double S_, tol_;
  std::vector<Plane> planes_;
  std::vector<FacetInfo> facets_;
  std::vector<std::string> paths_;
  std::map<std::pair<std::string, int>, size_t> where_;
};

/// Half-size of the rough block: a few times every length the design names.
double roughScale(const FacetedDesign& d) {
  double s = std::max({d.girdle.length, d.girdle.width, d.girdle.thickness});
  for (const auto& t : d.tiers) s = std::max(s, std::abs(t.value));
  return 4.0 * s;
}

/// A design is cut to 1e-9 of its largest length (the rough block's size), so one length far
/// beyond all others (a distance of 1e12 mm beside 5 mm) leaves the other facets no precision:
/// they fail on their own lines ("removes the whole stone") though that length is at fault. When
/// cutting failed, `error` blamed on the largest length if it is more than 1000 times the next
/// one, `error` itself otherwise.
FacetError blameOutlier(const FacetedDesign& d, const FacetError& error) {
  std::string where = "/girdle";
  double largest = std::max({d.girdle.length, d.girdle.width, d.girdle.thickness}), next = 0.0;
  for (const auto& t : d.tiers) {
    const double v = std::abs(t.value);
    if (v > largest)
      next = largest, largest = v, where = t.path;
    else
      next = std::max(next, v);
  }
  for (double g : {d.girdle.length, d.girdle.width, d.girdle.thickness})
    if (g < largest) next = std::max(next, g);
  // A design of one length (next = 0) has nothing that length could be too coarse for.
  if (!(next > 0) || !(largest > 1e3 * next) || where == error.where()) return error;
  return FacetError(where, "the length " + num(largest) + " mm is more than 1000 times the " +
                               "design's next largest (" + num(next) +
                               " mm): the facets are cut to 1e-9 of the largest, too coarse for "
                               "the others (" +
                               error.where() + ": " + error.what() + ")");
}

}  // namespace

glm::dvec3 facetNormal(FacetSide side, double angle_deg, int index, int gear) {
  const double phi = 2.0 * std::numbers::pi * index / gear,
               th = angle_deg * std::numbers::pi / 180.0;
  const glm::dvec3 u(std::cos(phi), 0.0, std::sin(phi));
  switch (side) {
    case FacetSide::Crown:
      return u * std::sin(th) + glm::dvec3(0.0, std::cos(th), 0.0);
    case FacetSide::Pavilion:
      return u * std::sin(th) - glm::dvec3(0.0, std::cos(th), 0.0);
    case FacetSide::Girdle:
      return u;
    case FacetSide::Table:
      return {0.0, 1.0, 0.0};
    case FacetSide::Culet:
      return {0.0, -1.0, 0.0};
  }
  return u;
}

FacetedStone cutFaceted(const FacetedDesign& design) {
  if (design.tiers.empty()) throw FacetError("/tiers", "no tiers: nothing is cut");
  size_t count = 0;
  std::map<std::string, size_t> names;
  for (size_t t = 0; t < design.tiers.size(); ++t) {
    const FacetTier& tier = design.tiers[t];
    count += tier.indices.size();
    if (!names.emplace(tier.name, t).second)
      throw FacetError(tier.path + "/name", "tier name '" + tier.name + "' is used twice");
    for (int i : tier.indices)
      if (i < 0 || i > design.gear)
        throw FacetError(tier.path + "/index", "index " + std::to_string(i) +
                                                   " is outside the gear's range [0, " +
                                                   std::to_string(design.gear) + "]");
    const std::vector<std::string> refs =
        tier.place == FacetTier::Place::MeetLevel ? std::vector<std::string>{tier.level_tier}
        : tier.place == FacetTier::Place::MeetPoint
            ? std::vector<std::string>{tier.meet[0].tier, tier.meet[1].tier, tier.meet[2].tier}
            : std::vector<std::string>{};
    // Before cutting: a cut that failed on it was blamed on a length instead (blameOutlier).
    if (tier.place == FacetTier::Place::MeetGirdle &&
        design.girdle.kind == GirdleOutline::Kind::None)
      throw FacetError(tier.path + "/meet", "meets the girdle, but the object has no girdle");
    for (const auto& r : refs) {
      auto it = names.find(r);
      if (it == names.end() || it->second == t)
        throw FacetError(tier.path + "/meet",
                         "cannot be met: '" + r + "' is not the name of an earlier tier");
    }
  }
  if (count > kMaxFacets)
    throw FacetError("/tiers", "at most " + std::to_string(kMaxFacets) + " facets, got " +
                                   std::to_string(count));
  const double S = roughScale(design);
  if (!(S > 0)) throw FacetError("/tiers", "the design has no size (give a girdle or distances)");
  Cutter cutter(design, S);
  try {
    for (size_t t = 0; t < design.tiers.size(); ++t) cutter.cutTier(t);
    return cutter.finish();
  } catch (const FacetError& e) {
    throw blameOutlier(design, e);
  }
}

namespace {

/// One "a" record of a .asc file: angle, distance, then gear indices, "n NAME" and a trailing
/// "G comment".
FacetTier ascFacet(std::istringstream& in, int gear, const std::string& at) {
  FacetTier t;
  t.place = FacetTier::Place::Distance;
  std::string angle_s, tok;
  double angle = 0;
  if (!(in >> angle_s) || !(std::istringstream(angle_s) >> angle) || !std::isfinite(angle) ||
      !(in >> t.value) || !std::isfinite(t.value))
    throw FacetError("/file", at + ": expected 'a ANGLE DISTANCE INDEX...'");
  if (angle < -90 || angle > 90)
    throw FacetError("/file", at + ": the angle must be in [-90, 90] degrees, got " + num(angle));
  if (std::abs(t.value) > kMaxAscDistanceMm)
    throw FacetError("/file", at + ": the distance must be in [-" + num(kMaxAscDistanceMm) + ", " +
                                  num(kMaxAscDistanceMm) + "] mm, got " + num(t.value));
  if (angle == 0)
    t.side = angle_s[0] == '-' ? FacetSide::Culet : FacetSide::Table;
  else if (std::abs(angle) == 90)
    t.side = FacetSide::Girdle;
  else
    t.side = angle < 0 ? FacetSide::Pavilion : FacetSide::Crown;
  t.angle_deg = std::abs(angle);
  std::string name;
  while (in >> tok) {
    if (tok == "G") break;  // a comment to the end of the line
    if (tok == "n") {
      if (!(in >> name)) throw FacetError("/file", at + ": 'n' without a facet name");
      continue;
    }
    size_t used = 0;
    long v = -1;
    try {
      v = std::stol(tok, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != tok.size())
      throw FacetError("/file", at + ": expected a gear index, got '" + tok.substr(0, 40) + "'");
    if (v < 0 || v > gear)
      throw FacetError("/file", at + ": index " + std::to_string(v) +
                                    " is outside the gear's range [0, " + std::to_string(gear) +
                                    "]");
    t.indices.push_back(int(v));
  }
  if (t.indices.empty()) throw FacetError("/file", at + ": a facet line without an index");
  t.name = at + (name.empty() ? "" : " (" + name + ")");
  t.path = "/file: " + at;
  if (t.side == FacetSide::Table || t.side == FacetSide::Culet) t.indices.resize(1);
  return t;
}

}  // namespace

FacetedDesign readGemCadAsc(std::istream& in, const std::string& name) {
  FacetedDesign d;
  std::string line;
  // A file is quoted in messages only once it is known to be GemCad's: after a "GemCad" or "g"
  // record.
  bool gear_seen = false, recognised = false;
  for (int no = 1; std::getline(in, line); ++no) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::string at = name + " line " + std::to_string(no);
    if (line.size() > 4096) throw FacetError("/file", at + ": line longer than 4096 bytes");
    std::istringstream s(line);
    std::string key;
    if (!(s >> key)) continue;
    if (key == "GemCad") recognised = true;
    if (key == "GemCad" || key == "H" || key == "F" || key == "I" || key == "y") continue;
    if (key == "g") {
      int teeth = 0;
      if (!(s >> teeth) || teeth < 3 || teeth > 400)
        throw FacetError("/file", at + ": expected 'g TEETH OFFSET' with 3 <= TEETH <= 400");
      if (!d.tiers.empty()) throw FacetError("/file", at + ": the gear must precede the facets");
      d.gear = teeth;
      gear_seen = recognised = true;
    } else if (key == "a") {
      if (!gear_seen) throw FacetError("/file", at + ": a facet before the 'g' (gear) line");
      d.tiers.push_back(ascFacet(s, d.gear, at));
    } else if (!recognised) {
      // Not GemCad's export (a wrong file named .asc, say /etc/passwd): its text is not quoted.
      throw FacetError("/file", at + ": not a GemCad .asc file: expected its first record to be "
                                     "'GemCad VERSION' or 'g TEETH OFFSET'");
    } else {
      throw FacetError(
          "/file", at + ": unknown record '" + key.substr(0, 40) + "' (GemCad, g, y, I, H, F, a)");
    }
  }
  if (d.tiers.empty()) throw FacetError("/file", name + ": no facets ('a' lines)");
  return d;
}

}  // namespace eikon
