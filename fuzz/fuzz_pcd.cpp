// PCD import (stereo/pcd_io.hpp, through PCL's reader) on a file holding the input bytes.
#include "harness.hpp"
#include "romo/stereo/pcd_io.hpp"

using romo::fuzz::ExpectOnlyRomoError;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static romo::fuzz::ScratchFile file(".pcd");
  const std::string& path = file.Write(data, size);
  ExpectOnlyRomoError([&] {
    romo::stereo::PcdLoadStats stats;
    const auto cloud = romo::stereo::LoadPcd(path, &stats);
    ROMO_DEMAND(cloud.IsConsistent());
  });
  return 0;
}
