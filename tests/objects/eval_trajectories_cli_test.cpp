// `romo eval trajectories` end to end: JSON keys and figures, bad input exit codes.
#include <cstdlib>

#include <gtest/gtest.h>

#include "test_support.hpp"

namespace romo {
namespace {

TEST(EvalTrajectoriesCliTest, PrintsDocumentedJsonForHotel) {
  ROMO_REQUIRE_SHARED_DATA("eth_ucy/biwi_hotel.txt");
  const std::string file = test::SharedData("eth_ucy/biwi_hotel.txt");
  const auto r = test::RunRomo("eval trajectories --file '" + file +
                               "' --format ethucy --obs 8 --pred 12 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* key : {"\"file\": ", "\"windows\": 1197", "\"romo\": {\"ade\": ",
                          "\"cv\": {\"ade\": 0.319", "\"fde\": 0.614"}) {
    EXPECT_NE(r.out.find(key), std::string::npos) << key << " in " << r.out;
  }
}

TEST(EvalTrajectoriesCliTest, BadInputExitsNonZeroWithMessage) {
  test::ScratchDir dir;
  const auto missing = test::RunRomo("eval trajectories --file '" + (dir / "none.txt") + "'");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("none.txt"), std::string::npos) << missing.err;
  test::WriteFile(dir / "t.txt", "0\t1\t0\t0\n10\t1\tnan\t0\n");
  const auto strict = test::RunRomo("eval trajectories --strict --file '" + (dir / "t.txt") + "'");
  EXPECT_EQ(strict.exit_code, 2);
  EXPECT_NE(strict.err.find("t.txt:2"), std::string::npos) << strict.err;
  const auto format = test::RunRomo("eval trajectories --format sdd --file '" + (dir / "t.txt") + "'");
  EXPECT_EQ(format.exit_code, 2);
  EXPECT_NE(format.err.find("sdd"), std::string::npos) << format.err;
}

}  // namespace
}  // namespace romo
