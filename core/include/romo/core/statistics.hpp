#pragma once
/// Order statistics of a sample, by nearest rank (no interpolation between samples).
#include <algorithm>
#include <cstddef>
#include <vector>

namespace romo {

/// The element of rank round(q (n - 1)) of @p values, q in [0, 1]; 0 for no values.
inline double Percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  const std::size_t k = std::min(values.size() - 1, static_cast<std::size_t>(q * (values.size() - 1) + 0.5));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

/// The upper of the two middle elements for an even count; 0 for no values.
inline double Median(std::vector<double> values) { return Percentile(std::move(values), 0.5); }

}  // namespace romo
