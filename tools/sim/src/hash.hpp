#pragma once
// Counter-based randomness: every random value is a pure function of its inputs, so rendering
// and scene generation give the same result for any thread count or evaluation order.
#include <cmath>
#include <cstdint>

namespace romo::sim::internal {

/// SplitMix64 finaliser: a strong 64-bit mix.
inline std::uint64_t Mix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

inline std::uint64_t Hash(std::uint64_t a, std::uint64_t b) { return Mix64(a ^ Mix64(b)); }
inline std::uint64_t Hash(std::uint64_t a, std::uint64_t b, std::uint64_t c) {
  return Hash(Hash(a, b), c);
}
inline std::uint64_t Hash(std::uint64_t a, std::uint64_t b, std::uint64_t c, std::uint64_t d) {
  return Hash(Hash(a, b, c), d);
}

/// Uniform in [0, 1) from the top 53 bits.
inline double ToUnit(std::uint64_t h) { return static_cast<double>(h >> 11) * 0x1.0p-53; }

/// An approximately standard normal sample from one hash: the sum of its four 16-bit parts
/// (Irwin-Hall, n = 4), centred and scaled to unit variance. No libm call, so it is cheap and
/// bit-identical everywhere; tails end at +-3.46 sigma, which is fine for sensor noise.
inline float ToGaussian(std::uint64_t h) {
  const std::uint32_t sum = static_cast<std::uint32_t>(h & 0xFFFF) +
                            static_cast<std::uint32_t>((h >> 16) & 0xFFFF) +
                            static_cast<std::uint32_t>((h >> 32) & 0xFFFF) +
                            static_cast<std::uint32_t>(h >> 48);
  // Each part is uniform on [0, 65535]: mean 4 * 32767.5, variance 4 * 65536^2 / 12.
  return (static_cast<float>(sum) - 131070.0f) * (1.7320508f / 65536.0f);
}

/// A fast 32-bit integer hash for texture lattices (lowbias32 by C. Wellons).
inline std::uint32_t Hash32(std::uint32_t x) {
  x ^= x >> 16;
  x *= 0x7FEB352Du;
  x ^= x >> 15;
  x *= 0x846CA68Bu;
  x ^= x >> 16;
  return x;
}

/// A sequential generator for scene layout: draw k of stream s is Hash(seed, s, k).
class Rng {
 public:
  Rng(std::uint64_t seed, std::uint64_t stream) : key_(Hash(seed, stream)) {}
  double Uniform(double lo, double hi) { return lo + (hi - lo) * ToUnit(Mix64(key_ + ++count_)); }
  std::uint32_t Bits() { return static_cast<std::uint32_t>(Mix64(key_ + ++count_) >> 32); }

 private:
  std::uint64_t key_;
  std::uint64_t count_ = 0;
};

}  // namespace romo::sim::internal
