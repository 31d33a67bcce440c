#include "romo/stereo/pcd_io.hpp"

#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include "romo/core/check.hpp"
#include "test_support.hpp"

namespace romo::stereo {
namespace {

// Binary PCD stores float32 exactly: a round trip must be bit-exact.
constexpr float kExactM = 0.f;

PointCloud MakeCloud() {
  PointCloud c;
  c.PushBack({1.5f, -2.25f, 10.f}, 0.125f, 200.f);
  c.PushBack({-0.001f, 3.f, 42.5f}, 1.75f, 0.f);
  c.PushBack({7.f, 8.f, -9.f}, 0.f, 255.f);
  return c;
}

TEST(PcdIoTest, RoundTripKeepsEveryChannel) {
  test::ScratchDir dir;
  const PointCloud in = MakeCloud();
  SavePcd(in, dir / "c.pcd");
  PcdLoadStats stats;
  const PointCloud out = LoadPcd(dir / "c.pcd", &stats);
  ASSERT_EQ(out.size(), in.size());
  ASSERT_TRUE(out.IsConsistent());
  EXPECT_EQ(stats.points_in_file, 3u);
  EXPECT_EQ(stats.dropped_non_finite, 0u);
  EXPECT_TRUE(stats.had_intensity);
  EXPECT_TRUE(stats.had_sigma_z);
  for (std::size_t i = 0; i < in.size(); ++i) {
    for (int r = 0; r < 3; ++r) EXPECT_NEAR(out.xyz(r, i), in.xyz(r, i), kExactM);
    EXPECT_EQ(out.sigma_z_m[i], in.sigma_z_m[i]);
    EXPECT_EQ(out.intensity[i], in.intensity[i]);
  }
}

TEST(PcdIoTest, EmptyCloudRoundTrips) {
  test::ScratchDir dir;
  SavePcd(PointCloud{}, dir / "e.pcd");
  EXPECT_TRUE(LoadPcd(dir / "e.pcd").empty());
}

TEST(PcdIoTest, NonFinitePointsAreDroppedAndCounted) {
  test::ScratchDir dir;
  test::WriteFile(dir / "n.pcd",
                  "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
                  "WIDTH 5\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 5\nDATA ascii\n"
                  "1 2 3\nnan 0 0\n4 5 6\n0 inf 0\n0 0 nan\n");
  PcdLoadStats stats;
  const PointCloud c = LoadPcd(dir / "n.pcd", &stats);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(stats.points_in_file, 5u);
  EXPECT_EQ(stats.dropped_non_finite, 3u);
  EXPECT_FALSE(stats.had_intensity);
  EXPECT_FALSE(stats.had_sigma_z);
  EXPECT_EQ(c.xyz(2, 1), 6.f);
  EXPECT_EQ(c.sigma_z_m[0], 0.f);  // absent field reads as "unknown"
}

TEST(PcdIoTest, ReadsPclTestFiles) {
  ROMO_REQUIRE_SHARED_DATA("pcl/sac_plane_test.pcd");
  // ascii with extra normal fields; the file header says 3283 points.
  const PointCloud plane = LoadPcd(test::SharedData("pcl/sac_plane_test.pcd"));
  EXPECT_EQ(plane.size(), 3283u);
  // binary_compressed, x y z only; header says 13704 points.
  const PointCloud milk = LoadPcd(test::SharedData("pcl/milk.pcd"));
  EXPECT_EQ(milk.size(), 13704u);
  // An organised Kinect frame (640x480) where pixels without depth are NaN.
  PcdLoadStats stats;
  const PointCloud kinect = LoadPcd(
      test::SharedData("pcl/grabber_sequences/pcd/frame_20121214T142255.814212.pcd"), &stats);
  EXPECT_EQ(stats.points_in_file, 640u * 480u);
  EXPECT_GT(stats.dropped_non_finite, 0u);
  EXPECT_EQ(kinect.size() + stats.dropped_non_finite, stats.points_in_file);
  for (Eigen::Index i = 0; i < kinect.xyz.cols(); ++i) ASSERT_TRUE(kinect.xyz.col(i).allFinite());
}

TEST(PcdIoTest, SamePointsAsPclsOwnReaderOnEveryPclTestFile) {
  // romo reads PCD itself (PCL's reader trusts its input): on real files, ascii, binary and
  // binary_compressed, with extra fields and organised frames, it must give PCL's points exactly.
  ROMO_REQUIRE_SHARED_DATA("pcl/milk.pcd");
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(test::SharedData("pcl"))) {
    if (entry.path().extension() == ".pcd") files.push_back(entry.path().string());
  }
  ASSERT_GE(files.size(), 6u);
  for (const std::string& file : files) {
    pcl::PointCloud<pcl::PointXYZ> theirs;
    ASSERT_EQ(pcl::io::loadPCDFile(file, theirs), 0) << file;
    const PointCloud ours = LoadPcd(file);
    std::size_t k = 0;
    for (const auto& p : theirs.points) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
      ASSERT_LT(k, ours.size()) << file;
      ASSERT_EQ(ours.xyz(0, static_cast<Eigen::Index>(k)), p.x) << file << " point " << k;
      ASSERT_EQ(ours.xyz(1, static_cast<Eigen::Index>(k)), p.y) << file << " point " << k;
      ASSERT_EQ(ours.xyz(2, static_cast<Eigen::Index>(k)), p.z) << file << " point " << k;
      ++k;
    }
    EXPECT_EQ(k, ours.size()) << file;
  }
}

TEST(PcdIoTest, MissingFileNamesThePath) {
  try {
    LoadPcd("/nonexistent/romo/cloud.pcd");
    FAIL() << "expected romo::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/romo/cloud.pcd"), std::string::npos);
  }
}

TEST(PcdIoTest, CorruptFilesNameThePath) {
  test::ScratchDir dir;
  test::WriteFile(dir / "garbage.pcd", "this is not a point cloud\n\x01\x02\x03");
  test::WriteFile(dir / "noxyz.pcd",
                  "VERSION 0.7\nFIELDS a b\nSIZE 4 4\nTYPE F F\nCOUNT 1 1\nWIDTH 1\nHEIGHT 1\n"
                  "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1\nDATA ascii\n1 2\n");
  // A valid binary file cut short in its data section (PCL pads binary files, so cut relative
  // to the header end: 3 points x 20 bytes follow it).
  SavePcd(MakeCloud(), dir / "full.pcd");
  const std::string full = test::ReadFile(dir / "full.pcd");
  const std::size_t data_start = full.find("DATA binary\n");
  ASSERT_NE(data_start, std::string::npos);
  test::WriteFile(dir / "cut.pcd", full.substr(0, data_start + 12 + 30));
  std::vector<std::string> names = {"garbage.pcd", "noxyz.pcd", "cut.pcd"};
  if (test::HaveSharedData("pcl/milk.pcd")) {
    // binary_compressed cut short.
    const std::string milk = test::ReadFile(test::SharedData("pcl/milk.pcd"));
    test::WriteFile(dir / "milkcut.pcd", milk.substr(0, milk.size() / 2));
    names.push_back("milkcut.pcd");
  }
  for (const std::string& name : names) {
    try {
      LoadPcd(dir / name);
      ADD_FAILURE() << name << ": expected romo::Error";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  }
}

TEST(PcdIoTest, HeadersClaimingMoreThanTheFileHoldsAreRefusedBeforeAllocating) {
  // PCL allocates width x height x point_step bytes from the header alone: these would ask for
  // 400 GB (ASCII), 8 GB (binary) and 10^14-byte fields in files of ~150 bytes.
  test::ScratchDir dir;
  const std::string head = "VERSION 0.7\nFIELDS x y z\n";
  test::WriteFile(dir / "ascii.pcd", head + "SIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 100000000000\nHEIGHT 1\n"
                                     "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 100000000000\nDATA ascii\n1 2 3\n");
  test::WriteFile(dir / "binary.pcd", head + "SIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 700000000\nHEIGHT 1\n"
                                      "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 700000000\nDATA binary\n0123456789ab");
  test::WriteFile(dir / "size.pcd", head + "SIZE 111111111111114 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 16\n"
                                    "HEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 16\nDATA binary_compressed\n");
  test::WriteFile(dir / "size3.pcd", head + "SIZE 3 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 1\nHEIGHT 1\n"
                                     "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1\nDATA ascii\n1 2 3\n");
  const std::pair<const char*, const char*> cases[] = {
      {"ascii.pcd", "100000000000 x 1 points"}, {"binary.pcd", "data of 700000000 points needs 8400000000 bytes"},
      {"size.pcd", "SIZE value '111111111111114'"}, {"size3.pcd", "SIZE 3 of field 'x' (TYPE F) is not"}};
  for (const auto& [name, says] : cases) {
    try {
      LoadPcd(dir / name);
      ADD_FAILURE() << name << ": expected romo::Error";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
    }
  }
  // A sane file still loads.
  SavePcd(MakeCloud(), dir / "ok.pcd");
  EXPECT_EQ(LoadPcd(dir / "ok.pcd").size(), MakeCloud().size());
}

TEST(PcdIoTest, HeadersPclWouldMisreadAreRefusedNamingTheLine) {
  // PCL read a line by its first token's prefix and let a second FIELDS line resize the fields
  // after SIZE set their offsets: that corrupted PCL's heap (fuzz/regressions/pcd). romo's reader
  // refuses each such header, naming the line.
  test::ScratchDir dir;
  const std::string tail = "WIDTH 1\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1\nDATA ascii\n1 2 3\n";
  const std::pair<std::string, std::string> cases[] = {
      {"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nFIELDS x y\nCOUNT 1 1\n" + tail,
       "line 5: a second FIELDS line (the first is line 2)"},
      {"VERSION 0.7\nFIELDSX x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nCOLUMNS x y z\n" + tail,
       "line 2: unknown header keyword 'FIELDSX'"},
      {"VERSION 0.7\nSIZE 4 4 4\nFIELDS x y z\nTYPE F F F\nCOUNT 1 1 1\n" + tail, "line 2: SIZE before FIELDS"},
      {"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n" + tail, "line 3: SIZE has 4 entries for 3"},
      {"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F\nCOUNT 1 1 1\n" + tail, "line 4: TYPE has 2 entries for 3"},
      {"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 1\nWIDTH 2\nHEIGHT 1\nPOINTS 1\n"
       "DATA ascii\n1 2 3\n",
       "line 7: a second WIDTH line"},
  };
  int k = 0;
  for (const auto& [text, says] : cases) {
    const std::string name = "bad" + std::to_string(k++) + ".pcd";
    test::WriteFile(dir / name, text);
    const std::string message = test::ErrorOf([&] { LoadPcd(dir / name); });
    EXPECT_NE(message.find(name), std::string::npos) << message;
    EXPECT_NE(message.find(says), std::string::npos) << message;
  }
  // Comments and blank lines between keywords are fine.
  test::WriteFile(dir / "commented.pcd", "# .PCD v0.7\nVERSION 0.7\n\nFIELDS x y z\n# sizes\nSIZE 4 4 4\nTYPE F F F\n"
                                        "COUNT 1 1 1\n" + tail);
  EXPECT_EQ(LoadPcd(dir / "commented.pcd").size(), 1u);
}

TEST(PcdIoTest, SaveIntoMissingFolderFailsWithPath) {
  EXPECT_THROW(SavePcd(MakeCloud(), "/nonexistent/romo/out.pcd"), Error);
}

}  // namespace
}  // namespace romo::stereo
