// LCM decoding of the simulator's ground truth (tools/sim/src/ground_truth.cpp): per-frame truth
// and per-pixel depth truth, read back by `romo eval scene` from recordings.
#include "harness.hpp"
#include "romo/sim/ground_truth.hpp"

using romo::fuzz::ExpectOnlyRomoError;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ExpectOnlyRomoError([&] { romo::sim::DecodeGroundTruth(data, size, "fuzz"); });
  ExpectOnlyRomoError([&] { romo::sim::DecodeGtDepth(data, size, "fuzz"); });
  return 0;
}
