#include "romo/drivers/uri.hpp"

#include <gtest/gtest.h>

#include "romo/core/check.hpp"
#include "romo/drivers/frame_source.hpp"
#include "test_support.hpp"

namespace romo::drivers {
namespace {

using romo::test::ErrorOf;

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

TEST(UriTest, NumbersOutsideTheirRangeAreRefusedNotWrapped) {
  const Uri uri = Uri::Parse("sim://p?n=4294967298&small=-3&x=inf&y=nan&z=1e300&ok=2.5");
  // 2^32 + 2 would become 2 if narrowed to int unchecked.
  EXPECT_NE(ErrorOf([&] { uri.GetInt32("n"); }).find("'n=4294967298' is outside"), std::string::npos);
  EXPECT_EQ(uri.GetInt("n"), 4294967298LL);
  EXPECT_NE(ErrorOf([&] { uri.GetInt("small", 0, 10); }).find("'small=-3' is outside 0..10"), std::string::npos);
  EXPECT_EQ(uri.GetInt("small", -3, -3), -3);
  for (const char* key : {"x", "y"}) {
    EXPECT_NE(ErrorOf([&] { uri.GetDouble(key); }).find("is not a finite number"), std::string::npos) << key;
  }
  EXPECT_NE(ErrorOf([&] { uri.GetDouble("z", 0.0, 1e9); }).find("'z=1e300' is outside"), std::string::npos);
  EXPECT_DOUBLE_EQ(*uri.GetDouble("ok", 2.5, 2.5), 2.5);
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
