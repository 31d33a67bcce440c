#include "romo/objects/view_completion.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>
#include <vector>
#include <sstream>
#include <string>

#include "romo/core/check.hpp"

namespace romo::objects {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Squared z-score of extent @p x under @p prior; negative when the extent is impossible. A
// truncated extent is a lower bound: shorter than the mean costs nothing, longer counts as usual.
double ExtentCost(const SizePrior& prior, double x, bool truncated) {
  if (x > prior.max_m) return -1.0;
  if (truncated && x <= prior.mean_m) return 0.0;
  if (x < prior.min_m) return -1.0;
  const double z = (x - prior.mean_m) / prior.sigma_m;
  return z * z;
}

// The box's footprint axes (col(0) along its length), its extents along them, and the unit line
// of sight from the viewer (zero when too near to have one).
struct Footprint {
  Eigen::Vector2d axis[2];
  double extent[2];
  Eigen::Vector2d center;
  Eigen::Vector2d sight = Eigen::Vector2d::Zero();
};

// One reading of which footprint axis shows only its near face (-1: none), with the extents
// and near face that follow from it.
struct Reading {
  int truncated_axis = -1;
  double extent[2] = {0.0, 0.0};  ///< the truncated one less the depth noise
  double near_face = 0.0;         ///< along the truncated axis: where the seen surface most likely is
  double away = 1.0;              ///< +-1: the truncated axis's direction away from the viewer
  bool lone_face = false;         ///< read as one face, whatever the sight line's angle
};

// How well a class explains a reading (score) and that times its prior (weight, which ranks).
struct Candidate {
  double score;
  double weight;
  int class_index;
  int length_axis;
  const Reading* reading;
};

Reading ReadTruncated(const Footprint& f, int truncated_axis, double depth_spread_m) {
  Reading r;
  r.truncated_axis = truncated_axis;
  r.extent[0] = f.extent[0];
  r.extent[1] = f.extent[1];
  if (truncated_axis < 0) return r;
  const Eigen::Vector2d& a = f.axis[truncated_axis];
  r.away = a.dot(f.sight) >= 0 ? 1.0 : -1.0;
  const double spread = std::min(depth_spread_m, f.extent[truncated_axis]);
  r.near_face = a.dot(f.center) - r.away * 0.5 * f.extent[truncated_axis] + r.away * 0.5 * spread;
  r.extent[truncated_axis] -= spread;
  return r;
}

// Which footprint axis only shows its near face: the one nearest the line of sight, if near
// enough; and for a lone face (thin across one axis) also its normal, whatever the angle. Both
// readings compete: two people one behind the other along the sight line look like a face seen
// at a grazing angle, and the classes' sizes tell which reading explains the box.
std::vector<Reading> Readings(const Footprint& f, const ViewCompletionParams& params, double depth_spread_m) {
  std::vector<Reading> readings;
  if (!f.sight.isZero()) {
    const double c[2] = {std::abs(f.axis[0].dot(f.sight)), std::abs(f.axis[1].dot(f.sight))};
    if (std::max(c[0], c[1]) >= std::cos(params.truncation_angle_deg * kPi / 180.0)) {
      readings.push_back(ReadTruncated(f, c[0] >= c[1] ? 0 : 1, depth_spread_m));
    } else if (params.corner_angle_deg > 45.0 &&
               std::min(c[0], c[1]) >= std::cos(params.corner_angle_deg * kPi / 180.0)) {
      // Seen at a corner: either side may be the one cut off (by a neighbour, the image border
      // or the end of the stereo range); the classes' sizes tell which.
      readings.push_back(ReadTruncated(f, 0, depth_spread_m));
      readings.push_back(ReadTruncated(f, 1, depth_spread_m));
    }
    const int thin = f.extent[0] <= f.extent[1] ? 0 : 1;
    const bool face = f.extent[thin] <= params.face_max_thickness_m &&
                      f.extent[thin] <= params.face_max_aspect * f.extent[1 - thin] &&
                      c[thin] >= std::cos(params.face_max_obliquity_deg * kPi / 180.0);
    if (face && (readings.empty() || readings.front().truncated_axis != thin)) {
      readings.push_back(ReadTruncated(f, thin, depth_spread_m));
      readings.back().lone_face = true;
    }
  }
  if (readings.empty()) readings.push_back(ReadTruncated(f, -1, depth_spread_m));
  return readings;
}

// Every class with priors under every reading when @p only_class < 0, else only that class; with
// @p only_length_axis >= 0 only with that footprint axis as the length.
std::vector<Candidate> Candidates(const Atlas& atlas, double height_m, const std::vector<Reading>& readings,
                                  const ViewCompletionParams& params, int only_class, int only_length_axis) {
  std::vector<Candidate> candidates;
  for (std::size_t c = 0; c < atlas.classes().size(); ++c) {
    const ObjectClass& cls = atlas.classes()[c];
    if (!cls.has_priors || (only_class >= 0 && static_cast<int>(c) != only_class)) continue;
    const double h = ExtentCost(cls.height, height_m, false);
    if (h < 0) continue;
    for (const Reading& r : readings) {
      for (int length_axis = 0; length_axis < 2; ++length_axis) {
        if (only_length_axis >= 0 && length_axis != only_length_axis) continue;
        const int width_axis = 1 - length_axis;
        const double l = ExtentCost(cls.length, r.extent[length_axis], r.truncated_axis == length_axis);
        const double w = ExtentCost(cls.width, r.extent[width_axis], r.truncated_axis == width_axis);
        if (l < 0 || w < 0) continue;
        const double score = std::exp(-0.5 * (l + w + h));
        if (r.lone_face && score < params.face_min_score) continue;
        candidates.push_back({score, score * cls.prior, static_cast<int>(c), length_axis, &r});
      }
    }
  }
  return candidates;
}

// The class's mean extent along the candidate reading's truncated axis.
double CompletedExtent(const Atlas& atlas, const Candidate& k) {
  const ObjectClass& cls = atlas.classes()[static_cast<std::size_t>(k.class_index)];
  return k.length_axis == k.reading->truncated_axis ? cls.length.mean_m : cls.width.mean_m;
}

// The heaviest candidate; with a truncated extent the hidden depth says nothing, so of the
// classes explaining the same reading about as well, the one needing the least completion.
const Candidate* Choose(const Atlas& atlas, const std::vector<Candidate>& candidates,
                        const ViewCompletionParams& params) {
  const Candidate* best = nullptr;
  for (const Candidate& k : candidates) {
    if (best == nullptr || k.weight > best->weight) best = &k;
  }
  if (best == nullptr || best->reading->truncated_axis < 0) return best;
  const Candidate* least = best;
  for (const Candidate& k : candidates) {
    if (k.reading == best->reading && k.weight * params.ambiguity_ratio >= best->weight &&
        CompletedExtent(atlas, k) < CompletedExtent(atlas, *least)) {
      least = &k;
    }
  }
  return least;
}

// @p box grown to @p completed along @p r's truncated axis, away from the viewer from the near
// face: the side that was seen keeps its place.
Box3 Completed(const Box3& box, const Footprint& f, const Reading& r, double completed) {
  Box3 out = box;
  const Eigen::Vector2d& a = f.axis[r.truncated_axis];
  const Eigen::Vector2d shift = a * (r.near_face + r.away * 0.5 * completed - a.dot(f.center));
  out.center.x() += static_cast<float>(shift.x());
  out.center.y() += static_cast<float>(shift.y());
  out.size[r.truncated_axis] = static_cast<float>(completed);
  if (out.size.y() > out.size.x()) {
    // Keep the box's convention (axes.col(0) along the length) after the length changed axis.
    std::swap(out.size.x(), out.size.y());
    out.yaw_rad = static_cast<float>(std::remainder(box.yaw_rad + kPi / 2, kPi));
    Eigen::Vector3f length_dir = out.axes.col(1), width_dir = -out.axes.col(0);
    if (std::cos(out.yaw_rad) * length_dir.x() + std::sin(out.yaw_rad) * length_dir.y() < 0) {
      length_dir = -length_dir;  // the heading wrapped by pi; turning both keeps the frame right-handed
      width_dir = -width_dir;
    }
    out.axes.col(0) = length_dir;
    out.axes.col(1) = width_dir;
  }
  return out;
}

// Every class with priors competes when @p only_class < 0, else only that one.
ViewedBox Classify(const Atlas& atlas, const Box3& box, const Eigen::Vector2f& viewer_xy,
                   const ViewCompletionParams& params, double depth_spread_m, int only_class,
                   std::optional<double> length_heading_rad = std::nullopt) {
  if (!(depth_spread_m >= 0.0) || !std::isfinite(depth_spread_m)) {
    Fail("ClassifyFromViewpoint: depth_spread_m must be finite and >= 0, got " + std::to_string(depth_spread_m));
  }
  if (!box.size.allFinite() || !box.center.allFinite() || !std::isfinite(box.yaw_rad) ||
      !viewer_xy.allFinite()) {
    std::ostringstream m;
    m << "ClassifyFromViewpoint: non-finite box (centre " << box.center.transpose() << ", size "
      << box.size.transpose() << ", yaw " << box.yaw_rad << ") or viewer (" << viewer_xy.transpose() << ")";
    Fail(m.str());
  }
  Footprint f;
  f.axis[0] = {std::cos(box.yaw_rad), std::sin(box.yaw_rad)};
  f.axis[1] = {-std::sin(box.yaw_rad), std::cos(box.yaw_rad)};
  f.extent[0] = box.size.x();
  f.extent[1] = box.size.y();
  f.center = box.center.head<2>().cast<double>();
  const Eigen::Vector2d sight = f.center - viewer_xy.cast<double>();
  if (sight.norm() >= params.min_range_m) f.sight = sight.normalized();

  std::vector<Reading> readings = Readings(f, params, depth_spread_m);
  int length_axis = -1;
  if (length_heading_rad) {
    // The heading is known from elsewhere (the row the car is parked in): its axis is the
    // length, and the near end may be all that was seen whatever angle the sight line makes.
    const Eigen::Vector2d heading(std::cos(*length_heading_rad), std::sin(*length_heading_rad));
    length_axis = std::abs(f.axis[0].dot(heading)) >= std::abs(f.axis[1].dot(heading)) ? 0 : 1;
    const bool read_truncated = std::any_of(readings.begin(), readings.end(),
                                            [&](const Reading& r) { return r.truncated_axis == length_axis; });
    if (!read_truncated && !f.sight.isZero()) readings.push_back(ReadTruncated(f, length_axis, depth_spread_m));
  }
  const std::vector<Candidate> candidates =
      Candidates(atlas, box.size.z(), readings, params, only_class, length_axis);
  const Candidate* best = Choose(atlas, candidates, params);
  ViewedBox out;
  out.box = box;
  if (best == nullptr || best->score < atlas.min_score()) {
    out.classification = {atlas.unknown_index(), 1.0 - (best != nullptr ? best->score : 0.0)};
    return out;
  }
  out.classification = {best->class_index, best->score};
  const Reading& r = *best->reading;
  if (r.truncated_axis < 0) return out;
  out.box = Completed(box, f, r, std::max(CompletedExtent(atlas, *best), r.extent[r.truncated_axis]));
  out.completed = true;
  return out;
}

}  // namespace

ViewedBox ClassifyFromViewpoint(const Atlas& atlas, const Box3& box, const Eigen::Vector2f& viewer_xy,
                                const ViewCompletionParams& params, double depth_spread_m) {
  return Classify(atlas, box, viewer_xy, params, depth_spread_m, -1);
}

ViewedBox CompleteAsClass(const Atlas& atlas, int class_index, const Box3& box, const Eigen::Vector2f& viewer_xy,
                          const ViewCompletionParams& params, double depth_spread_m,
                          std::optional<double> length_heading_rad) {
  if (class_index < 0 || class_index >= static_cast<int>(atlas.classes().size())) {
    Fail("CompleteAsClass: class index " + std::to_string(class_index) + " is not in the atlas (" +
         std::to_string(atlas.classes().size()) + " classes)");
  }
  if (length_heading_rad && !std::isfinite(*length_heading_rad)) {
    Fail("CompleteAsClass: non-finite length heading " + std::to_string(*length_heading_rad));
  }
  return Classify(atlas, box, viewer_xy, params, depth_spread_m, class_index, length_heading_rad);
}

}  // namespace romo::objects
