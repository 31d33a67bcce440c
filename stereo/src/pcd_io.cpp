// SavePcd through PCL I/O: the only translation unit of the stereo module that includes PCL (slow
// to compile). Reading is pcd_reader.cpp's own.
#include "romo/stereo/pcd_io.hpp"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include <pcl/PCLPointCloud2.h>
#include <pcl/exceptions.h>
#include <pcl/io/pcd_io.h>

#include "romo/core/check.hpp"

namespace romo::stereo {
namespace {

void AddField(pcl::PCLPointCloud2* cloud, const char* name, std::uint32_t offset) {
  pcl::PCLPointField f;
  f.name = name;
  f.offset = offset;
  f.datatype = pcl::PCLPointField::FLOAT32;
  f.count = 1;
  cloud->fields.push_back(f);
}

}  // namespace

void SavePcd(const PointCloud& cloud, const std::string& path) {
  if (!cloud.IsConsistent()) {
    Fail("SavePcd('" + path + "'): point cloud channels disagree in size (" +
         std::to_string(cloud.size()) + " points, " + std::to_string(cloud.sigma_z_m.size()) +
         " sigma_z, " + std::to_string(cloud.intensity.size()) + " intensity)");
  }
  constexpr std::uint32_t kFields = 5;  // x y z intensity sigma_z
  pcl::PCLPointCloud2 out;
  AddField(&out, "x", 0);
  AddField(&out, "y", 4);
  AddField(&out, "z", 8);
  AddField(&out, "intensity", 12);
  AddField(&out, "sigma_z", 16);
  out.point_step = kFields * sizeof(float);
  out.width = static_cast<std::uint32_t>(cloud.size());
  out.height = 1;
  out.row_step = out.point_step * out.width;
  out.is_dense = true;
  out.is_bigendian = false;
  out.data.resize(static_cast<std::size_t>(out.row_step));
  auto* dst = reinterpret_cast<float*>(out.data.data());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const auto c = static_cast<Eigen::Index>(i);
    float values[kFields] = {cloud.xyz(0, c), cloud.xyz(1, c), cloud.xyz(2, c), cloud.intensity[i],
                             cloud.sigma_z_m[i]};
    std::memcpy(dst + i * kFields, values, sizeof(values));
    if (!std::isfinite(values[0]) || !std::isfinite(values[1]) || !std::isfinite(values[2])) {
      out.is_dense = false;
    }
  }

  const std::string tmp = path + ".tmp";
  int rc = -1;
  try {
    rc = pcl::io::savePCDFile(tmp, out, Eigen::Vector4f::Zero(), Eigen::Quaternionf::Identity(),
                              /*binary_mode=*/true);
  } catch (const pcl::PCLException& e) {
    std::remove(tmp.c_str());
    Fail("cannot write PCD file '" + path + "': " + e.what());
  }
  if (rc != 0) {
    std::remove(tmp.c_str());
    Fail("cannot write PCD file '" + path + "' (PCL error " + std::to_string(rc) + ")");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    Fail("cannot write PCD file '" + path + "': " + ec.message());
  }
}

}  // namespace romo::stereo
