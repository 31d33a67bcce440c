// `romo segment`: ground removal, DFS blob segmentation, vertical boxes and their Atlas classes
// for one PCD cloud (vehicle frame, z up), as text or JSON; optionally a top-view picture and one
// PCD per blob.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "cli/command_registry.hpp"
#include "romo/core/check.hpp"
#include "romo/core/json.hpp"
#include "romo/mapping/ground_removal.hpp"
#include "romo/mapping/segmentation.hpp"
#include "romo/objects/atlas.hpp"
#include "romo/objects/box.hpp"
#include "romo/stereo/pcd_io.hpp"

namespace romo::tools {
namespace {

struct Options {
  std::string pcd;
  float leaf_m = 0.1f;
  int min_points = 10;
  float max_extent_m = 8.f;
  float ground_tolerance_m = 0.1f;
  float ground_contact_m = 0.25f;  // as romo run (PipelineParams::ground_contact_gap_m)
  bool json = false;
  std::string out_dir;
  std::string atlas;  // "" = objects::Atlas::DefaultPath()
};

struct BlobReport {
  std::vector<int> indices;
  objects::Box3 box;
  std::string cls;
};

// The Atlas class of a blob's vertical box from its extents alone (no viewpoint: a cloud file
// has none); "unknown" when no class's size priors explain it.
std::string ClassifyBlob(const objects::Atlas& atlas, const objects::Box3& box) {
  return atlas.classes()[static_cast<std::size_t>(atlas.Classify(box).class_index)].name;
}

std::string Num(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return buf;
}

std::string Vec(const Eigen::Vector3f& v) { return "[" + Num(v.x()) + ", " + Num(v.y()) + ", " + Num(v.z()) + "]"; }

void WriteTopView(const PointCloud& cloud, const mapping::GroundRemoval& ground,
                  const std::vector<BlobReport>& blobs, const std::string& path) {
  constexpr int kSizePx = 800;
  Eigen::Vector2f lo(-5.f, -5.f), hi(5.f, 5.f);  // always include the vehicle at the origin
  for (Eigen::Index i = 0; i < cloud.xyz.cols(); ++i) {
    lo = lo.cwiseMin(cloud.xyz.col(i).head<2>());
    hi = hi.cwiseMax(cloud.xyz.col(i).head<2>());
  }
  const float span = std::max(hi.x() - lo.x(), hi.y() - lo.y()) * 1.05f;
  const float px_per_m = static_cast<float>(kSizePx) / span;
  const Eigen::Vector2f mid = 0.5f * (lo + hi);
  // Top view: vehicle x (forward) up the image, y (left) to the image's left.
  const auto to_px = [&](const Eigen::Vector2f& p) {
    return cv::Point(static_cast<int>(kSizePx / 2 - (p.y() - mid.y()) * px_per_m),
                     static_cast<int>(kSizePx / 2 - (p.x() - mid.x()) * px_per_m));
  };
  cv::Mat img(kSizePx, kSizePx, CV_8UC3, cv::Scalar(20, 20, 20));
  for (int i : ground.ground) {
    const cv::Point p = to_px(cloud.xyz.col(i).head<2>());
    if (p.inside(cv::Rect(0, 0, kSizePx, kSizePx))) img.at<cv::Vec3b>(p) = cv::Vec3b(90, 90, 90);
  }
  for (std::size_t b = 0; b < blobs.size(); ++b) {
    // Golden-angle hues keep neighbouring blob colours apart.
    cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar((b * 47) % 180, 220, 255)), bgr;
    cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
    const cv::Vec3b colour = bgr.at<cv::Vec3b>(0, 0);
    for (int i : blobs[b].indices) {
      const cv::Point p = to_px(cloud.xyz.col(i).head<2>());
      if (p.inside(cv::Rect(0, 0, kSizePx, kSizePx))) img.at<cv::Vec3b>(p) = colour;
    }
    const Eigen::Matrix<float, 3, 8> corners = blobs[b].box.Corners();
    const int order[4] = {0, 1, 3, 2};  // bottom face corners in ring order
    for (int k = 0; k < 4; ++k) {
      cv::line(img, to_px(corners.col(order[k]).head<2>()), to_px(corners.col(order[(k + 1) % 4]).head<2>()),
               cv::Scalar(colour[0], colour[1], colour[2]), 1, cv::LINE_AA);
    }
  }
  cv::circle(img, to_px(Eigen::Vector2f::Zero()), 4, cv::Scalar(255, 255, 255), cv::FILLED);
  if (!cv::imwrite(path, img)) Fail("cannot write top view '" + path + "'");
}

void Run(const Options& o) {
  mapping::SegmentationParams seg;
  seg.leaf_size_m = o.leaf_m;
  seg.min_blob_points = o.min_points;
  seg.max_object_extent_m = o.max_extent_m;
  seg.Validate();  // bad --leaf etc. before any file work
  mapping::GroundRemovalParams gp;
  gp.height_tolerance_m = o.ground_tolerance_m;
  gp.Validate();
  if (!(o.ground_contact_m >= 0.f) || !std::isfinite(o.ground_contact_m)) {
    Fail("--ground-contact must be a finite height >= 0 m, got " + std::to_string(o.ground_contact_m));
  }
  const objects::Atlas atlas = objects::Atlas::Load(o.atlas.empty() ? objects::Atlas::DefaultPath() : o.atlas);

  stereo::PcdLoadStats load_stats;
  const PointCloud cloud = stereo::LoadPcd(o.pcd, &load_stats);
  const mapping::GroundRemoval ground = mapping::RemoveGround(cloud, gp);
  const mapping::Segmentation s = mapping::SegmentBlobs(cloud.xyz, seg, &ground.obstacles);
  std::vector<BlobReport> blobs;
  blobs.reserve(s.blobs.size());
  for (const auto& indices : s.blobs) {
    BlobReport r;
    r.indices = indices;
    r.box = objects::StandOnGround(objects::FitVerticalBox(cloud.xyz, indices, ground.plane.normal), ground.plane,
                                   o.ground_contact_m);
    r.cls = ClassifyBlob(atlas, r.box);
    blobs.push_back(std::move(r));
  }
  if (load_stats.dropped_non_finite > 0) {
    std::fprintf(stderr, "romo: %s: %zu non-finite points dropped\n", o.pcd.c_str(), load_stats.dropped_non_finite);
  }

  if (!o.out_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(o.out_dir, ec);
    if (ec) Fail("--out: cannot create '" + o.out_dir + "': " + ec.message());
    WriteTopView(cloud, ground, blobs, o.out_dir + "/topview.png");
    for (std::size_t b = 0; b < blobs.size(); ++b) {
      char name[32];
      std::snprintf(name, sizeof(name), "/blob_%03zu.pcd", b);
      stereo::SavePcd(cloud.Select(blobs[b].indices), o.out_dir + name);
    }
  }

  const Eigen::Vector4f plane = ground.plane.Coefficients();
  if (o.json) {
    std::ostringstream js;
    js << "{\"points\": " << cloud.size() << ", \"ground\": {\"plane\": [" << Num(plane[0]) << ", "
       << Num(plane[1]) << ", " << Num(plane[2]) << ", " << Num(plane[3]) << "], \"inliers\": "
       << ground.ransac_inliers << "}, \"blobs\": [";
    for (std::size_t b = 0; b < blobs.size(); ++b) {
      const auto& r = blobs[b];
      js << (b ? ", " : "") << "{\"points\": " << r.indices.size() << ", \"center\": " << Vec(r.box.center)
         << ", \"size\": " << Vec(r.box.size) << ", \"yaw\": " << Num(r.box.yaw_rad) << ", \"class\": "
         << JsonString(r.cls) << "}";
    }
    js << "]}\n";
    std::fputs(js.str().c_str(), stdout);
    return;
  }
  std::printf("%s: %zu points, ground plane (%.4f, %.4f, %.4f, %.4f) %s, %d inliers, %zu ground points removed "
              "(%zu more too far below it to be ground)\n",
              o.pcd.c_str(), cloud.size(), plane[0], plane[1], plane[2], plane[3],
              ground.refined ? "fitted" : "prior (not enough ground to fit)", ground.ransac_inliers,
              ground.ground.size(), ground.below.size());
  std::printf("%zu blobs at %.3f m leaves (%zu occupied leaves, %zu small dropped, %zu refined)\n", blobs.size(),
              o.leaf_m, s.occupied_leaves, s.dropped_small, s.refined);
  for (std::size_t b = 0; b < blobs.size(); ++b) {
    const auto& r = blobs[b];
    std::printf("  blob %zu: %zu points, centre (%.2f, %.2f, %.2f) m, size %.2f x %.2f x %.2f m, yaw %.1f deg, %s\n", b,
                r.indices.size(), r.box.center.x(), r.box.center.y(), r.box.center.z(), r.box.size.x(),
                r.box.size.y(), r.box.size.z(), r.box.yaw_rad * 180.0 / M_PI, r.cls.c_str());
  }
  if (!o.out_dir.empty()) std::printf("wrote %s/topview.png and %zu blob PCDs\n", o.out_dir.c_str(), blobs.size());
}

ROMO_REGISTER_COMMAND([](CLI::App& root) {
  auto opts = std::make_shared<Options>();
  CLI::App* cmd = root.add_subcommand("segment", "Ground removal, blobs and boxes of a PCD cloud (vehicle frame)");
  cmd->add_option("--pcd", opts->pcd, "PCD file (vehicle frame: x forward, y left, z up, metres)")->required();
  cmd->add_option("--leaf", opts->leaf_m, "octree leaf size in metres (> 0)")->capture_default_str();
  cmd->add_option("--min-points", opts->min_points, "smallest blob kept, points")->capture_default_str();
  cmd->add_option("--max-extent", opts->max_extent_m,
                  "blobs with a larger diagonal (m) are re-clustered at half the leaf; 0 = never")
      ->capture_default_str();
  cmd->add_option("--ground-tolerance", opts->ground_tolerance_m,
                  "points up to this height above the ground plane are removed, metres")
      ->capture_default_str();
  cmd->add_option("--ground-contact", opts->ground_contact_m,
                  "blobs whose bottom is at most this far above the ground plane reach down to it (ground "
                  "removal took their lowest points with the ground), metres; 0 = as measured")
      ->capture_default_str();
  cmd->add_option("--atlas", opts->atlas,
                  "Atlas YAML with the classes' size priors (default config/atlas.yaml or $ROMO_ATLAS)");
  cmd->add_flag("--json", opts->json, "print one JSON object");
  cmd->add_option("--out", opts->out_dir, "folder for topview.png and blob_NNN.pcd");
  cmd->callback([opts] { Run(*opts); });
});

}  // namespace
}  // namespace romo::tools
