#pragma once
/// PCD import/export of romo::PointCloud, for inspection and test data: written through PCL I/O,
/// read by a reader of our own that checks every size before using it (PCL's trusts its input).
/// Fields written: x y z intensity sigma_z (float32, binary). Fields read: x y z (required),
/// intensity and sigma_z when present (otherwise 0), any numeric PCD type.
#include <cstddef>
#include <string>

#include "romo/core/point_cloud.hpp"

namespace romo::stereo {

/// What LoadPcd found in a file besides the points it returns.
struct PcdLoadStats {
  std::size_t points_in_file = 0;    ///< width * height as stored
  std::size_t dropped_non_finite = 0;  ///< points with a NaN/inf coordinate, not returned
  bool had_intensity = false;        ///< an "intensity" field was present
  bool had_sigma_z = false;          ///< a "sigma_z" field was present
};

/// Writes @p cloud to @p path as a binary PCD (written to a temporary file, then renamed, so a
/// crash never leaves a half-written file under @p path).
/// @throws romo::Error naming the file when the cloud is inconsistent or the file cannot be written.
void SavePcd(const PointCloud& cloud, const std::string& path);

/// Reads a PCD file (ascii, binary or binary_compressed). Points with a non-finite coordinate are
/// dropped and counted in @p stats (optional).
/// @throws romo::Error naming the file when it is missing, unreadable, corrupt or has no x/y/z.
PointCloud LoadPcd(const std::string& path, PcdLoadStats* stats = nullptr);

}  // namespace romo::stereo
