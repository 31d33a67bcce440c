// Left/right pairing by device timestamp and GVSP block-id gap counting: pure logic, no network.
#include <cstdlib>

#include "romo/core/check.hpp"
#include "romo/drivers/gige.hpp"

namespace romo::drivers {

PairDecision DecidePair(std::int64_t left_ns, std::int64_t right_ns, std::int64_t tolerance_ns) {
  const std::int64_t difference = left_ns - right_ns;
  if (std::llabs(difference) <= tolerance_ns) return PairDecision::kPair;
  return difference < 0 ? PairDecision::kLeftUnpaired : PairDecision::kRightUnpaired;
}

std::uint64_t FrameIdGap(std::uint64_t previous, std::uint64_t current) {
  constexpr std::uint64_t kMax16 = 65535;
  // Ids near the top of the 16-bit range followed by small ones: GEV 1.x wrapped (0 is skipped).
  constexpr std::uint64_t kWrapWindow = 4096;
  if (current > previous) return current - previous - 1;
  if (previous <= kMax16 && previous > kMax16 - kWrapWindow && current >= 1 && current < kWrapWindow) {
    return (kMax16 - previous) + (current - 1);
  }
  return 0;  // same id again or the camera restarted its counter
}

StereoPairer::StereoPairer(int rig_id, std::int64_t tolerance_ns, std::size_t max_pending)
    : rig_id_(rig_id), tolerance_ns_(tolerance_ns), max_pending_(max_pending) {
  ROMO_THROW_UNLESS(tolerance_ns >= 0 && max_pending >= 1);
}

void StereoPairer::PushLeft(CameraFrame frame) {
  // A stamp going back means the camera's clock restarted: nothing pending can match any more.
  if (!left_.empty() && frame.stamp_ns < left_.back().stamp_ns) {
    unpaired_left_ += left_.size();
    left_.clear();
  }
  left_.push_back(std::move(frame));
  Match();
}

void StereoPairer::PushRight(CameraFrame frame) {
  if (!right_.empty() && frame.stamp_ns < right_.back().stamp_ns) {
    unpaired_right_ += right_.size();
    right_.clear();
  }
  right_.push_back(std::move(frame));
  Match();
}

void StereoPairer::Match() {
  while (!left_.empty() && !right_.empty()) {
    switch (DecidePair(left_.front().stamp_ns, right_.front().stamp_ns, tolerance_ns_)) {
      case PairDecision::kPair: {
        StereoFrame pair;
        pair.rig_id = rig_id_;
        pair.left = std::move(left_.front());
        pair.right = std::move(right_.front());
        left_.pop_front();
        right_.pop_front();
        pairs_.push_back(std::move(pair));
        break;
      }
      case PairDecision::kLeftUnpaired:
        left_.pop_front();
        ++unpaired_left_;
        break;
      case PairDecision::kRightUnpaired:
        right_.pop_front();
        ++unpaired_right_;
        break;
    }
  }
  // One side waiting for a partner that does not come (camera gone): give up the oldest.
  while (left_.size() > max_pending_) {
    left_.pop_front();
    ++unpaired_left_;
  }
  while (right_.size() > max_pending_) {
    right_.pop_front();
    ++unpaired_right_;
  }
}

std::optional<StereoFrame> StereoPairer::Pop() {
  if (pairs_.empty()) return std::nullopt;
  StereoFrame pair = std::move(pairs_.front());
  pairs_.pop_front();
  return pair;
}

}  // namespace romo::drivers
