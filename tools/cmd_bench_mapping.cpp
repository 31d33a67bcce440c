// `romo bench mapping`: romo's DFS segmentation, octree, ground removal and fusion against the
// named peers (PCL EuclideanClusterExtraction, OctoMap, PCL SACSegmentation) in the same run.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "cli/command_registry.hpp"
#include "cli/progress.hpp"
#include "romo/core/check.hpp"
#include "romo/drivers/calibration.hpp"
#include "romo/mapping/fusion.hpp"
#include "romo/mapping/ground_removal.hpp"
#include "romo/mapping/octree.hpp"
#include "romo/mapping/peers.hpp"
#include "romo/mapping/segmentation.hpp"
#include "romo/mapping/synthetic_scene.hpp"
#include "romo/stereo/pcd_io.hpp"

namespace romo::tools {
namespace {

struct Options {
  bool json = false;
  int repeats = 5;
  std::string data_dir;
  bool skip_10m = false;
  std::vector<std::string> only;  // case groups to run; empty = all

  bool Runs(const std::string& group) const {
    return only.empty() || std::find(only.begin(), only.end(), group) != only.end();
  }
};

struct Case {
  std::string name;
  std::size_t points = 0;
  double romo_ms = 0;
  std::string peer;                    // "" when there is no peer for this case
  std::optional<double> peer_ms;
  std::vector<std::pair<std::string, double>> extra;  // figures shown beside the times
  std::string note;                                   // how the input was made, where it matters
};

double MedianMs(int repeats, const std::function<void()>& work) {
  std::vector<double> ms;
  for (int r = 0; r < repeats; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    work();
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::nth_element(ms.begin(), ms.begin() + static_cast<long>(ms.size() / 2), ms.end());
  return ms[ms.size() / 2];
}

/// A /proc/self/status figure (@p key "VmHWM:" peak resident set, "VmRSS:" resident set) in MiB;
/// 0 when /proc is unavailable.
double StatusMb(const std::string& key) {
  std::ifstream status("/proc/self/status");
  std::string k;
  while (status >> k) {
    if (k == key) {
      double kb = 0;
      status >> kb;
      return kb / 1024.0;
    }
    status.ignore(4096, '\n');
  }
  return 0;
}

/// Resets VmHWM to the current resident set (Linux clear_refs, value 5), so the next VmHWM is
/// the peak since now.
void ResetPeakRss() {
  std::ofstream clear("/proc/self/clear_refs");
  clear << "5";
}

/// Hands the heap's free pages back to the system, so that what a case allocates shows as RSS
/// growth instead of reusing what earlier cases freed (still resident).
void TrimHeap() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}

std::string DataDir(const Options& o) {
  if (!o.data_dir.empty()) return o.data_dir;
  if (const char* env = std::getenv("ROMO_SHARED_DATA")) return env;
  return "../shared/data";
}

void SegmentationCases(const Options& o, std::vector<Case>* cases, Progress* progress, int* step) {
  constexpr float kToleranceM = 0.1f;
  for (std::size_t n : {std::size_t{200000}, std::size_t{400000}}) {
    const mapping::SyntheticScene scene = mapping::MakeParkingScene(n, 11);
    mapping::SegmentationParams params;
    params.leaf_size_m = kToleranceM;
    mapping::Segmentation ours;
    std::vector<std::vector<int>> theirs;
    Case c;
    c.name = "dfs_segmentation_" + std::to_string(n / 1000) + "k";
    c.points = scene.cloud.size();
    // Both sides from cloud to index lists (ascending), the same min size; medians of repeats.
    c.romo_ms = MedianMs(o.repeats, [&] { ours = mapping::SegmentBlobs(scene.cloud.xyz, params); });
    // The octree-hash labelling (the dense grid's reference and fallback) for comparison.
    mapping::SegmentationParams octree_params = params;
    octree_params.dense_grid_max_bytes = 0;
    const double octree_ms = MedianMs(std::min(o.repeats, 3), [&] { mapping::SegmentBlobs(scene.cloud.xyz, octree_params); });
    c.peer = "pcl::EuclideanClusterExtraction";
    c.peer_ms = MedianMs(std::min(o.repeats, 3), [&] {
      theirs = mapping::peers::PclEuclideanClusters(scene.cloud.xyz, kToleranceM, params.min_blob_points, 1 << 30);
    });
    const auto labels = [&](const std::vector<std::vector<int>>& blobs) {
      std::vector<int> l(scene.cloud.size(), -1);
      for (std::size_t b = 0; b < blobs.size(); ++b)
        for (int i : blobs[b]) l[static_cast<std::size_t>(i)] = static_cast<int>(b);
      return l;
    };
    c.extra = {{"leaf_m", kToleranceM},
               {"romo_blobs", static_cast<double>(ours.blobs.size())},
               {"pcl_clusters", static_cast<double>(theirs.size())},
               {"adjusted_rand_index", mapping::peers::AdjustedRandIndex(labels(ours.blobs), labels(theirs))},
               {"occupied_leaves", static_cast<double>(ours.occupied_leaves)},
               {"romo_octree_path_ms", octree_ms}};
    cases->push_back(c);
    progress->Update(++*step, c.name);
  }
}

/// Table 5.1's point count.
constexpr Eigen::Index kTable51Points = 2292618;

struct CollatedCloud {
  Eigen::Matrix3Xf xyz;
  int views = 0;           // poses of office1.pcd used
  Eigen::Index frame = 0;  // points per view
};

/// Table 5.1's setting: 2.29 M points of an indoor scene collated from overlapping views.
/// office1.pcd (a real Kinect frame) seen from as many poses (panning 8 deg and stepping 0.1 m
/// apart) as it takes to reach Table 5.1's count, the last view cut to land on it exactly.
CollatedCloud CollatedIndoorCloud(const Options& o) {
  const std::string path = DataDir(o) + "/pcl/office1.pcd";
  const PointCloud frame = stereo::LoadPcd(path);
  if (frame.empty()) Fail(path + ": no finite points");
  CollatedCloud out;
  out.frame = frame.xyz.cols();
  out.views = static_cast<int>((kTable51Points + out.frame - 1) / out.frame);
  out.xyz.resize(3, kTable51Points);
  for (int k = 0; k < out.views; ++k) {
    Eigen::Isometry3f T = Eigen::Isometry3f::Identity();
    T.linear() = Eigen::AngleAxisf(0.14f * static_cast<float>(k), Eigen::Vector3f::UnitY()).toRotationMatrix();
    T.translation() = Eigen::Vector3f(0.1f * static_cast<float>(k), 0.f, 0.f);
    const Eigen::Index begin = k * out.frame;
    const Eigen::Index count = std::min(out.frame, kTable51Points - begin);
    out.xyz.middleCols(begin, count) = T * frame.xyz.leftCols(count);
  }
  return out;
}

void OctreeCases(const Options& o, std::vector<Case>* cases, Progress* progress, int* step) {
  const CollatedCloud cloud = CollatedIndoorCloud(o);
  const Eigen::Matrix3Xf& xyz = cloud.xyz;
  for (int leaf_mm : {1, 2, 5, 10, 20, 40, 80}) {
    const float leaf_m = static_cast<float>(leaf_mm) * 1e-3f;
    mapping::VoxelOctree tree(leaf_m);
    Case c;
    c.name = "octree_build_" + std::to_string(leaf_mm) + "mm";
    c.points = static_cast<std::size_t>(xyz.cols());
    c.romo_ms = MedianMs(std::max(1, o.repeats / 2), [&] { tree.Build(xyz); });
    const mapping::peers::OctomapFigures peer = mapping::peers::OctomapBuild(xyz, leaf_m);
    c.note = "office1.pcd from " + std::to_string(cloud.views) + " poses (" + std::to_string(cloud.frame) +
             " points each), last view cut: " + std::to_string(xyz.cols()) + " points as in Table 5.1";
    c.peer = "octomap::OcTree";
    c.peer_ms = peer.build_ms;
    c.extra = {{"leaf_mm", leaf_mm},
               {"office1_views", cloud.views},
               {"office1_points_per_view", static_cast<double>(cloud.frame)},
               {"nodes", static_cast<double>(tree.node_count())},
               {"leaves", static_cast<double>(tree.leaf_count())},
               {"root_size_m", tree.root_size_m()},
               {"memory_mb", static_cast<double>(tree.MemoryBytes()) / (1 << 20)},
               {"octomap_nodes", static_cast<double>(peer.nodes)},
               {"octomap_leaves", static_cast<double>(peer.leaves)},
               {"octomap_root_size_m", peer.root_size_m},
               {"octomap_memory_mb", static_cast<double>(peer.memory_bytes) / (1 << 20)}};
    cases->push_back(c);
    progress->Update(++*step, c.name);
  }
}

/// A 360-degree frame: the parking scene with ground, cut into the six sample rigs' sectors (5 deg
/// overlaps seen twice), expressed in each rig's frame at its own capture instant.
std::vector<mapping::RigCloud> Rigs360(const mapping::VehicleMotion& motion) {
  const drivers::Calibration calib = drivers::Calibration::Load(drivers::SampleCalibrationPath());
  const mapping::SyntheticScene scene = mapping::MakeParkingScene(300000, 5, 20.f);
  constexpr float kPi = 3.14159265f, kOverlapRad = 5.f * kPi / 180.f;
  std::vector<mapping::RigCloud> rigs;
  for (const auto& rc : calib.rigs) {
    mapping::RigCloud rig;
    rig.rig_id = rc.rig_id;
    rig.stamp_ns = motion.reference_stamp_ns - 5'000'000LL * rc.rig_id;  // staggered triggers
    rig.T_vehicle_rig = rc.T_vehicle_rig.cast<float>();
    const Eigen::Vector3f axis = rig.T_vehicle_rig.linear().col(2);  // optical axis in the vehicle
    const float rig_yaw = std::atan2(axis.y(), axis.x());
    const Eigen::Isometry3f T_rig_ref =
        (mapping::VehicleDisplacement(motion, rig.stamp_ns) * rig.T_vehicle_rig).inverse();
    std::vector<float> buf;
    std::vector<float> sigma;
    for (Eigen::Index i = 0; i < scene.cloud.xyz.cols(); ++i) {
      const Eigen::Vector3f p = scene.cloud.xyz.col(i);
      const float off = std::abs(std::remainder(std::atan2(p.y(), p.x()) - rig_yaw, 2.f * kPi));
      if (off > kPi / 6.f + kOverlapRad) continue;
      const Eigen::Vector3f q = T_rig_ref * p;
      buf.insert(buf.end(), {q.x(), q.y(), q.z()});
      // Eq. 2.3 with b f = 0.25 m * 400 px and 0.5 px disparity noise.
      sigma.push_back(q.z() * q.z() / 100.f * 0.5f);
    }
    rig.cloud.Resize(sigma.size());
    rig.cloud.xyz = Eigen::Map<Eigen::Matrix3Xf>(buf.data(), 3, static_cast<Eigen::Index>(sigma.size()));
    rig.cloud.sigma_z_m = sigma;
    rigs.push_back(std::move(rig));
  }
  return rigs;
}

void FrameCases(const Options& o, std::vector<Case>* cases, Progress* progress, int* step) {
  const mapping::VehicleMotion motion{3.f, 0.2f, 10'000'000'000LL};
  const std::vector<mapping::RigCloud> rigs = Rigs360(motion);
  std::size_t input = 0;
  for (const auto& r : rigs) input += r.cloud.size();
  PointCloud fused;
  mapping::FusionStats stats;
  Case f;
  f.name = "fusion_360";
  f.points = input;
  f.romo_ms = MedianMs(o.repeats, [&] { fused = mapping::FuseRigClouds(rigs, motion, mapping::FusionParams{}, &stats); });
  f.extra = {{"fused_points", static_cast<double>(fused.size())}, {"thinned", static_cast<double>(stats.thinned)}};
  cases->push_back(f);
  progress->Update(++*step, f.name);

  mapping::GroundRemovalParams gp;
  mapping::GroundRemoval g;
  Case c;
  c.name = "ground_removal_360";
  c.points = fused.size();
  c.romo_ms = MedianMs(o.repeats, [&] { g = mapping::RemoveGround(fused, gp); });
  c.peer = "pcl::SACSegmentation(plane)";
  c.peer_ms = MedianMs(1, [&] {
    mapping::peers::PclRansacPlane(fused.xyz, gp.ransac.inlier_threshold_m, gp.ransac.max_iterations);
  });
  c.extra = {{"ground_points", static_cast<double>(g.ground.size())},
             {"ransac_iterations", static_cast<double>(g.ransac_iterations)},
             {"plane_d", g.plane.d}};
  cases->push_back(c);
  progress->Update(++*step, c.name);
}

void TenMillionCase(std::vector<Case>* cases, Progress* progress, int* step) {
  // The case's own memory: the peak over the resident set just before it. The process's peak
  // would include what earlier cases left resident (after the octree cases, ~1 GB of freed
  // OctoMap nodes the 10 M case then fits in) and the binary itself (~110 MB).
  TrimHeap();
  const double before = StatusMb("VmRSS:");
  ResetPeakRss();
  const mapping::SyntheticScene scene = mapping::MakeParkingScene(10'000'000, 3, 20.f);
  const double build_peak = StatusMb("VmHWM:");
  TrimHeap();
  const double with_cloud = StatusMb("VmRSS:");
  ResetPeakRss();
  Case c;
  c.name = "ground_and_segmentation_10M";
  c.points = scene.cloud.size();
  std::size_t blobs = 0;
  c.romo_ms = MedianMs(1, [&] {
    const mapping::GroundRemoval g = mapping::RemoveGround(scene.cloud, mapping::GroundRemovalParams{});
    mapping::SegmentationParams params;
    params.leaf_size_m = 0.1f;
    blobs = mapping::SegmentBlobs(scene.cloud.xyz, params, &g.obstacles).blobs.size();
  });
  const double stages_peak = StatusMb("VmHWM:");
  const double cloud_mb = static_cast<double>(sizeof(float) * (static_cast<std::size_t>(scene.cloud.xyz.size()) +
                                                               scene.cloud.sigma_z_m.size() +
                                                               scene.cloud.intensity.size())) /
                         (1 << 20);
  c.extra = {{"case_peak_rss_mb", std::max(build_peak, stages_peak) - before},
             {"stages_peak_rss_mb", stages_peak - with_cloud},
             {"cloud_mb", cloud_mb},
             {"rss_before_mb", before},
             {"process_peak_rss_mb", std::max(build_peak, stages_peak)},
             {"blobs", static_cast<double>(blobs)}};
  c.note = "case_peak_rss_mb: building the cloud and both stages, over the RSS before the case; "
           "stages_peak_rss_mb: ground removal and segmentation over the RSS with the cloud built";
  cases->push_back(c);
  progress->Update(++*step, c.name);
}

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return buf;
}

void Run(const Options& o) {
  if (o.repeats < 1) Fail("--repeats must be >= 1, got " + std::to_string(o.repeats));
  std::vector<Case> cases;
  for (const std::string& g : o.only) {
    if (g != "segmentation" && g != "octree" && g != "frame" && g != "10m") {
      Fail("--only: unknown case group '" + g + "' (segmentation, octree, frame, 10m)");
    }
  }
  const bool ten_m = !o.skip_10m && o.Runs("10m");
  const int steps = (o.Runs("segmentation") ? 2 : 0) + (o.Runs("octree") ? 7 : 0) + (o.Runs("frame") ? 2 : 0) + ten_m;
  int step = 0;
  Progress progress("bench mapping", steps);
  if (o.Runs("segmentation")) SegmentationCases(o, &cases, &progress, &step);
  if (o.Runs("octree")) OctreeCases(o, &cases, &progress, &step);
  if (o.Runs("frame")) FrameCases(o, &cases, &progress, &step);
  if (ten_m) TenMillionCase(&cases, &progress, &step);
  progress.Finish();

  if (o.json) {
    std::string js = "{\"cases\": [";
    for (std::size_t i = 0; i < cases.size(); ++i) {
      const Case& c = cases[i];
      const bool pcl = c.peer.rfind("pcl::", 0) == 0;
      js += std::string(i ? ", " : "") + "{\"name\": \"" + c.name + "\", \"points\": " + std::to_string(c.points) +
            ", \"romo_ms\": " + Num(c.romo_ms) + ", \"pcl_ms\": " + (pcl && c.peer_ms ? Num(*c.peer_ms) : "null") +
            ", \"peer\": " + (c.peer.empty() ? "null" : "\"" + c.peer + "\"") +
            ", \"peer_ms\": " + (c.peer_ms ? Num(*c.peer_ms) : "null") +
            ", \"speedup\": " + (c.peer_ms ? Num(*c.peer_ms / c.romo_ms) : "null");
      for (const auto& [k, v] : c.extra) js += ", \"" + k + "\": " + Num(v);
      if (!c.note.empty()) js += ", \"note\": \"" + c.note + "\"";
      js += "}";
    }
    js += "]}\n";
    std::fputs(js.c_str(), stdout);
    return;
  }
  std::printf("%-30s %9s %10s %10s %8s  %s\n", "case", "points", "romo_ms", "peer_ms", "speedup", "peer / figures");
  for (const Case& c : cases) {
    std::printf("%-30s %9zu %10.2f %10s %8s  %s\n", c.name.c_str(), c.points, c.romo_ms,
                c.peer_ms ? Num(*c.peer_ms).c_str() : "-", c.peer_ms ? (Num(*c.peer_ms / c.romo_ms) + "x").c_str() : "-",
                c.peer.empty() ? "" : c.peer.c_str());
    std::string figures = "    ";
    for (const auto& [k, v] : c.extra) figures += k + "=" + Num(v) + " ";
    std::printf("%s\n", figures.c_str());
    if (!c.note.empty()) std::printf("    (%s)\n", c.note.c_str());
  }
}

ROMO_REGISTER_COMMAND([](CLI::App& root) {
  auto opts = std::make_shared<Options>();
  CLI::App& bench = CommandGroup(root, "bench", "Benchmarks against named baselines");
  CLI::App* cmd = bench.add_subcommand("mapping", "DFS segmentation vs PCL, octree vs OctoMap, ground removal, 10 M points");
  cmd->add_flag("--json", opts->json, "print {\"cases\": [...]} as JSON");
  cmd->add_option("--repeats", opts->repeats, "runs per romo timing (median)")->capture_default_str();
  cmd->add_option("--data", opts->data_dir, "shared data folder (default $ROMO_SHARED_DATA or ../shared/data)");
  cmd->add_flag("--skip-10m", opts->skip_10m, "leave out the 10 M point memory case");
  cmd->add_option("--only", opts->only, "run only these case groups: segmentation, octree, frame, 10m");
  cmd->callback([opts] { Run(*opts); });
});

}  // namespace
}  // namespace romo::tools
