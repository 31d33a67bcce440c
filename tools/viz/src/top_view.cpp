#include "romo/viz/top_view.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "romo/core/check.hpp"

namespace romo::viz {
namespace {

constexpr double kPi = 3.14159265358979323846;

cv::Scalar ClassColour(const std::string& name) {
  if (name == "car") return {60, 160, 255};          // orange
  if (name == "pedestrian") return {255, 80, 220};   // magenta
  if (name == "cyclist") return {255, 200, 0};       // cyan-ish
  return {160, 160, 160};
}

class Canvas {
 public:
  Canvas(const TopViewParams& p, const Eigen::Vector2d& centre)
      : img(p.size_px, p.size_px, CV_8UC3, cv::Scalar(30, 30, 30)),
        centre_(centre),
        scale_(p.size_px / p.span_m),
        half_(p.size_px / 2.0) {}
  cv::Point Px(const Eigen::Vector2d& w) const {
    const Eigen::Vector2d d = w - centre_;
    return {static_cast<int>(std::lround(half_ + d.x() * scale_)),
            static_cast<int>(std::lround(half_ - d.y() * scale_))};
  }
  void Polygon(const std::vector<Eigen::Vector2d>& pts, const cv::Scalar& colour, int thickness) {
    std::vector<cv::Point> p;
    for (const auto& w : pts) p.push_back(Px(w));
    cv::polylines(img, p, true, colour, thickness, cv::LINE_AA);
  }
  void Box(const Eigen::Vector2d& c, double yaw, double length, double width, const cv::Scalar& colour,
           int thickness) {
    const Eigen::Vector2d a(std::cos(yaw) * length / 2, std::sin(yaw) * length / 2);
    const Eigen::Vector2d b(-std::sin(yaw) * width / 2, std::cos(yaw) * width / 2);
    Polygon({c + a + b, c - a + b, c - a - b, c + a - b}, colour, thickness);
  }
  // Dashes of about @p dash_px: an outline that must not be taken for a detection's box.
  void DashedPolygon(const std::vector<Eigen::Vector2d>& pts, const cv::Scalar& colour, double dash_px) {
    for (std::size_t k = 0; k < pts.size(); ++k) {
      const cv::Point2d a = Px(pts[k]), b = Px(pts[(k + 1) % pts.size()]);
      const double len = std::hypot(b.x - a.x, b.y - a.y);
      const int dashes = std::max(1, static_cast<int>(len / (2 * dash_px)));
      for (int d = 0; d < dashes; ++d) {
        const double start = static_cast<double>(d) / dashes, end = (d + 0.5) / dashes;  // then a gap as long
        cv::line(img, a + (b - a) * start, a + (b - a) * end, colour, 1, cv::LINE_AA);
      }
    }
  }
  double scale() const { return scale_; }
  cv::Mat img;

 private:
  Eigen::Vector2d centre_;
  double scale_, half_;
};

}  // namespace

void TopViewParams::Validate() const {
  if (size_px < 64 || size_px > 8192) Fail("viz: size_px must be 64..8192, got " + std::to_string(size_px));
  if (!(span_m > 1.0)) Fail("viz: span_m must be > 1, got " + std::to_string(span_m));
}

cv::Mat DrawTopView(const pipeline::FrameResult& f, const TopViewParams& params,
                    const std::vector<Eigen::Vector2d>& ego_trail, const std::string& title,
                    const std::vector<TruthOutline>& truth) {
  params.Validate();
  Canvas cv_(params, f.ego_world.position_m);
  const Eigen::Isometry3d& T = f.T_world_vehicle;
  auto world = [&](const Eigen::Vector3f& p) {
    return (T * p.cast<double>()).head<2>().eval();
  };

  // Grid every 5 m.
  const double half_span = params.span_m / 2;
  for (double g = std::floor((f.ego_world.position_m.x() - half_span) / 5) * 5;
       g < f.ego_world.position_m.x() + half_span; g += 5) {
    cv::line(cv_.img, cv_.Px({g, f.ego_world.position_m.y() - half_span}),
             cv_.Px({g, f.ego_world.position_m.y() + half_span}), cv::Scalar(50, 50, 50), 1);
  }
  for (double g = std::floor((f.ego_world.position_m.y() - half_span) / 5) * 5;
       g < f.ego_world.position_m.y() + half_span; g += 5) {
    cv::line(cv_.img, cv_.Px({f.ego_world.position_m.x() - half_span, g}),
             cv_.Px({f.ego_world.position_m.x() + half_span, g}), cv::Scalar(50, 50, 50), 1);
  }

  // Ground points (dim), obstacle points by blob.
  const std::size_t step =
      std::max<std::size_t>(1, f.ground_indices.size() / std::max(1, params.max_ground_points));
  for (std::size_t k = 0; k < f.ground_indices.size(); k += step) {
    const cv::Point p = cv_.Px(world(f.cloud.xyz.col(f.ground_indices[k])));
    if (p.x >= 0 && p.y >= 0 && p.x < cv_.img.cols && p.y < cv_.img.rows) {
      cv_.img.at<cv::Vec3b>(p) = cv::Vec3b(70, 90, 70);
    }
  }
  for (std::size_t b = 0; b < f.blobs.size(); ++b) {
    const cv::Scalar c = ClassColour(f.box_classes[b]) * 0.6;
    for (int idx : f.blobs[b]) {
      const cv::Point p = cv_.Px(world(f.cloud.xyz.col(idx)));
      if (p.x >= 0 && p.y >= 0 && p.x < cv_.img.cols && p.y < cv_.img.rows) {
        cv_.img.at<cv::Vec3b>(p) = cv::Vec3b(c[0], c[1], c[2]);
      }
    }
  }

  // Parking slots: box, approach spot, turn, sideways entry path.
  for (const auto& s : f.slots.slots) {
    const cv::Scalar colour = s.feasible ? cv::Scalar(80, 220, 80) : cv::Scalar(60, 60, 220);
    const double row_yaw = std::atan2(s.row_axis.y(), s.row_axis.x());
    cv_.Box(s.target.position_m, row_yaw, s.length_m, s.depth_m, colour, 2);
    cv::circle(cv_.img, cv_.Px(s.approach.position_m), 6, cv::Scalar(0, 230, 255), 2, cv::LINE_AA);
    for (std::size_t k = 1; k < s.entry_path_m.size(); ++k) {
      cv::line(cv_.img, cv_.Px(s.entry_path_m[k - 1]), cv_.Px(s.entry_path_m[k]), cv::Scalar(60, 60, 255), 2,
               cv::LINE_AA);
    }
    if (s.entry_path_m.size() >= 2) {
      cv::arrowedLine(cv_.img, cv_.Px(s.entry_path_m[s.entry_path_m.size() - 2]), cv_.Px(s.entry_path_m.back()),
                      cv::Scalar(60, 60, 255), 2, cv::LINE_AA, 0, 0.6);
    }
    // The turn on the spot: an arc of the rotation about the approach spot.
    const double r_px = 20;
    const double start = -(s.target.yaw_rad - s.rotation_rad) * 180 / kPi;
    cv::ellipse(cv_.img, cv_.Px(s.approach.position_m), cv::Size(r_px, r_px), 0, start,
                start - s.rotation_rad * 180 / kPi, cv::Scalar(255, 160, 40), 2, cv::LINE_AA);
    char label[96];
    std::snprintf(label, sizeof(label), "slot %d %.2fm %s c%.2f", s.slot_id, s.length_m,
                  s.feasible ? "ok" : "narrow", s.confidence);
    cv::putText(cv_.img, label, cv_.Px(s.target.position_m) + cv::Point(-40, 0), cv::FONT_HERSHEY_SIMPLEX,
                0.4, colour, 1, cv::LINE_AA);
  }

  // Truth under the detections, lighter than their class colour.
  for (const auto& t : truth) {
    cv_.DashedPolygon(t.corners_world, ClassColour(t.class_name) * 0.5 + cv::Scalar(110, 110, 110), 6);
  }

  // Boxes with class and track id.
  std::vector<int> track_of(f.boxes.size(), -1);
  for (std::size_t i = 0; i < f.obstacles.obstacles.size() && i < f.boxes.size(); ++i) {
    track_of[i] = f.obstacles.obstacles[i].track_id;
  }
  for (std::size_t i = 0; i < f.boxes.size(); ++i) {
    const auto& b = f.boxes[i];
    const Eigen::Vector2d c = world(b.center);
    const double yaw = b.yaw_rad + f.ego_world.yaw_rad;
    cv_.Box(c, yaw, b.size.x(), b.size.y(), ClassColour(f.box_classes[i]), 2);
    const std::string label = f.box_classes[i] + (track_of[i] >= 0 ? " #" + std::to_string(track_of[i]) : "");
    cv::putText(cv_.img, label, cv_.Px(c) + cv::Point(6, -6), cv::FONT_HERSHEY_SIMPLEX, 0.4,
                ClassColour(f.box_classes[i]), 1, cv::LINE_AA);
  }

  // Pedestrian predictions (ENU path drawn through the world frame: vehicle xy -> world).
  for (const auto& pred : f.predictions) {
    Eigen::Vector2d prev = (T * Eigen::Vector3d(pred.observed.vehicle_xy_m.x(), pred.observed.vehicle_xy_m.y(), 0)).head<2>();
    for (const auto& pt : pred.path) {
      const Eigen::Vector2d w = (T * Eigen::Vector3d(pt.vehicle_xy_m.x(), pt.vehicle_xy_m.y(), 0)).head<2>();
      cv::line(cv_.img, cv_.Px(prev), cv_.Px(w), cv::Scalar(255, 120, 255), 1, cv::LINE_AA);
      cv::circle(cv_.img, cv_.Px(w), 2, cv::Scalar(255, 120, 255), -1);
      prev = w;
    }
  }

  // Ego path and footprint (RoMo 2.8 x 1.6 m).
  for (std::size_t k = 1; k < ego_trail.size(); ++k) {
    cv::line(cv_.img, cv_.Px(ego_trail[k - 1]), cv_.Px(ego_trail[k]), cv::Scalar(200, 200, 200), 1, cv::LINE_AA);
  }
  cv_.Box(f.ego_world.position_m, f.ego_world.yaw_rad, 2.8, 1.6, cv::Scalar(255, 255, 255), 2);
  const Eigen::Vector2d nose = f.ego_world.position_m +
                               1.4 * Eigen::Vector2d(std::cos(f.ego_world.yaw_rad), std::sin(f.ego_world.yaw_rad));
  cv::line(cv_.img, cv_.Px(f.ego_world.position_m), cv_.Px(nose), cv::Scalar(255, 255, 255), 2, cv::LINE_AA);

  // Header: frame, stage, ground estimate, missing rigs.
  char line[200];
  std::snprintf(line, sizeof(line), "%s frame %lld  stage %s  ground n=(%.2f %.2f %.2f) d=%.2f %s", title.c_str(),
                static_cast<long long>(f.frame_sequence), planning_iface::ToString(f.slots.stage),
                f.ground_plane.normal.x(), f.ground_plane.normal.y(), f.ground_plane.normal.z(), f.ground_plane.d,
                f.ground_refined ? "fit" : "prior");
  cv::putText(cv_.img, line, {8, 18}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(230, 230, 230), 1, cv::LINE_AA);
  std::string missing;
  for (int r : f.missing_rigs) missing += " " + std::to_string(r);
  std::snprintf(line, sizeof(line), "points %zu  boxes %zu  tracks %zu  slots %zu%s%s", f.cloud.size(),
                f.boxes.size(), f.tracks.size(), f.slots.slots.size(), missing.empty() ? "" : "  MISSING rigs:",
                missing.c_str());
  cv::putText(cv_.img, line, {8, 36}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(230, 230, 230), 1, cv::LINE_AA);
  cv::putText(cv_.img, truth.empty() ? "N^  5 m grid" : "N^  5 m grid   dashed: ground truth", {8, cv_.img.rows - 10}, cv::FONT_HERSHEY_SIMPLEX, 0.4,
              cv::Scalar(150, 150, 150), 1, cv::LINE_AA);
  return cv_.img;
}

void WritePng(const std::string& path, const cv::Mat& image) {
  bool ok = false;
  try {
    ok = cv::imwrite(path, image);
  } catch (const cv::Exception& e) {
    Fail("viz: cannot write " + path + ": " + e.what());
  }
  if (!ok) Fail("viz: cannot write " + path);
}

}  // namespace romo::viz
