// kinect:// through the real libfreenect. No Kinect is attached to the test machines, so the
// no-device path is what runs here; recorded sessions replay through fakenect (same code).
#include <string>

#include <gtest/gtest.h>

#include "romo/core/check.hpp"
#include "romo/drivers/frame_source.hpp"
#include "test_support.hpp"

namespace romo::drivers {
namespace {

std::string ErrorOf(const std::string& uri) {
  try {
    OpenSource(uri);
  } catch (const romo::Error& e) {
    return e.what();
  }
  return "no error";
}

TEST(KinectSourceTest, NoDeviceGivesClearError) {
  EXPECT_NE(ErrorOf("kinect://0").find("no Kinect found at index 0"), std::string::npos)
      << ErrorOf("kinect://0");
  EXPECT_NE(ErrorOf("kinect://3").find("no Kinect found at index 3"), std::string::npos);
}

TEST(KinectSourceTest, BadIndexOrOptionsAreRejected) {
  EXPECT_NE(ErrorOf("kinect://front").find("Kinect index 'front' must be a number"), std::string::npos);
  EXPECT_NE(ErrorOf("kinect://-1").find("must be a number 0-63"), std::string::npos);
  EXPECT_NE(ErrorOf("kinect://0?fps=30").find("takes no options"), std::string::npos);
}

}  // namespace
}  // namespace romo::drivers
