#include "romo/objects/view_completion.hpp"

#include <cmath>
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

// One reading of which footprint axis shows only its near face (-1: none), with the extents
// and near face that follow from it.
struct Reading {
  int truncated_axis = -1;
  double extent[2] = {0.0, 0.0};  ///< the truncated one less the depth noise
  double near_face = 0.0;         ///< along the truncated axis: where the seen surface most likely is
  double away = 1.0;              ///< +-1: the truncated axis's direction away from the viewer
};

// How well a class explains a reading (score) and that times its prior (weight, which ranks).
struct Candidate {
  double score;
  double weight;
  int class_index;
  int length_axis;
  int reading;
};

// Every class with priors competes when @p only_class < 0, else only that one.
ViewedBox Classify(const Atlas& atlas, const Box3& box, const Eigen::Vector2f& viewer_xy,
                   const ViewCompletionParams& params, double depth_spread_m, int only_class) {
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
  const Eigen::Vector2d axis[2] = {{std::cos(box.yaw_rad), std::sin(box.yaw_rad)},
                                   {-std::sin(box.yaw_rad), std::cos(box.yaw_rad)}};
  const double extent[2] = {box.size.x(), box.size.y()};
  Eigen::Vector2d sight = (box.center.head<2>() - viewer_xy).cast<double>();
  const double range = sight.norm();
  auto reading = [&](int truncated_axis) {
    Reading r;
    r.truncated_axis = truncated_axis;
    r.extent[0] = extent[0];
    r.extent[1] = extent[1];
    if (truncated_axis < 0) return r;
    const Eigen::Vector2d a = axis[truncated_axis];
    r.away = a.dot(sight) >= 0 ? 1.0 : -1.0;
    const double spread = std::min(depth_spread_m, extent[truncated_axis]);
    r.near_face = a.dot(box.center.head<2>().cast<double>()) - r.away * 0.5 * extent[truncated_axis] +
                  r.away * 0.5 * spread;
    r.extent[truncated_axis] -= spread;
    return r;
  };
  // Which footprint axis only shows its near face: the one nearest the line of sight, if near
  // enough; and for a lone face (thin across one axis) also its normal, whatever the angle. Both
  // readings compete: two people one behind the other along the sight line look like a face seen
  // at a grazing angle, and the classes' sizes tell which reading explains the box.
  std::vector<Reading> readings;
  int face_reading = -1;  // index of the lone-face reading, if any
  if (range >= params.min_range_m) {
    sight /= range;
    const double c[2] = {std::abs(axis[0].dot(sight)), std::abs(axis[1].dot(sight))};
    if (std::max(c[0], c[1]) >= std::cos(params.truncation_angle_deg * kPi / 180.0)) {
      readings.push_back(reading(c[0] >= c[1] ? 0 : 1));
    }
    const int thin = extent[0] <= extent[1] ? 0 : 1;
    const bool face = extent[thin] <= params.face_max_thickness_m &&
                      extent[thin] <= params.face_max_aspect * extent[1 - thin] &&
                      c[thin] >= std::cos(params.face_max_obliquity_deg * kPi / 180.0);
    if (face && (readings.empty() || readings.front().truncated_axis != thin)) {
      face_reading = static_cast<int>(readings.size());
      readings.push_back(reading(thin));
    }
  }
  if (readings.empty()) readings.push_back(reading(-1));

  std::vector<Candidate> candidates;
  for (std::size_t c = 0; c < atlas.classes().size(); ++c) {
    const ObjectClass& cls = atlas.classes()[c];
    if (!cls.has_priors || (only_class >= 0 && static_cast<int>(c) != only_class)) continue;
    const double h = ExtentCost(cls.height, box.size.z(), false);
    if (h < 0) continue;
    for (std::size_t k = 0; k < readings.size(); ++k) {
      const Reading& r = readings[k];
      for (int length_axis = 0; length_axis < 2; ++length_axis) {
        const int width_axis = 1 - length_axis;
        const double l = ExtentCost(cls.length, r.extent[length_axis], r.truncated_axis == length_axis);
        const double w = ExtentCost(cls.width, r.extent[width_axis], r.truncated_axis == width_axis);
        if (l < 0 || w < 0) continue;
        const double score = std::exp(-0.5 * (l + w + h));
        if (static_cast<int>(k) == face_reading && score < params.face_min_score) continue;
        candidates.push_back({score, score * cls.prior, static_cast<int>(c), length_axis, static_cast<int>(k)});
      }
    }
  }
  const Candidate* best = nullptr;
  for (const Candidate& k : candidates) {
    if (best == nullptr || k.weight > best->weight) best = &k;
  }
  auto completed_extent = [&](const Candidate& k) {
    const ObjectClass& cls = atlas.classes()[static_cast<std::size_t>(k.class_index)];
    return k.length_axis == readings[static_cast<std::size_t>(k.reading)].truncated_axis ? cls.length.mean_m
                                                                                        : cls.width.mean_m;
  };
  if (best != nullptr && readings[static_cast<std::size_t>(best->reading)].truncated_axis >= 0) {
    // With a truncated extent the hidden depth says nothing: of the classes explaining the same
    // reading about as well, the one needing the least completion wins.
    const Candidate* least = best;
    for (const Candidate& k : candidates) {
      if (k.reading == best->reading && k.weight * params.ambiguity_ratio >= best->weight &&
          completed_extent(k) < completed_extent(*least)) {
        least = &k;
      }
    }
    best = least;
  }

  ViewedBox out;
  out.box = box;
  if (best == nullptr || best->score < atlas.min_score()) {
    out.classification = {atlas.unknown_index(), 1.0 - (best != nullptr ? best->score : 0.0)};
    return out;
  }
  out.classification = {best->class_index, best->score};
  const Reading& r = readings[static_cast<std::size_t>(best->reading)];
  if (r.truncated_axis < 0) return out;

  const double completed = std::max(completed_extent(*best), r.extent[r.truncated_axis]);
  // Grow away from the viewer from the near face: the side that was seen keeps its place.
  const Eigen::Vector2d a = axis[r.truncated_axis];
  const double along_now = a.dot(box.center.head<2>().cast<double>());
  const Eigen::Vector2d shift = a * (r.near_face + r.away * 0.5 * completed - along_now);
  out.box.center.x() += static_cast<float>(shift.x());
  out.box.center.y() += static_cast<float>(shift.y());
  out.box.size[r.truncated_axis] = static_cast<float>(completed);
  out.completed = true;
  if (out.box.size.y() > out.box.size.x()) {
    // Keep the box's convention (axes.col(0) along the length) after the length changed axis.
    std::swap(out.box.size.x(), out.box.size.y());
    out.box.yaw_rad = static_cast<float>(std::remainder(box.yaw_rad + kPi / 2, kPi));
    Eigen::Vector3f length_dir = out.box.axes.col(1), width_dir = -out.box.axes.col(0);
    if (std::cos(out.box.yaw_rad) * length_dir.x() + std::sin(out.box.yaw_rad) * length_dir.y() < 0) {
      length_dir = -length_dir;  // the heading wrapped by pi; turning both keeps the frame right-handed
      width_dir = -width_dir;
    }
    out.box.axes.col(0) = length_dir;
    out.box.axes.col(1) = width_dir;
  }
  return out;
}

}  // namespace

ViewedBox ClassifyFromViewpoint(const Atlas& atlas, const Box3& box, const Eigen::Vector2f& viewer_xy,
                                const ViewCompletionParams& params, double depth_spread_m) {
  return Classify(atlas, box, viewer_xy, params, depth_spread_m, -1);
}

ViewedBox CompleteAsClass(const Atlas& atlas, int class_index, const Box3& box, const Eigen::Vector2f& viewer_xy,
                          const ViewCompletionParams& params, double depth_spread_m) {
  if (class_index < 0 || class_index >= static_cast<int>(atlas.classes().size())) {
    Fail("CompleteAsClass: class index " + std::to_string(class_index) + " is not in the atlas (" +
         std::to_string(atlas.classes().size()) + " classes)");
  }
  return Classify(atlas, box, viewer_xy, params, depth_spread_m, class_index);
}

}  // namespace romo::objects
