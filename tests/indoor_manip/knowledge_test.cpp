// The Atlas of object functions (config/object_functions.yaml) loaded and validated, and the
// knowledge container (physics, motions, locations, action) filled from a simulated scene whose
// objects have known sizes.
#include <algorithm>
#include <cstdio>

#include <gtest/gtest.h>

#include "romo/core/check.hpp"
#include "romo/indoor_manip/knowledge.hpp"
#include "romo/indoor_manip/object_functions.hpp"
#include "romo/sim_manip/manip_eval.hpp"
#include "test_support.hpp"

namespace romo::indoor_manip {
namespace {

const char* kGood = R"(objects:
  hammer:
    interaction_plane: table
    functions:
      - label: hitting
        motion: fast descents
        pattern: spikes
)";

// The file's own functions for every action, with one object overridden by @p hammer_block.
std::string WithHammer(const std::string& hammer_block) {
  std::string text = test::ReadFile(ObjectFunctionAtlas::DefaultPath());
  const auto at = text.find("  hammer:");
  const auto next = text.find("  knife:");
  EXPECT_NE(at, std::string::npos);
  EXPECT_NE(next, std::string::npos);
  return text.substr(0, at) + hammer_block + text.substr(next);
}

TEST(ObjectFunctionsTest, RepositoryAtlasLoadsAndMapsLabelsToObjects) {
  const ObjectFunctionAtlas atlas = ObjectFunctionAtlas::Load(ObjectFunctionAtlas::DefaultPath());
  EXPECT_EQ(atlas.objects().size(), 7u);  // whiteboard, screwdriver, hammer, knife, pen, fork, glass
  EXPECT_EQ(atlas.functions().size(), 10u);
  for (const auto& a : ActionNames()) EXPECT_FALSE(atlas.FunctionsFor(a).empty()) << a;
  const auto hit = atlas.FunctionsFor("hitting");
  ASSERT_EQ(hit.size(), 1u);
  EXPECT_EQ(hit[0].object, "hammer");
  EXPECT_EQ(hit[0].interaction_plane, "table");
  EXPECT_EQ(atlas.FunctionsFor("writing")[0].interaction_plane, "vertical");
  EXPECT_TRUE(atlas.FunctionsFor("juggling").empty());
}

TEST(ObjectFunctionsTest, BadYamlNamesFileLineFieldAndValue) {
  // Bad syntax: yaml-cpp's position, 1-based.
  std::string e = test::ErrorOf([] { ObjectFunctionAtlas::Parse("objects:\n  hammer: [1, 2\n", "f.yaml"); });
  EXPECT_NE(e.find("f.yaml:"), std::string::npos) << e;
  EXPECT_NE(e.find("not valid YAML"), std::string::npos) << e;

  // A misspelt label: the message names the line it is on.
  const std::string misspelt = WithHammer(
      "  hammer:\n    interaction_plane: table\n    functions:\n      - label: hiting\n"
      "        motion: m\n        pattern: p\n      - label: pulling\n        motion: m\n        pattern: p\n");
  const int line = 1 + static_cast<int>(std::count(misspelt.begin(), misspelt.begin() + misspelt.find("hiting"), '\n'));
  e = test::ErrorOf([&] { ObjectFunctionAtlas::Parse(misspelt, "atlas.yaml"); });
  EXPECT_NE(e.find("atlas.yaml:" + std::to_string(line) + ":"), std::string::npos) << e;
  EXPECT_NE(e.find("objects.hammer.functions[0].label"), std::string::npos) << e;
  EXPECT_NE(e.find("'hiting'"), std::string::npos) << e;

  e = test::ErrorOf([] {
    ObjectFunctionAtlas::Parse(WithHammer("  hammer:\n    interaction_plane: floor\n    functions:\n"
                                          "      - {label: hitting, motion: m, pattern: p}\n"
                                          "      - {label: pulling, motion: m, pattern: p}\n"),
                               "a.yaml");
  });
  EXPECT_NE(e.find("objects.hammer.interaction_plane"), std::string::npos) << e;
  EXPECT_NE(e.find("'floor'"), std::string::npos) << e;

  e = test::ErrorOf([] {
    ObjectFunctionAtlas::Parse(WithHammer("  hammer:\n    interaction_plane: table\n    functions:\n"
                                          "      - {label: hitting, pattern: p}\n"
                                          "      - {label: pulling, motion: m, pattern: p}\n"),
                               "a.yaml");
  });
  EXPECT_NE(e.find("objects.hammer.functions[0].motion"), std::string::npos) << e;

  e = test::ErrorOf([] {
    ObjectFunctionAtlas::Parse(WithHammer("  hammer:\n    interaction_plane: table\n    functions:\n"
                                          "      - {label: hitting, motion: m, patern: p}\n"
                                          "      - {label: pulling, motion: m, pattern: p}\n"),
                               "a.yaml");
  });
  EXPECT_NE(e.find("objects.hammer.functions[0].patern"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown key"), std::string::npos) << e;

  // No functions key at all: named, not yaml-cpp's InvalidNode (found by fuzzing).
  e = test::ErrorOf([] {
    ObjectFunctionAtlas::Parse(WithHammer("  hammer:\n    interaction_plane: table\n"), "a.yaml");
  });
  EXPECT_NE(e.find("field 'objects.hammer.functions' = '<missing>': need a non-empty list"),
            std::string::npos)
      << e;

  // Aliases cannot multiply texts without bound (3000 objects aliasing one: 180 MB from 55 KB).
  e = test::ErrorOf([] {
    std::string many = WithHammer("  hammer: &h\n    interaction_plane: table\n    functions:\n"
                                  "      - {label: hitting, motion: m, pattern: p}\n"
                                  "      - {label: pulling, motion: m, pattern: p}\n");
    for (int i = 0; i < 300; ++i) many += "  copy" + std::to_string(i) + ": *h\n";
    ObjectFunctionAtlas::Parse(many, "a.yaml");
  });
  EXPECT_NE(e.find("field 'objects' = '307 objects': more than 256"), std::string::npos) << e;
  e = test::ErrorOf([] {
    ObjectFunctionAtlas::Parse(WithHammer("  hammer:\n    interaction_plane: table\n    functions:\n"
                                          "      - {label: hitting, motion: " + std::string(1001, 'm') +
                                          ", pattern: p}\n"
                                          "      - {label: pulling, motion: m, pattern: p}\n"),
                               "a.yaml");
  });
  EXPECT_NE(e.find("objects.hammer.functions[0].motion' = '" + std::string(40, 'm') +
                   "...': 1001 characters, more than 1000"),
            std::string::npos)
      << e;

  // Removing pulling leaves an action the plugin reports without any object to explain it.
  e = test::ErrorOf([] {
    ObjectFunctionAtlas::Parse(WithHammer("  hammer:\n    interaction_plane: table\n    functions:\n"
                                          "      - {label: hitting, motion: m, pattern: p}\n"),
                               "a.yaml");
  });
  EXPECT_NE(e.find("action 'pulling' has no object function"), std::string::npos) << e;

  e = test::ErrorOf([] { ObjectFunctionAtlas::Parse(kGood, "small.yaml"); });
  EXPECT_NE(e.find("small.yaml:2:"), std::string::npos) << e;  // where the objects map starts
  EXPECT_NE(e.find("has no object function"), std::string::npos) << e;

  e = test::ErrorOf([] { ObjectFunctionAtlas::Parse("- just\n- a list\n", "l.yaml"); });
  EXPECT_NE(e.find("l.yaml:1: field '<root>'"), std::string::npos) << e;
  e = test::ErrorOf([] { ObjectFunctionAtlas::Load("/nonexistent/of.yaml"); });
  EXPECT_NE(e.find("'/nonexistent/of.yaml': cannot open file"), std::string::npos) << e;
}

TEST(KnowledgeTest, ContainerHoldsPlaneObjectsWithPcaBoxesAreasAndAtlasFunctions) {
  sim_manip::SimManipOptions o;
  o.action = "tightening";
  o.seed = 100;
  o.frames = 150;
  o.transports = 1;
  const ManipResult r = sim_manip::AnalyzeSimManip(o, ManipParams{});
  const ObjectFunctionAtlas atlas = ObjectFunctionAtlas::Load(ObjectFunctionAtlas::DefaultPath());
  const KnowledgeContainer kc = BuildKnowledge(r, atlas);
  // Physics: the table holds most of the 320x240 pixels; the hand, the cup (8 x 8 x 12 cm) and
  // the box (15 x 10 x 4 cm) are octree DFS blobs with PCA boxes.
  std::printf("plane inliers %d, %zu objects\n", kc.physics.plane_inliers, kc.physics.objects.size());
  for (const auto& ob : kc.physics.objects) {
    std::printf("  object %d: %d points, hand %d, box %.3f x %.3f x %.3f m, top %.3f m above the plane\n", ob.id,
                ob.points, ob.is_hand, ob.box.size.x(), ob.box.size.y(), ob.box.size.z(), ob.height_above_plane_m);
  }
  EXPECT_GT(kc.physics.plane_inliers, 320 * 240 / 2);
  ASSERT_GE(kc.physics.objects.size(), 3u);
  EXPECT_EQ(std::count_if(kc.physics.objects.begin(), kc.physics.objects.end(),
                          [](const SceneObject& s) { return s.is_hand; }),
            1);
  // The cup: the blob whose top is 12 cm above the table (depth noise: +-1 cm).
  const auto cup = std::find_if(kc.physics.objects.begin(), kc.physics.objects.end(), [](const SceneObject& s) {
    return !s.is_hand && std::abs(s.height_above_plane_m - 0.12) < 0.01;
  });
  ASSERT_NE(cup, kc.physics.objects.end());
  // A PCA box of the visible surface spans the cup's extent: its longest side lies between the
  // cup's height (12 cm) and its diagonal (sqrt(8^2 + 8^2 + 12^2) = 16.5 cm), +-1 cm noise.
  EXPECT_GT(cup->box.size.x(), 0.11);
  EXPECT_LT(cup->box.size.x(), 0.175);
  // The blob map over the frames: every second frame with the hand found is fused, and the cup
  // carries the completed box of its highest-confidence points, standing on the table.
  std::printf("blob map: %d frames fused, %d without ego-motion\n", kc.physics.map.frames_fused,
              kc.physics.map.ego_failures);
  EXPECT_GE(kc.physics.map.frames_fused, o.frames / 2 - 5);
  const auto cup_map = std::find_if(kc.physics.completed.begin(), kc.physics.completed.end(),
                                    [&](const CompletedObject& c) { return c.first_frame_object == cup->id; });
  ASSERT_NE(cup_map, kc.physics.completed.end());
  ASSERT_TRUE(cup_map->completed_box.has_value());
  const Eigen::Vector3f cup_size = cup_map->completed_box->size;
  std::printf("cup completed box %.3f x %.3f x %.3f m from %d of %d points, mean CV %.3f, bands %d %d %d %d\n",
              cup_size.x(), cup_size.y(), cup_size.z(), cup_map->completed_points, cup_map->points,
              cup_map->mean_confidence, cup_map->points_per_band[0], cup_map->points_per_band[1],
              cup_map->points_per_band[2], cup_map->points_per_band[3]);
  // 8 x 8 cm footprint, 10 cm above the 2 cm foreground height; 1 cm for mixed pixels at edges.
  constexpr float kCupTolM = 0.01f;
  EXPECT_NEAR(cup_size.x(), 0.08f, kCupTolM);
  EXPECT_NEAR(cup_size.y(), 0.08f, kCupTolM);
  EXPECT_NEAR(cup_size.z(), 0.10f, kCupTolM);
  EXPECT_GT(cup_map->points_per_band[3], cup_map->points / 2);
  // Motions and locations: one transport between two areas.
  EXPECT_EQ(kc.motions.transports.size(), 1u);
  EXPECT_EQ(kc.locations.areas.size(), 2u);
  EXPECT_GT(kc.motions.hand_path_length_m, 0.3);  // the transport alone is 30 cm
  // Action: the label's object functions from the Atlas.
  EXPECT_EQ(kc.action.label, r.decision.label);
  ASSERT_FALSE(kc.action.functions.empty());
  for (const auto& f : kc.action.functions) EXPECT_EQ(f.label, kc.action.label);
  const std::string json = kc.ToJson();
  for (const char* key : {"\"physics\"", "\"motions\"", "\"locations\"", "\"action\"", "\"pca_box\"",
                          "\"functions\"", "\"transports\"",
                          "\"completed_box\"", "\"points_per_band\"", "\"mean_confidence\"", "\"blob_map\""}) {
    EXPECT_NE(json.find(key), std::string::npos) << key;
  }
}

}  // namespace
}  // namespace romo::indoor_manip
