#pragma once
/// Optimal assignment (Hungarian method, shortest augmenting paths with potentials, O(n^2 m)).
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace romo::objects {

/// Cost of a forbidden pair (outside a gate): never chosen when any other way exists, and
/// reported as unassigned when it is.
inline constexpr double kForbiddenCost = 1e18;

struct Assignment {
  std::vector<int> row_to_col;  ///< per row, the assigned column or -1
  std::vector<int> col_to_row;  ///< per column, the assigned row or -1
  double total_cost = 0.0;      ///< sum over assigned (allowed) pairs
};

/// Minimum-cost assignment of the rows of @p cost to its columns (rectangular allowed: the
/// smaller side is fully assigned). Entries >= kForbiddenCost are forbidden: such pairs are
/// dropped from the result. The minimum is over assignments of min(rows, cols) pairs, then
/// forbidden pairs are removed (so gating never makes the solver trade two good pairs for one).
/// @throws romo::Error when a cost is NaN or negative infinity.
Assignment SolveAssignment(const Eigen::MatrixXd& cost);

/// One-to-one pairs (index into @p a, index into @p b) at most @p gate_m apart: the most such
/// pairs, then the least summed distance (CLEAR-MOT matching), ascending by index into @p a.
std::vector<std::pair<int, int>> MatchWithinGate(const std::vector<Eigen::Vector2d>& a,
                                                 const std::vector<Eigen::Vector2d>& b, double gate_m);

/// Reference: tries every assignment (rows, cols <= 8). Same contract as SolveAssignment.
Assignment SolveAssignmentBruteForce(const Eigen::MatrixXd& cost);

}  // namespace romo::objects
