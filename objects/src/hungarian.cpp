#include "romo/objects/hungarian.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "romo/core/check.hpp"

namespace romo::objects {
namespace {

void CheckCosts(const Eigen::MatrixXd& cost) {
  for (Eigen::Index r = 0; r < cost.rows(); ++r) {
    for (Eigen::Index c = 0; c < cost.cols(); ++c) {
      const double v = cost(r, c);
      if (std::isnan(v) || v == -std::numeric_limits<double>::infinity()) {
        Fail("assignment cost (" + std::to_string(r) + ", " + std::to_string(c) + ") = " +
             std::to_string(v) + " is not a usable cost");
      }
    }
  }
}

// Forbidden pairs get a finite cost B just big enough that one more forbidden pair always costs
// more than any difference among allowed pairs (B > 2 k max|c|), so the optimum uses as few as
// possible; a modest B (not 1e18) keeps the potentials' round-off small.
Eigen::MatrixXd Clamped(const Eigen::MatrixXd& cost) {
  double max_abs = 0.0;
  for (Eigen::Index i = 0; i < cost.size(); ++i) {
    const double v = cost.data()[i];
    if (v < kForbiddenCost) max_abs = std::max(max_abs, std::abs(v));
  }
  const double k = static_cast<double>(std::min(cost.rows(), cost.cols()));
  const double big = 1.0 + 2.0 * (k + 1.0) * max_abs;
  Eigen::MatrixXd out = cost;
  for (Eigen::Index i = 0; i < out.size(); ++i) {
    if (out.data()[i] >= kForbiddenCost) out.data()[i] = big;
  }
  return out;
}

Assignment Finish(const Eigen::MatrixXd& cost, std::vector<int> row_to_col) {
  Assignment a;
  a.row_to_col = std::move(row_to_col);
  a.col_to_row.assign(static_cast<std::size_t>(cost.cols()), -1);
  for (std::size_t r = 0; r < a.row_to_col.size(); ++r) {
    const int c = a.row_to_col[r];
    if (c < 0) continue;
    if (cost(static_cast<Eigen::Index>(r), c) >= kForbiddenCost) {
      a.row_to_col[r] = -1;
      continue;
    }
    a.col_to_row[static_cast<std::size_t>(c)] = static_cast<int>(r);
    a.total_cost += cost(static_cast<Eigen::Index>(r), c);
  }
  return a;
}

// Rows <= cols: every row gets a column. Potentials u (rows), v (cols); p[j] = row matched to
// column j (1-based, 0 = free, column 0 a virtual start); way[j] = previous column on the path.
std::vector<int> SolveRowsLeCols(const Eigen::MatrixXd& a) {
  const int n = static_cast<int>(a.rows());
  const int m = static_cast<int>(a.cols());
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> u(n + 1, 0.0), v(m + 1, 0.0);
  std::vector<int> p(m + 1, 0), way(m + 1, 0);
  std::vector<double> min_to(m + 1);
  std::vector<char> used(m + 1);
  for (int i = 1; i <= n; ++i) {
    p[0] = i;
    int j0 = 0;
    std::fill(min_to.begin(), min_to.end(), inf);
    std::fill(used.begin(), used.end(), 0);
    do {
      used[j0] = 1;
      const int i0 = p[j0];
      double delta = inf;
      int j1 = -1;
      for (int j = 1; j <= m; ++j) {
        if (used[j]) continue;
        const double reduced = a(i0 - 1, j - 1) - u[i0] - v[j];
        if (reduced < min_to[j]) {
          min_to[j] = reduced;
          way[j] = j0;
        }
        if (min_to[j] < delta) {
          delta = min_to[j];
          j1 = j;
        }
      }
      ROMO_DEMAND(j1 > 0);
      for (int j = 0; j <= m; ++j) {
        if (used[j]) {
          u[p[j]] += delta;
          v[j] -= delta;
        } else {
          min_to[j] -= delta;
        }
      }
      j0 = j1;
    } while (p[j0] != 0);
    // Augment along the path back to the virtual column.
    do {
      const int j1 = way[j0];
      p[j0] = p[j1];
      j0 = j1;
    } while (j0 != 0);
  }
  std::vector<int> row_to_col(static_cast<std::size_t>(n), -1);
  for (int j = 1; j <= m; ++j) {
    if (p[j] != 0) row_to_col[static_cast<std::size_t>(p[j] - 1)] = j - 1;
  }
  return row_to_col;
}

}  // namespace

Assignment SolveAssignment(const Eigen::MatrixXd& cost) {
  CheckCosts(cost);
  if (cost.rows() == 0 || cost.cols() == 0) {
    return Finish(cost, std::vector<int>(static_cast<std::size_t>(cost.rows()), -1));
  }
  const Eigen::MatrixXd a = Clamped(cost);
  if (a.rows() <= a.cols()) return Finish(cost, SolveRowsLeCols(a));
  const std::vector<int> col_to_row = SolveRowsLeCols(a.transpose());
  std::vector<int> row_to_col(static_cast<std::size_t>(a.rows()), -1);
  for (std::size_t c = 0; c < col_to_row.size(); ++c) {
    if (col_to_row[c] >= 0) row_to_col[static_cast<std::size_t>(col_to_row[c])] = static_cast<int>(c);
  }
  return Finish(cost, row_to_col);
}

std::vector<std::pair<int, int>> MatchWithinGate(const std::vector<Eigen::Vector2d>& a,
                                                 const std::vector<Eigen::Vector2d>& b, double gate_m) {
  Eigen::MatrixXd cost(static_cast<Eigen::Index>(a.size()), static_cast<Eigen::Index>(b.size()));
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (std::size_t j = 0; j < b.size(); ++j) {
      const double d = (a[i] - b[j]).norm();
      cost(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = d <= gate_m ? d : kForbiddenCost;
    }
  }
  const Assignment assignment = SolveAssignment(cost);
  std::vector<std::pair<int, int>> pairs;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (assignment.row_to_col[i] >= 0) pairs.emplace_back(static_cast<int>(i), assignment.row_to_col[i]);
  }
  return pairs;
}

Assignment SolveAssignmentBruteForce(const Eigen::MatrixXd& cost) {
  CheckCosts(cost);
  ROMO_THROW_UNLESS(cost.rows() <= 8 && cost.cols() <= 8);
  const Eigen::MatrixXd a = Clamped(cost);
  const bool transpose = a.rows() > a.cols();
  const Eigen::MatrixXd t = transpose ? Eigen::MatrixXd(a.transpose()) : a;
  const int n = static_cast<int>(t.rows());
  const int m = static_cast<int>(t.cols());
  // Every injective map of the n rows into the m columns: permutations of the columns, first n.
  std::vector<int> cols(static_cast<std::size_t>(m));
  std::iota(cols.begin(), cols.end(), 0);
  double best = std::numeric_limits<double>::infinity();
  std::vector<int> best_map(static_cast<std::size_t>(n), -1);
  do {
    double sum = 0.0;
    for (int r = 0; r < n; ++r) sum += t(r, cols[static_cast<std::size_t>(r)]);
    if (sum < best) {
      best = sum;
      best_map.assign(cols.begin(), cols.begin() + n);
    }
  } while (std::next_permutation(cols.begin(), cols.end()));
  std::vector<int> row_to_col(static_cast<std::size_t>(a.rows()), -1);
  if (!transpose) {
    row_to_col = best_map;
  } else {
    for (int r = 0; r < n; ++r) row_to_col[static_cast<std::size_t>(best_map[r])] = r;
  }
  return Finish(cost, row_to_col);
}

}  // namespace romo::objects
