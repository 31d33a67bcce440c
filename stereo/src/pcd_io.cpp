// The only translation unit of the stereo module that includes PCL (slow to compile).
#include "romo/stereo/pcd_io.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include <pcl/PCLPointCloud2.h>
#include <pcl/exceptions.h>
#include <pcl/io/pcd_io.h>

#include "romo/core/check.hpp"

namespace romo::stereo {
namespace {

const pcl::PCLPointField* FindField(const pcl::PCLPointCloud2& cloud, const char* name) {
  for (const auto& f : cloud.fields) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

int DatatypeSize(std::uint8_t datatype) {
  switch (datatype) {
    case pcl::PCLPointField::INT8:
    case pcl::PCLPointField::UINT8: return 1;
    case pcl::PCLPointField::INT16:
    case pcl::PCLPointField::UINT16: return 2;
    case pcl::PCLPointField::INT32:
    case pcl::PCLPointField::UINT32:
    case pcl::PCLPointField::FLOAT32: return 4;
    case pcl::PCLPointField::FLOAT64: return 8;
    default: return 0;
  }
}

template <typename T>
float Read(const std::uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return static_cast<float>(v);
}

float ReadAsFloat(const std::uint8_t* p, std::uint8_t datatype) {
  switch (datatype) {
    case pcl::PCLPointField::INT8: return Read<std::int8_t>(p);
    case pcl::PCLPointField::UINT8: return Read<std::uint8_t>(p);
    case pcl::PCLPointField::INT16: return Read<std::int16_t>(p);
    case pcl::PCLPointField::UINT16: return Read<std::uint16_t>(p);
    case pcl::PCLPointField::INT32: return Read<std::int32_t>(p);
    case pcl::PCLPointField::UINT32: return Read<std::uint32_t>(p);
    case pcl::PCLPointField::FLOAT32: return Read<float>(p);
    case pcl::PCLPointField::FLOAT64: return Read<double>(p);
    default: ROMO_DEMAND(false);
  }
  return 0.f;
}

// A field checked against the point layout, so the per-point loop needs no bounds checks.
const pcl::PCLPointField* CheckedField(const pcl::PCLPointCloud2& cloud, const char* name,
                                       const std::string& path, bool required) {
  const pcl::PCLPointField* f = FindField(cloud, name);
  if (f == nullptr) {
    if (required) Fail("PCD file '" + path + "': no field '" + name + "'");
    return nullptr;
  }
  const int size = DatatypeSize(f->datatype);
  if (size == 0) {
    Fail("PCD file '" + path + "': field '" + name + "' has unsupported datatype " +
         std::to_string(f->datatype));
  }
  if (f->offset + static_cast<std::uint32_t>(size) > cloud.point_step) {
    Fail("PCD file '" + path + "': field '" + name + "' offset " + std::to_string(f->offset) +
         " lies outside the point step " + std::to_string(cloud.point_step));
  }
  return f;
}

void AddField(pcl::PCLPointCloud2* cloud, const char* name, std::uint32_t offset) {
  pcl::PCLPointField f;
  f.name = name;
  f.offset = offset;
  f.datatype = pcl::PCLPointField::FLOAT32;
  f.count = 1;
  cloud->fields.push_back(f);
}

// PCL's readHeader allocates width x height x point_step bytes before it reads any data, so a
// header claiming a 10^14-byte field (or 10^12 points) in a 200-byte file exhausts memory. The
// sizes are checked against what the file can hold first: binary data is stored as is, ASCII
// needs at least 2 bytes a value, LZF expands at most ~100 times (its longest back reference).
void CheckPcdHeaderSizes(const std::string& path, std::uintmax_t file_size) {
  std::ifstream in(path, std::ios::binary);
  if (!in) Fail("PCD file '" + path + "' cannot be opened");
  std::vector<unsigned long long> sizes, counts;
  unsigned long long width = 1, height = 1, points_line = 0;
  std::string data_kind, line;
  int line_number = 0;
  auto numbers = [&](std::istringstream& fields, const std::string& key) {
    std::vector<unsigned long long> out;
    std::string token;
    while (fields >> token) {
      if (token.find_first_not_of("0123456789") != std::string::npos || token.size() > 12) {
        Fail("PCD file '" + path + "' line " + std::to_string(line_number) + ": " + key + " value '" +
             token.substr(0, 24) + "' is not a count of a sane size");
      }
      out.push_back(std::stoull(token));
    }
    return out;
  };
  while (data_kind.empty() && in.tellg() < (1 << 20) && std::getline(in, line)) {
    ++line_number;
    std::istringstream fields(line);
    std::string key;
    fields >> key;
    if (key == "SIZE") {
      sizes = numbers(fields, key);
      for (unsigned long long size : sizes) {
        if (size != 1 && size != 2 && size != 4 && size != 8) {
          Fail("PCD file '" + path + "' line " + std::to_string(line_number) + ": SIZE " + std::to_string(size) +
               " is not 1, 2, 4 or 8 bytes");
        }
      }
    } else if (key == "COUNT") {
      counts = numbers(fields, key);
    } else if (key == "WIDTH" || key == "HEIGHT") {
      const auto v = numbers(fields, key);
      if (v.size() == 1) (key == "WIDTH" ? width : height) = v[0];
    } else if (key == "POINTS") {
      const auto v = numbers(fields, key);
      if (v.size() == 1) points_line = v[0];
    } else if (key == "DATA") {
      fields >> data_kind;
      if (data_kind.empty()) data_kind = "?";
    }
  }
  if (data_kind.empty()) return;  // no DATA line where PCL would look: it reports that itself
  if (counts.empty()) counts.assign(sizes.size(), 1);
  unsigned long long point_step = 0, values = 0;
  for (std::size_t k = 0; k < sizes.size() && k < counts.size(); ++k) {
    point_step += sizes[k] * counts[k];  // each factor < 10^12: no overflow
    values += counts[k];
  }
  const double points = std::max(static_cast<double>(width) * static_cast<double>(height),
                                 static_cast<double>(points_line));
  const double claimed = data_kind == "ascii" ? points * static_cast<double>(values) * 2.0
                                              : points * static_cast<double>(point_step);
  const double room = data_kind == "binary_compressed" ? 100.0 * static_cast<double>(file_size) + 4096.0
                                                       : static_cast<double>(file_size);
  if (claimed > room) {
    std::ostringstream msg;
    msg << "PCD file '" << path << "' header claims " << width << " x " << height << " points of " << point_step
        << " bytes (" << data_kind << ", at least " << claimed << " bytes) but the file has " << file_size
        << " bytes: corrupt WIDTH, HEIGHT, SIZE or COUNT";
    Fail(msg.str());
  }
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

PointCloud LoadPcd(const std::string& path, PcdLoadStats* stats) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    Fail("PCD file '" + path + "' does not exist or is not a regular file");
  }
  // PCL 1.13 crashes on some malformed files (no FIELDS, short binary data), so the header and
  // the data size are checked here before PCL reads the points.
  const std::uintmax_t file_size = std::filesystem::file_size(path, ec);
  if (ec) Fail("PCD file '" + path + "': cannot read its size: " + ec.message());
  CheckPcdHeaderSizes(path, file_size);
  pcl::PCLPointCloud2 header;
  Eigen::Vector4f origin;
  Eigen::Quaternionf orientation;
  int version = 0;
  int data_type = 0;
  unsigned int data_idx = 0;
  pcl::PCDReader reader;
  int rc = -1;
  try {
    rc = reader.readHeader(path, header, origin, orientation, version, data_type, data_idx);
  } catch (const pcl::PCLException& e) {
    Fail("PCD file '" + path + "' has a corrupt header: " + e.what());
  } catch (const std::exception& e) {  // PCL 1.13 also throws std::out_of_range (vector::at)
    Fail("PCD file '" + path + "' has a corrupt header: " + e.what());
  }
  if (rc < 0) Fail("PCD file '" + path + "' has a corrupt header (PCL error " + std::to_string(rc) + ")");
  if (header.fields.empty()) Fail("PCD file '" + path + "' has no FIELDS: not a PCD file?");
  for (const char* name : {"x", "y", "z"}) CheckedField(header, name, path, true);
  const std::size_t n = static_cast<std::size_t>(header.width) * header.height;
  if (n == 0) {
    if (stats != nullptr) *stats = PcdLoadStats{};
    return PointCloud{};
  }
  const std::uintmax_t data_bytes = static_cast<std::uintmax_t>(n) * header.point_step;
  if (data_type == 1 && file_size < data_idx + data_bytes) {
    Fail("PCD file '" + path + "' is truncated: binary data of " + std::to_string(n) +
         " points needs " + std::to_string(data_bytes) + " bytes after the header, found " +
         std::to_string(file_size > data_idx ? file_size - data_idx : 0));
  }
  if (data_type == 2) {
    // binary_compressed: two uint32 (compressed size, uncompressed size) then the LZF block.
    std::uint32_t sizes[2] = {0, 0};
    std::FILE* f = std::fopen(path.c_str(), "rb");
    const bool got = f != nullptr && std::fseek(f, static_cast<long>(data_idx), SEEK_SET) == 0 &&
                     std::fread(sizes, sizeof(sizes), 1, f) == 1;
    if (f != nullptr) std::fclose(f);
    if (!got || file_size < data_idx + sizeof(sizes) + sizes[0] || sizes[1] != data_bytes) {
      Fail("PCD file '" + path + "' is truncated or corrupt: compressed block of " +
           std::to_string(sizes[0]) + " bytes (" + std::to_string(sizes[1]) +
           " uncompressed, expected " + std::to_string(data_bytes) + ") in a file of " +
           std::to_string(file_size) + " bytes");
    }
  }

  pcl::PCLPointCloud2 in;
  try {
    rc = reader.read(path, in);
  } catch (const pcl::PCLException& e) {
    Fail("PCD file '" + path + "' is corrupt: " + e.what());
  } catch (const std::exception& e) {  // as for the header
    Fail("PCD file '" + path + "' is corrupt: " + e.what());
  }
  if (rc < 0) Fail("PCD file '" + path + "' is corrupt or unreadable (PCL error " + std::to_string(rc) + ")");
  if (static_cast<std::size_t>(in.width) * in.height != n || in.data.size() < data_bytes) {
    Fail("PCD file '" + path + "' is truncated: " + std::to_string(n) + " points need " +
         std::to_string(data_bytes) + " bytes, found " + std::to_string(in.data.size()));
  }
  const pcl::PCLPointField* fx = CheckedField(in, "x", path, true);
  const pcl::PCLPointField* fy = CheckedField(in, "y", path, true);
  const pcl::PCLPointField* fz = CheckedField(in, "z", path, true);
  const pcl::PCLPointField* fi = CheckedField(in, "intensity", path, false);
  const pcl::PCLPointField* fs = CheckedField(in, "sigma_z", path, false);

  PointCloud cloud;
  cloud.Resize(n);
  std::size_t kept = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t* p = in.data.data() + i * in.point_step;
    const float x = ReadAsFloat(p + fx->offset, fx->datatype);
    const float y = ReadAsFloat(p + fy->offset, fy->datatype);
    const float z = ReadAsFloat(p + fz->offset, fz->datatype);
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) continue;
    const auto c = static_cast<Eigen::Index>(kept);
    cloud.xyz(0, c) = x;
    cloud.xyz(1, c) = y;
    cloud.xyz(2, c) = z;
    cloud.intensity[kept] = fi ? ReadAsFloat(p + fi->offset, fi->datatype) : 0.f;
    cloud.sigma_z_m[kept] = fs ? ReadAsFloat(p + fs->offset, fs->datatype) : 0.f;
    ++kept;
  }
  cloud.Resize(kept);
  if (stats != nullptr) {
    stats->points_in_file = n;
    stats->dropped_non_finite = n - kept;
    stats->had_intensity = fi != nullptr;
    stats->had_sigma_z = fs != nullptr;
  }
  return cloud;
}

}  // namespace romo::stereo
