#include "romo/indoor_manip/knowledge.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "romo/core/json.hpp"
#include "romo/indoor_manip/manip_analyzer.hpp"

namespace romo::indoor_manip {
namespace {

std::string Num(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return buf;
}

template <typename Vec>
std::string Arr(const Vec& v) {
  std::string s = "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) s += (i ? ", " : "") + Num(static_cast<double>(v[i]));
  return s + "]";
}

std::string Str(const std::string& s) { return "\"" + JsonEscape(s) + "\""; }

std::string BoxJson(const objects::Box3& b) {
  return "{\"center_m\": " + Arr(b.center) + ", \"size_m\": " + Arr(b.size) + ", \"axes\": [" +
         Arr(b.axes.col(0)) + ", " + Arr(b.axes.col(1)) + ", " + Arr(b.axes.col(2)) + "]}";
}

// The blob map's view of an object: completed box (highest-confidence points), points per
// confidence band, mean confidence.
std::string CompletedJson(const CompletedObject& c) {
  std::string s = "{\"blob_id\": " + std::to_string(c.blob_id) + ", \"points\": " + std::to_string(c.points) +
                  ", \"mean_confidence\": " + Num(c.mean_confidence) + ", \"points_per_band\": [";
  for (std::size_t i = 0; i < c.points_per_band.size(); ++i) {
    s += std::string(i ? ", " : "") + "{\"cv_from\": " + Num(kConfidenceBandLow[i]) + ", \"points\": " +
         std::to_string(c.points_per_band[i]) + "}";
  }
  s += "], \"completed_points\": " + std::to_string(c.completed_points) + ", \"completed_box\": " +
       (c.completed_box ? BoxJson(*c.completed_box) : std::string("null")) + ", \"completed_pca_box\": " +
       (c.completed_pca_box ? BoxJson(*c.completed_pca_box) : std::string("null")) + "}";
  return s;
}

}  // namespace

KnowledgeContainer BuildKnowledge(const ManipResult& r, const ObjectFunctionAtlas& atlas) {
  KnowledgeContainer kc;
  kc.physics.plane = r.plane;
  kc.physics.plane_inliers = r.scene.plane_inliers;
  kc.physics.objects = r.scene.objects;
  kc.physics.completed = r.completed_objects;
  kc.physics.map = r.object_map;
  auto& m = kc.motions;
  m.frames = r.frames;
  m.frames_with_hand = r.frames - r.frames_without_hand;
  m.duration_s = r.path.size() > 1 ? r.path.back().t_s - r.path.front().t_s : 0.0;
  for (std::size_t i = 1; i < r.path.size(); ++i) {
    m.hand_path_length_m += (r.path[i].corrected_m - r.path[i - 1].corrected_m).norm();
  }
  m.fingerprint_extent_m = r.fingerprint.box_extent_m;
  m.fingerprint_height_m = r.fingerprint.box_height_m;
  for (const auto& s : r.rotation_steps_rad) m.cumulative_rotation_deg += s * 180.0 / M_PI;
  m.features = r.features;
  m.transports = r.locations.transports;
  m.object_motions = r.object_motions;
  kc.locations.areas = r.locations.areas;
  kc.action.label = r.decision.label;
  kc.action.reasons = r.decision.reasons;
  kc.action.functions = atlas.FunctionsFor(r.decision.label);
  return kc;
}

std::string KnowledgeContainer::ToJson() const {
  std::ostringstream s;
  s << "{\n  \"physics\": {\n    \"plane\": {\"normal\": " << Arr(physics.plane.normal)
    << ", \"d_m\": " << Num(physics.plane.d_m) << ", \"inliers\": " << physics.plane_inliers << "},\n";
  s << "    \"objects\": [";
  for (std::size_t i = 0; i < physics.objects.size(); ++i) {
    const auto& o = physics.objects[i];
    std::string completed = "null";
    for (const auto& c : physics.completed) {
      if (c.first_frame_object == o.id) completed = CompletedJson(c);
    }
    s << (i ? ",\n      " : "\n      ") << "{\"id\": " << o.id << ", \"points\": " << o.points
      << ", \"is_hand\": " << (o.is_hand ? "true" : "false") << ", \"pca_box\": " << BoxJson(o.box)
      << ", \"height_above_plane_m\": " << Num(o.height_above_plane_m) << ", \"completed\": " << completed << "}";
  }
  s << "],\n    \"later_objects\": [";
  bool first = true;
  for (const auto& c : physics.completed) {
    if (c.first_frame_object >= 0) continue;
    s << (first ? "\n      " : ",\n      ") << CompletedJson(c);
    first = false;
  }
  const auto& st = physics.map;
  s << "],\n    \"blob_map\": {\"frames_fused\": " << st.frames_fused << ", \"ego_failures\": " << st.ego_failures
    << ", \"rekeys\": " << st.rekeys << ", \"matched\": " << st.matched << ", \"unpredicted\": " << st.unpredicted
    << ", \"unobserved\": " << st.unobserved << "}\n  },\n";
  const auto& m = motions;
  s << "  \"motions\": {\n    \"frames\": " << m.frames << ", \"frames_with_hand\": " << m.frames_with_hand
    << ", \"duration_s\": " << Num(m.duration_s) << ", \"hand_path_length_m\": " << Num(m.hand_path_length_m)
    << ",\n    \"fingerprint_extent_m\": " << Arr(m.fingerprint_extent_m)
    << ", \"fingerprint_height_m\": " << Num(m.fingerprint_height_m)
    << ", \"cumulative_rotation_deg\": " << Arr(m.cumulative_rotation_deg) << ",\n    \"features\": {";
  const auto named = m.features.Named();
  for (std::size_t i = 0; i < named.size(); ++i) {
    s << (i ? ", " : "") << Str(named[i].first) << ": " << Num(named[i].second);
  }
  s << "},\n    \"transports\": [";
  for (std::size_t i = 0; i < m.transports.size(); ++i) {
    const auto& t = m.transports[i];
    s << (i ? ", " : "") << "{\"from_area\": " << t.from_area << ", \"to_area\": " << t.to_area
      << ", \"length_m\": " << Num(t.length_m) << ", \"duration_s\": " << Num(t.duration_s) << "}";
  }
  s << "],\n    \"object_motions\": [";
  for (std::size_t i = 0; i < m.object_motions.size(); ++i) {
    const auto& om = m.object_motions[i];
    const Eigen::AngleAxisd aa(om.T_k1_k.linear());
    s << (i ? ", " : "") << "{\"object_id\": " << om.object_id << ", \"translation_m\": "
      << Arr(om.T_k1_k.translation()) << ", \"rotation_deg\": " << Num(aa.angle() * 180.0 / M_PI)
      << ", \"feature_matches\": " << om.feature_matches << ", \"icp_rmse_m\": " << Num(om.icp_rmse_m) << "}";
  }
  s << "]\n  },\n  \"locations\": {\"areas\": [";
  for (std::size_t i = 0; i < locations.areas.size(); ++i) {
    const auto& a = locations.areas[i];
    s << (i ? ",\n    " : "\n    ") << "{\"id\": " << i << ", \"centre_camera_m\": " << Arr(a.centre_camera_m)
      << ", \"radius_m\": " << Num(a.radius_m) << ", \"dwell_s\": " << Num(a.dwell_s)
      << ", \"transport_starts\": " << a.transport_starts << ", \"transport_ends\": " << a.transport_ends << "}";
  }
  s << "]},\n  \"action\": {\"label\": " << Str(action.label) << ", \"reasons\": [";
  for (std::size_t i = 0; i < action.reasons.size(); ++i) s << (i ? ", " : "") << Str(action.reasons[i]);
  s << "],\n    \"functions\": [";
  for (std::size_t i = 0; i < action.functions.size(); ++i) {
    const auto& f = action.functions[i];
    s << (i ? ", " : "") << "{\"object\": " << Str(f.object) << ", \"interaction_plane\": "
      << Str(f.interaction_plane) << ", \"motion\": " << Str(f.motion) << ", \"pattern\": " << Str(f.pattern) << "}";
  }
  s << "]}\n}\n";
  return s.str();
}

}  // namespace romo::indoor_manip
