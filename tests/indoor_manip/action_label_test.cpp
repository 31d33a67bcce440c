// Action labels on simulated manipulations with seeds disjoint from the ones the thresholds were
// chosen on (0-9): every pair of Tables 6.1/6.2 must be told apart.
#include <cstdio>

#include <gtest/gtest.h>

#include "romo/core/check.hpp"
#include "romo/indoor_manip/action_label.hpp"
#include "romo/sim_manip/manip_eval.hpp"

namespace romo::indoor_manip {
namespace {

TEST(ActionLabelTest, PairsAreTheFiveOfTables61And62) {
  EXPECT_EQ(ActionNames().size(), 10u);
  EXPECT_EQ(ActionPartner("writing"), "erasing");
  EXPECT_EQ(ActionPartner("poking"), "tightening");
  EXPECT_EQ(ActionPartner("hitting"), "pulling");
  EXPECT_EQ(ActionPartner("writing_pen"), "chopping");
  EXPECT_EQ(ActionPartner("drinking"), "eating");
  EXPECT_THROW(ActionPartner("juggling"), romo::Error);
}

TEST(ActionLabelTest, RulesNameTheFeaturesTheyUsed) {
  ActionFeatures f;
  f.rotation_spread_z_deg = 8.0;
  const auto d = ClassifyAction(f, ActionThresholds{});
  EXPECT_EQ(d.label, "tightening");
  ASSERT_FALSE(d.reasons.empty());
  EXPECT_NE(d.reasons.front().find("rotation_spread_z_deg"), std::string::npos);
  f.rotation_spread_z_deg = 1.0;
  f.peak_height_m = 0.33;
  f.descent_speed_mps = 0.4;
  EXPECT_EQ(ClassifyAction(f, ActionThresholds{}).label, "drinking");
  f.peak_height_m = 0.23;
  EXPECT_EQ(ClassifyAction(f, ActionThresholds{}).label, "eating");
  f.descent_speed_mps = 2.0;
  EXPECT_EQ(ClassifyAction(f, ActionThresholds{}).label, "hitting");
}

// The labels do not depend on the blob map: left out to keep the suite short.
ManipParams LabelsOnly() {
  ManipParams p;
  p.object_map = false;
  return p;
}

TEST(ActionLabelTest, EachPairIsSeparatedOnUnseenSeeds) {
  // Seeds 100-102: disjoint from 0-9 used to choose the thresholds; three per action keeps the
  // suite short (`romo eval manip --seeds 100-119` runs the full set).
  constexpr int kFirstSeed = 100, kLastSeed = 102;
  constexpr double kMinAccuracy = 0.8;  // across all ten actions, including the writing contexts
  sim_manip::ConfusionMatrix cm;
  for (const auto& action : ActionNames()) {
    for (int seed = kFirstSeed; seed <= kLastSeed; ++seed) {
      sim_manip::SimManipOptions o;
      o.action = action;
      o.seed = seed;
      std::string label = "error";
      try {
        label = sim_manip::AnalyzeSimManip(o, LabelsOnly()).decision.label;
      } catch (const romo::Error& e) {
        ADD_FAILURE() << action << " seed " << seed << ": " << e.what();
      }
      cm.Add(action, label);
    }
  }
  std::printf("%s", cm.ToText().c_str());
  for (std::size_t i = 0; i < ActionNames().size(); i += 2) {
    EXPECT_EQ(cm.PairConfusions(ActionNames()[i]), 0)
        << ActionNames()[i] << " vs " << ActionPartner(ActionNames()[i]);
  }
  EXPECT_GE(cm.Accuracy(), kMinAccuracy);
}

}  // namespace
}  // namespace romo::indoor_manip
