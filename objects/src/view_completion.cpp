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
  double extent[2] = {box.size.x(), box.size.y()};
  Eigen::Vector2d sight = (box.center.head<2>() - viewer_xy).cast<double>();
  const double range = sight.norm();
  // Which footprint axis only shows its near face: the one nearest the line of sight, if near enough.
  int truncated_axis = -1;
  if (range >= params.min_range_m) {
    sight /= range;
    const double c0 = std::abs(axis[0].dot(sight)), c1 = std::abs(axis[1].dot(sight));
    const double limit = std::cos(params.truncation_angle_deg * kPi / 180.0);
    if (std::max(c0, c1) >= limit) truncated_axis = c0 >= c1 ? 0 : 1;
  }
  // The near face as seen, less the noise: where the object's surface most likely is.
  double near_face = 0.0, away = 1.0;
  if (truncated_axis >= 0) {
    const Eigen::Vector2d a = axis[truncated_axis];
    away = a.dot(sight) >= 0 ? 1.0 : -1.0;
    const double spread = std::min(depth_spread_m, extent[truncated_axis]);
    near_face = a.dot(box.center.head<2>().cast<double>()) - away * 0.5 * extent[truncated_axis] + away * 0.5 * spread;
    extent[truncated_axis] -= spread;
  }

  ViewedBox out;
  out.box = box;
  // score: how well the class's sizes explain the box; weight: that times the class's prior,
  // which ranks the candidates.
  struct Candidate {
    double score;
    int class_index;
    int length_axis;
    double weight;
  };
  std::vector<Candidate> candidates;
  double best_weight = 0.0;
  int best_class = -1, best_length_axis = 0;
  for (std::size_t c = 0; c < atlas.classes().size(); ++c) {
    const ObjectClass& cls = atlas.classes()[c];
    if (!cls.has_priors || (only_class >= 0 && static_cast<int>(c) != only_class)) continue;
    const double h = ExtentCost(cls.height, box.size.z(), false);
    if (h < 0) continue;
    for (int length_axis = 0; length_axis < 2; ++length_axis) {
      const int width_axis = 1 - length_axis;
      const double l = ExtentCost(cls.length, extent[length_axis], truncated_axis == length_axis);
      const double w = ExtentCost(cls.width, extent[width_axis], truncated_axis == width_axis);
      if (l < 0 || w < 0) continue;
      const double score = std::exp(-0.5 * (l + w + h));
      candidates.push_back({score, static_cast<int>(c), length_axis, score * cls.prior});
    }
  }
  for (const Candidate& k : candidates) {
    if (k.weight > best_weight) {
      best_weight = k.weight;
      best_class = k.class_index;
      best_length_axis = k.length_axis;
    }
  }
  if (truncated_axis >= 0 && best_class >= 0) {
    auto completed_extent = [&](int class_index, int length_axis) {
      const ObjectClass& cls = atlas.classes()[static_cast<std::size_t>(class_index)];
      return length_axis == truncated_axis ? cls.length.mean_m : cls.width.mean_m;
    };
    double least = completed_extent(best_class, best_length_axis);
    for (const Candidate& k : candidates) {
      const double completed = completed_extent(k.class_index, k.length_axis);
      if (k.weight * params.ambiguity_ratio >= best_weight && completed < least) {
        least = completed;
        best_class = k.class_index;
        best_length_axis = k.length_axis;
      }
    }
  }
  double best_score = 0.0;
  for (const Candidate& k : candidates) {
    if (k.class_index == best_class && k.length_axis == best_length_axis) best_score = k.score;
  }
  if (best_class < 0 || best_score < atlas.min_score()) {
    out.classification = {atlas.unknown_index(), 1.0 - best_score};
    return out;
  }
  out.classification = {best_class, best_score};
  if (truncated_axis < 0) return out;

  const ObjectClass& cls = atlas.classes()[static_cast<std::size_t>(best_class)];
  const double mean = truncated_axis == best_length_axis ? cls.length.mean_m : cls.width.mean_m;
  const double completed = std::max(mean, extent[truncated_axis]);
  // Grow away from the viewer from the near face: the side that was seen keeps its place.
  const Eigen::Vector2d a = axis[truncated_axis];
  const double along_now = a.dot(box.center.head<2>().cast<double>());
  const Eigen::Vector2d shift = a * (near_face + away * 0.5 * completed - along_now);
  out.box.center.x() += static_cast<float>(shift.x());
  out.box.center.y() += static_cast<float>(shift.y());
  out.box.size[truncated_axis] = static_cast<float>(completed);
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
