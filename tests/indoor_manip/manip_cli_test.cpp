// `romo manip` end to end on a simulated scene: outputs, the LCM log, and bad input exit codes.
#include <filesystem>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "test_support.hpp"

namespace romo {
namespace {

TEST(ManipCliTest, WritesPlotsLabelJsonAndLcmLog) {
  test::ScratchDir dir;
  const auto r = test::RunRomo("manip --source 'sim-manip://hitting?seed=3&frames=90' --plane auto "
                               "--hand-seed 160,120 --out " + dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* f : {"fingerprint.png", "profiles.png", "rotation.png", "label.json", "path.csv",
                        "profiles.csv", "manip.lcmlog"}) {
    EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
  }
  const std::string json = test::ReadFile(dir / "label.json");
  EXPECT_NE(json.find("\"label\": \""), std::string::npos) << json;
  EXPECT_NE(json.find("\"evidence\": {"), std::string::npos) << json;
  lcm::LogFile log(dir / "manip.lcmlog", "r");
  ASSERT_TRUE(log.good());
  const lcm::LogEvent* ev = log.readNextEvent();
  ASSERT_NE(ev, nullptr);
  EXPECT_EQ(ev->channel, "ROMO_MANIP");
}

TEST(ManipCliTest, BadInputExitsWithCode2AndNamesTheProblem) {
  test::ScratchDir dir;
  // The top-left pixel of a table scene sees the table: not a hand.
  auto r = test::RunRomo("manip --source 'sim-manip://eating?seed=1&frames=5' --hand-seed 0,239 --out " +
                         dir.path());
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("hand seed"), std::string::npos) << r.err;
  r = test::RunRomo("manip --source 'sim-manip://juggling?seed=1' --hand-seed 1,1 --out " + dir.path());
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("juggling"), std::string::npos) << r.err;
  r = test::RunRomo("manip --source 'sim-manip://eating?seed=1&frames=5' --plane 1,2,3 --hand-seed 160,120 --out " +
                    dir.path());
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--plane"), std::string::npos) << r.err;
  // 2^32 + 2 frames: narrowed to int unchecked it became 2 and passed the range check.
  r = test::RunRomo("manip --source 'sim-manip://poking?frames=4294967298' --hand-seed 160,120 --out " + dir.path());
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("'frames=4294967298' is outside"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace romo
