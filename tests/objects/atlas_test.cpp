// Atlas classes from config/atlas.yaml: classification of boxes by size priors, validation.
#include <cmath>

#include <gtest/gtest.h>

#include "romo/core/check.hpp"
#include "romo/objects/atlas.hpp"
#include "test_support.hpp"

namespace romo::objects {
namespace {

Atlas Load() { return Atlas::Load(test::SourcePath("config/atlas.yaml")); }

std::string NameOf(const Atlas& atlas, const Classification& c) {
  return atlas.classes()[static_cast<std::size_t>(c.class_index)].name;
}

TEST(AtlasTest, ShippedAtlasHasTheFourClasses) {
  const Atlas atlas = Load();
  for (const char* name : {"car", "pedestrian", "cyclist", "unknown"}) {
    EXPECT_GE(atlas.Find(name), 0) << name;
  }
  EXPECT_TRUE(atlas.classes()[atlas.Require("pedestrian")].predict_path);
  EXPECT_FALSE(atlas.classes()[atlas.Require("car")].predict_path);
}

TEST(AtlasTest, ClassifiesTypicalBoxes) {
  const Atlas atlas = Load();
  EXPECT_EQ(NameOf(atlas, atlas.Classify(4.5, 1.8, 1.5)), "car");
  EXPECT_EQ(NameOf(atlas, atlas.Classify(1.8, 4.5, 1.45)), "car");  // length/width order free
  EXPECT_EQ(NameOf(atlas, atlas.Classify(0.6, 0.4, 1.75)), "pedestrian");
  EXPECT_EQ(NameOf(atlas, atlas.Classify(1.7, 0.6, 1.65)), "cyclist");
  EXPECT_EQ(NameOf(atlas, atlas.Classify(0.3, 0.3, 0.4)), "unknown");  // a bollard
  EXPECT_EQ(NameOf(atlas, atlas.Classify(12.0, 2.5, 3.5)), "unknown");  // a bus
  // At the prior means the score is 1; farther away it falls.
  const Classification at_mean = atlas.Classify(0.6, 0.4, 1.7);
  EXPECT_NEAR(at_mean.score, 1.0, 1e-12);
  EXPECT_LT(atlas.Classify(0.9, 0.6, 1.9).score, at_mean.score);
}

TEST(AtlasTest, ClassifiesAVerticalBox) {
  const Atlas atlas = Load();
  Box3 box;
  box.size = Eigen::Vector3f(0.55f, 0.35f, 1.8f);
  EXPECT_EQ(NameOf(atlas, atlas.Classify(box)), "pedestrian");
}

TEST(AtlasTest, UsersCanAddClasses) {
  const Atlas atlas = Atlas::Parse(R"(
classes:
  - name: shopping_cart
    length_m: {mean: 0.9, sigma: 0.1, min: 0.7, max: 1.1}
    width_m: {mean: 0.55, sigma: 0.08, min: 0.4, max: 0.7}
    height_m: {mean: 1.0, sigma: 0.1, min: 0.8, max: 1.2}
    attributes: {movable: true, predict_path: false}
  - name: unknown
)", "inline");
  EXPECT_EQ(NameOf(atlas, atlas.Classify(0.92, 0.56, 1.02)), "shopping_cart");
}

// Two classes with the same size priors explain a box equally well: the prior decides, and the
// score reported stays the size likelihood (what min_score is compared with).
TEST(AtlasTest, PriorDecidesBetweenEquallyFittingClasses) {
  const std::string sizes =
      "    length_m: {mean: 1.0, sigma: 0.2, min: 0.5, max: 1.5}\n"
      "    width_m: {mean: 0.5, sigma: 0.1, min: 0.3, max: 0.7}\n"
      "    height_m: {mean: 1.0, sigma: 0.2, min: 0.5, max: 1.5}\n";
  const Atlas atlas = Atlas::Parse("classes:\n  - name: rare\n    prior: 0.2\n" + sizes +
                                       "  - name: common\n" + sizes + "  - name: unknown\n",
                                   "inline");
  EXPECT_DOUBLE_EQ(atlas.classes()[atlas.Require("rare")].prior, 0.2);
  EXPECT_DOUBLE_EQ(atlas.classes()[atlas.Require("common")].prior, 1.0);  // the default
  const Classification c = atlas.Classify(1.1, 0.5, 1.0);
  EXPECT_EQ(NameOf(atlas, c), "common");
  EXPECT_NEAR(c.score, std::exp(-0.5 * 0.25), 1e-12);  // (1.1 - 1.0) / 0.2 = 0.5 sigma
  // The shipped Atlas: a cyclist-sized box is still a cyclist when nothing else fits.
  EXPECT_EQ(NameOf(Load(), Load().Classify(1.7, 0.6, 1.65)), "cyclist");
}

void ExpectError(const std::string& yaml, const std::string& needle) {
  try {
    Atlas::Parse(yaml, "bad.yaml");
    ADD_FAILURE() << "no error for: " << yaml;
  } catch (const romo::Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("bad.yaml"), std::string::npos) << what;
    EXPECT_NE(what.find(needle), std::string::npos) << what;
  }
}

TEST(AtlasTest, BadFilesNameFileFieldAndValue) {
  ExpectError("classes: []", "classes");
  ExpectError("classes:\n  - name: car\n", "unknown");
  ExpectError(
      "classes:\n  - name: car\n    length_m: {mean: 4, sigma: -1, min: 2, max: 6}\n"
      "    width_m: {mean: 1.8, sigma: 0.2, min: 1, max: 2}\n"
      "    height_m: {mean: 1.5, sigma: 0.2, min: 1, max: 2}\n  - name: unknown\n",
      "classes[0] (car).length_m.sigma' = '-1'");
  ExpectError(
      "classes:\n  - name: car\n    length_m: {mean: abc, sigma: 1, min: 2, max: 6}\n"
      "    width_m: {mean: 1.8, sigma: 0.2, min: 1, max: 2}\n"
      "    height_m: {mean: 1.5, sigma: 0.2, min: 1, max: 2}\n  - name: unknown\n",
      "'abc'");
  ExpectError("classes:\n  - name: unknown\n  - name: unknown\n", "duplicate");
  ExpectError("classes:\n  - name: unknown\n    attributes: {predict_path: maybe}\n", "maybe");
  ExpectError("classes: [", "not valid YAML");
  ExpectError("classes:\n  - name: unknown\n    prior: 0\n", "classes[0] (unknown).prior' = '0'");
  ExpectError("classes:\n  - name: unknown\n    prior: 1.5\n", "need 0 < prior <= 1");
  EXPECT_THROW(Atlas::Load("/nonexistent/atlas.yaml"), romo::Error);
}

}  // namespace
}  // namespace romo::objects
