#pragma once
// Private: FrameSet parts <-> romo_lcm messages (raw or PNG images) and the strict LCM log-file
// parser the reader uses. Only drivers' recording code includes this.
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "romo/drivers/frames.hpp"
#include "romo/drivers/recording.hpp"

namespace romo::drivers::lcm_codec {

/// Encoded LCM messages of one frame-set part.
std::vector<std::uint8_t> EncodeStereo(const StereoFrame& frame, std::int64_t set_stamp_ns,
                                       std::uint64_t set_sequence, ImageEncoding encoding);
std::vector<std::uint8_t> EncodeRgbd(const RgbdFrame& frame, std::uint64_t set_sequence,
                                     ImageEncoding encoding);
std::vector<std::uint8_t> EncodeVehicleState(const VehicleState& state,
                                             std::uint64_t set_sequence);
std::vector<std::uint8_t> EncodeGnss(const GnssFix& fix, std::uint64_t set_sequence);
std::vector<std::uint8_t> EncodeCalibration(const std::string& yaml, std::int64_t stamp_ns);

/// Decoders: @throws romo::Error naming @p origin when the bytes are not a valid message.
/// @param set_stamp_ns / set_sequence receive the frame-set stamp and sequence carried.
StereoFrame DecodeStereo(const std::vector<std::uint8_t>& data, const std::string& origin,
                         std::int64_t* set_stamp_ns, std::uint64_t* set_sequence);
RgbdFrame DecodeRgbd(const std::vector<std::uint8_t>& data, const std::string& origin,
                     std::uint64_t* set_sequence);
VehicleState DecodeVehicleState(const std::vector<std::uint8_t>& data, const std::string& origin,
                                std::uint64_t* set_sequence);
GnssFix DecodeGnss(const std::vector<std::uint8_t>& data, const std::string& origin,
                   std::uint64_t* set_sequence);
std::string DecodeCalibration(const std::vector<std::uint8_t>& data, const std::string& origin);

/// What a strict read of one event found.
enum class ReadResult { kEvent, kEnd, kTruncated, kCorrupt };

/// Reads LCM log files event by event, tracking byte offsets. Unlike lcm_eventlog, which skips
/// forward to the next sync word, it stops at the first damaged byte so nothing is silently lost.
class EventFileReader {
 public:
  /// @throws romo::Error when @p path cannot be opened.
  explicit EventFileReader(const std::string& path);
  ~EventFileReader();
  EventFileReader(const EventFileReader&) = delete;
  EventFileReader& operator=(const EventFileReader&) = delete;

  ReadResult Next(LogEvent* event);
  /// Byte offset of the next event (after a kTruncated/kCorrupt: where the damage starts).
  std::int64_t offset() const { return offset_; }
  void SeekTo(std::int64_t offset);
  std::int64_t file_size() const { return file_size_; }
  const std::string& path() const { return path_; }
  /// What was wrong with the event at offset() after a kTruncated/kCorrupt.
  const char* damage() const { return damage_; }

 private:
  ReadResult Damaged(ReadResult result, const char* why);

  std::string path_;
  const char* damage_ = "";
  std::FILE* file_ = nullptr;
  std::int64_t offset_ = 0;
  std::int64_t file_size_ = 0;
};

}  // namespace romo::drivers::lcm_codec
