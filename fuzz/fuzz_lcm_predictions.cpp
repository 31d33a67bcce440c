// LCM decoding of pedestrian predictions (objects/src/prediction_lcm.cpp), e.g. from the network.
#include "harness.hpp"
#include "romo/objects/prediction_log.hpp"

using romo::fuzz::ExpectOnlyRomoError;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::int64_t sequence = 0;
  ExpectOnlyRomoError([&] { romo::objects::DecodePedestrianPredictions(data, size, &sequence); });
  return 0;
}
