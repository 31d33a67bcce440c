// Optimal assignment against exhaustive search.
#include <random>

#include <gtest/gtest.h>

#include "romo/core/check.hpp"
#include "romo/objects/hungarian.hpp"

namespace romo::objects {
namespace {

// Costs are O(1..100); sums of up to 7 terms agree to far better than this in double.
constexpr double kCostTolerance = 1e-9;

TEST(HungarianTest, MatchesBruteForceOnRandomRectangularMatrices) {
  std::mt19937 rng(20261121);
  std::uniform_int_distribution<int> size(0, 7);
  std::uniform_real_distribution<double> value(0.0, 100.0);
  std::bernoulli_distribution forbidden(0.25);
  for (int trial = 0; trial < 600; ++trial) {
    const int rows = size(rng), cols = size(rng);
    Eigen::MatrixXd cost(rows, cols);
    const bool with_gates = trial % 2 == 1;
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        // Integer-valued every third trial: many ties between optimal assignments.
        const double v = trial % 3 == 0 ? std::floor(value(rng) / 20.0) : value(rng);
        cost(r, c) = with_gates && forbidden(rng) ? kForbiddenCost : v;
      }
    }
    const Assignment fast = SolveAssignment(cost);
    const Assignment slow = SolveAssignmentBruteForce(cost);
    ASSERT_NEAR(fast.total_cost, slow.total_cost, kCostTolerance) << "trial " << trial << "\n" << cost;
    int fast_pairs = 0, slow_pairs = 0;
    for (int r = 0; r < rows; ++r) {
      fast_pairs += fast.row_to_col[r] >= 0;
      slow_pairs += slow.row_to_col[r] >= 0;
      const int c = fast.row_to_col[r];
      if (c >= 0) {
        EXPECT_EQ(fast.col_to_row[c], r);
        EXPECT_LT(cost(r, c), kForbiddenCost);
      }
    }
    EXPECT_EQ(fast_pairs, slow_pairs) << "trial " << trial;
  }
}

TEST(HungarianTest, KnownThreeByThreeOptimum) {
  Eigen::MatrixXd cost(3, 3);
  cost << 4, 1, 3,
          2, 0, 5,
          3, 2, 2;
  const Assignment a = SolveAssignment(cost);
  EXPECT_EQ(a.row_to_col, (std::vector<int>{1, 0, 2}));
  EXPECT_DOUBLE_EQ(a.total_cost, 5.0);
}

// Greedy nearest-first would pair a1 with b0 (0.4 m) and leave a0 without a partner within the
// gate; the gated matching takes both pairs, then the least summed distance, never one past it.
TEST(HungarianTest, MatchWithinGateTakesTheMostPairsThenTheLeastDistance) {
  const std::vector<Eigen::Vector2d> a{{0.0, 0.0}, {1.0, 0.0}, {9.0, 0.0}};
  const std::vector<Eigen::Vector2d> b{{1.7, 0.0}, {0.6, 0.0}};
  EXPECT_EQ(MatchWithinGate(a, b, 0.75), (std::vector<std::pair<int, int>>{{0, 1}, {1, 0}}));
  EXPECT_EQ(MatchWithinGate(a, b, 0.65), (std::vector<std::pair<int, int>>{{1, 1}}));
  const std::vector<Eigen::Vector2d> near_b{{1.1, 0.0}, {0.1, 0.0}};
  EXPECT_EQ(MatchWithinGate(a, near_b, 1.5), (std::vector<std::pair<int, int>>{{0, 1}, {1, 0}}));
  EXPECT_TRUE(MatchWithinGate(a, {}, 1.0).empty());
}

TEST(HungarianTest, RejectsNaNCost) {
  Eigen::MatrixXd cost = Eigen::MatrixXd::Ones(2, 2);
  cost(1, 0) = std::nan("");
  EXPECT_THROW(SolveAssignment(cost), romo::Error);
}

}  // namespace
}  // namespace romo::objects
