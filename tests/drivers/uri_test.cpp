#include "romo/drivers/uri.hpp"

#include <gtest/gtest.h>

#include "romo/core/check.hpp"
#include "romo/drivers/frame_source.hpp"

namespace romo::drivers {
namespace {

TEST(UriTest, ParsesSchemePathAndQuery) {
  const Uri uri = Uri::Parse("sim://parking?seed=7&frames=20&scale=0.5");
  EXPECT_EQ(uri.scheme, "sim");
  EXPECT_EQ(uri.path, "parking");
  EXPECT_EQ(uri.GetInt("seed"), 7);
  EXPECT_EQ(uri.GetInt("frames"), 20);
  EXPECT_DOUBLE_EQ(*uri.GetDouble("scale"), 0.5);
  EXPECT_FALSE(uri.Get("missing").has_value());
  EXPECT_EQ(Uri::Parse(uri.ToString()).query, uri.query);
}

TEST(UriTest, MalformedUrisNameTheProblem) {
  for (const char* bad : {"parking", "://x", "sim://p?seed", "sim://p?=3", "sim://p?a=1&a=2",
                          "si m://p", "sim://p?seed=1&"}) {
    EXPECT_THROW(Uri::Parse(bad), Error) << bad;
  }
  try {
    Uri::Parse("sim://parking?seed=abc").GetInt("seed");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("seed=abc"), std::string::npos) << e.what();
  }
}

TEST(UriTest, UnknownSchemeListsKnownOnes) {
  try {
    OpenSource("ftp://x");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("unknown source URI scheme 'ftp'"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace romo::drivers
