#include <cstdint>
#include <unordered_map>

#include "romo/core/check.hpp"
#include "romo/mapping/peers.hpp"

namespace romo::mapping::peers {

double AdjustedRandIndex(const std::vector<int>& a, const std::vector<int>& b) {
  ROMO_THROW_UNLESS(a.size() == b.size());
  const std::size_t n = a.size();
  if (n < 2) return 1.0;
  // Unlabeled points (-1) become singleton clusters with unique negative ids.
  const auto relabel = [](const std::vector<int>& in) {
    std::vector<std::int64_t> out(in.size());
    for (std::size_t i = 0; i < in.size(); ++i) out[i] = in[i] >= 0 ? in[i] : -1 - static_cast<std::int64_t>(i);
    return out;
  };
  const auto la = relabel(a), lb = relabel(b);
  std::unordered_map<std::int64_t, std::int64_t> ca, cb;
  std::unordered_map<std::uint64_t, std::int64_t> cab;
  for (std::size_t i = 0; i < n; ++i) {
    ++ca[la[i]];
    ++cb[lb[i]];
    // Pair key: both labels fit 32 bits for clouds below 2^31 points.
    ++cab[(static_cast<std::uint64_t>(static_cast<std::uint32_t>(la[i])) << 32) |
          static_cast<std::uint32_t>(lb[i])];
  }
  const auto pairs = [](double k) { return k * (k - 1) / 2; };
  double sum_ab = 0, sum_a = 0, sum_b = 0;
  for (const auto& kv : cab) sum_ab += pairs(static_cast<double>(kv.second));
  for (const auto& kv : ca) sum_a += pairs(static_cast<double>(kv.second));
  for (const auto& kv : cb) sum_b += pairs(static_cast<double>(kv.second));
  const double expected = sum_a * sum_b / pairs(static_cast<double>(n));
  const double max_index = 0.5 * (sum_a + sum_b);
  if (max_index == expected) return 1.0;
  return (sum_ab - expected) / (max_index - expected);
}

}  // namespace romo::mapping::peers
