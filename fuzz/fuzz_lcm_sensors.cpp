// LCM decoding of romo's sensor messages (drivers/src/lcm_codec.cpp): stereo and RGB-D frames
// (raw and PNG images), vehicle state, GNSS, calibration text. Every decoder sees every input;
// the type hash rejects the others at once.
#include <vector>

#include "harness.hpp"
#include "lcm_codec.hpp"
#include "romo/drivers/recording.hpp"

namespace codec = romo::drivers::lcm_codec;
using romo::fuzz::ExpectOnlyRomoError;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::vector<std::uint8_t> bytes(data, data + size);
  std::int64_t stamp_ns = 0;
  std::uint64_t sequence = 0;
  ExpectOnlyRomoError([&] { codec::DecodeStereo(bytes, "fuzz", &stamp_ns, &sequence); });
  ExpectOnlyRomoError([&] { codec::DecodeRgbd(bytes, "fuzz", &sequence); });
  ExpectOnlyRomoError([&] { codec::DecodeVehicleState(bytes, "fuzz", &sequence); });
  ExpectOnlyRomoError([&] { codec::DecodeGnss(bytes, "fuzz", &sequence); });
  ExpectOnlyRomoError([&] { codec::DecodeCalibration(bytes, "fuzz"); });
  romo::drivers::LcmTypeName(bytes.data(), bytes.size());
  romo::drivers::LogEvent event;
  event.data = bytes;
  for (const char* channel : {"ROMO_STEREO_RIG3", romo::drivers::kRgbdChannel,
                              romo::drivers::kVehicleStateChannel, romo::drivers::kGnssChannel}) {
    event.channel = channel;
    romo::drivers::FrameSequenceOf(event);
  }
  return 0;
}
