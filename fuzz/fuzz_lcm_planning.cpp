// LCM decoding of what perception tells planning (planning_iface/src/messages.cpp). A message
// that decodes must encode again (the decoder validated every field the encoder relies on).
#include "harness.hpp"
#include "romo/planning_iface/messages.hpp"

namespace pi = romo::planning_iface;
using romo::fuzz::ExpectOnlyRomoError;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string why;
  if (const auto m = pi::DecodeObstacleList(data, size, &why)) {
    ExpectOnlyRomoError([&] { pi::Encode(*m); });
  }
  if (const auto m = pi::DecodeParkingSlots(data, size, &why)) {
    ExpectOnlyRomoError([&] { pi::Encode(*m); });
  }
  if (const auto m = pi::DecodePerceptionStatus(data, size, &why)) {
    ExpectOnlyRomoError([&] { pi::Encode(*m); });
  }
  if (const auto m = pi::DecodeRigCloud(data, size, &why)) {
    ExpectOnlyRomoError([&] { pi::Encode(*m); });
  }
  return 0;
}
