#include "romo/indoor_manip/scene_objects.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "romo/core/check.hpp"
#include "romo/indoor_manip/manip_session.hpp"
#include "romo/indoor_manip/rgbd_odometry.hpp"
#include "romo/mapping/ego_motion.hpp"
#include "romo/mapping/segmentation.hpp"

namespace romo::indoor_manip {

void SceneObjectParams::Validate() const {
  if (!(min_height_m > 0.0)) Fail("scene_objects.min_height_m must be > 0, got " + std::to_string(min_height_m));
  if (!(leaf_size_m > 0.f)) Fail("scene_objects.leaf_size_m must be > 0, got " + std::to_string(leaf_size_m));
  if (min_blob_points < 4) Fail("scene_objects.min_blob_points must be >= 4, got " + std::to_string(min_blob_points));
}

SceneGeometry SegmentSceneObjects(const RgbdImage& image, const DepthIntrinsics& intrinsics,
                                  const InteractionPlane& plane, cv::Point hand_seed,
                                  const SceneObjectParams& params) {
  params.Validate();
  const Eigen::Matrix3Xf xyz = OrganizedCloud(image, intrinsics);
  constexpr double kPlaneInlierM = 0.01;  // the band ChooseInteractionPlane fits with
  SceneGeometry g;
  std::vector<int> foreground;
  for (Eigen::Index i = 0; i < xyz.cols(); ++i) {
    if (!xyz.col(i).allFinite()) continue;
    // The plane is oriented towards the camera: objects on it have positive distance.
    const double r = plane.Distance(xyz.col(i).cast<double>());
    if (std::abs(r) <= kPlaneInlierM) ++g.plane_inliers;
    if (r >= params.min_height_m) foreground.push_back(static_cast<int>(i));
  }
  g.foreground_points = static_cast<int>(foreground.size());
  mapping::SegmentationParams sp;
  sp.leaf_size_m = params.leaf_size_m;
  sp.min_blob_points = params.min_blob_points;
  const mapping::Segmentation seg = mapping::SegmentBlobs(xyz, sp, &foreground);
  g.occupied_leaves = static_cast<int>(seg.occupied_leaves);
  const bool seed_inside = hand_seed.x >= 0 && hand_seed.y >= 0 && hand_seed.x < image.width() &&
                           hand_seed.y < image.height();
  const int seed_index = seed_inside ? hand_seed.y * image.width() + hand_seed.x : -1;
  for (std::size_t b = 0; b < seg.blobs.size(); ++b) {
    const auto& idx = seg.blobs[b];
    SceneObject o;
    o.id = static_cast<int>(b);
    o.box = objects::FitPcaBox(xyz, idx);
    o.points = static_cast<int>(idx.size());
    for (int i : idx) o.height_above_plane_m = std::max(o.height_above_plane_m, plane.Distance(xyz.col(i).cast<double>()));
    o.is_hand = seed_index >= 0 && std::binary_search(idx.begin(), idx.end(), seed_index);
    o.pixels = idx;  // the organized cloud's index is the pixel index
    g.objects.push_back(o);
  }
  return g;
}

namespace {

// Object id per pixel (-1: none).
std::vector<int> LabelImage(const SceneGeometry& g, int n) {
  std::vector<int> label(static_cast<std::size_t>(n), -1);
  for (std::size_t o = 0; o < g.objects.size(); ++o) {
    for (int i : g.objects[o].pixels) label[static_cast<std::size_t>(i)] = static_cast<int>(o);
  }
  return label;
}

int PixelOf(const Eigen::Vector3d& p, const DepthIntrinsics& k, int w, int h) {
  const Eigen::Vector2d uv = k.Project(p);
  const int u = static_cast<int>(std::lround(uv.x())), v = static_cast<int>(std::lround(uv.y()));
  return u >= 0 && v >= 0 && u < w && v < h ? v * w + u : -1;
}

Eigen::Matrix3Xd BlobPoints(const Eigen::Matrix3Xf& cloud, const std::vector<int>& pixels) {
  Eigen::Matrix3Xd out(3, static_cast<Eigen::Index>(pixels.size()));
  for (std::size_t i = 0; i < pixels.size(); ++i) out.col(static_cast<Eigen::Index>(i)) = cloud.col(pixels[i]).cast<double>();
  return out;
}

}  // namespace

std::vector<ObjectMotion> EstimateObjectMotions(const RgbdImage& a, const SceneGeometry& ga, const RgbdImage& b,
                                                const SceneGeometry& gb, const DepthIntrinsics& k,
                                                const OdometryParams& odometry, const mapping::IcpParams& icp) {
  std::vector<ObjectMotion> out;
  if (a.width() != b.width() || a.height() != b.height()) {
    Fail("object motion: frames of different sizes (" + std::to_string(a.width()) + "x" + std::to_string(a.height()) +
         " vs " + std::to_string(b.width()) + "x" + std::to_string(b.height()) + ")");
  }
  const int w = a.width(), h = a.height();
  mapping::MatchedPoints3D m = MatchRgbdFeatures(a, b, k, odometry);
  const auto ego = mapping::EstimateRigidMotion(m, odometry.ransac);
  if (!ego) return out;
  const std::vector<int> la = LabelImage(ga, w * h), lb = LabelImage(gb, w * h);
  std::vector<int> obj_a(m.size(), -1), obj_b(m.size(), -1);
  for (std::size_t i = 0; i < m.size(); ++i) {
    const int pa = PixelOf(m.p1.col(static_cast<Eigen::Index>(i)), k, w, h);
    const int pb = PixelOf(m.p2.col(static_cast<Eigen::Index>(i)), k, w, h);
    if (pa >= 0) obj_a[i] = la[static_cast<std::size_t>(pa)];
    if (pb >= 0) obj_b[i] = lb[static_cast<std::size_t>(pb)];
  }
  const Eigen::Matrix3Xf cloud_a = OrganizedCloud(a, k), cloud_b = OrganizedCloud(b, k);
  for (std::size_t oa = 0; oa < ga.objects.size(); ++oa) {
    // The new blob most outlier flows of this one reach.
    std::vector<int> votes(gb.objects.size(), 0);
    for (int i : ego->outliers) {
      if (obj_a[static_cast<std::size_t>(i)] == static_cast<int>(oa) && obj_b[static_cast<std::size_t>(i)] >= 0) {
        ++votes[static_cast<std::size_t>(obj_b[static_cast<std::size_t>(i)])];
      }
    }
    const auto best = std::max_element(votes.begin(), votes.end());
    if (best == votes.end() || *best < odometry.ransac.min_inliers) continue;
    const int ob = static_cast<int>(best - votes.begin());
    std::vector<char> in_k(m.size(), 0), in_k1(m.size(), 0);
    for (std::size_t i = 0; i < m.size(); ++i) {
      in_k[i] = obj_a[i] == static_cast<int>(oa);
      in_k1[i] = obj_b[i] == ob;
    }
    const auto motion = mapping::EstimateIndependentMotionIcp(
        m, *ego, in_k, in_k1, BlobPoints(cloud_a, ga.objects[oa].pixels),
        BlobPoints(cloud_b, gb.objects[static_cast<std::size_t>(ob)].pixels), odometry.ransac, icp);
    if (!motion) continue;
    ObjectMotion om;
    om.object_id = ga.objects[oa].id;
    om.T_k1_k = motion->T_2_1();
    om.feature_matches = static_cast<int>(motion->flows.inliers.size());
    om.icp_rmse_m = motion->icp.rmse_m;
    out.push_back(om);
  }
  return out;
}

}  // namespace romo::indoor_manip
