#pragma once
/// A thin handle on one LCM network (memq://, udpm://, file://...): publish bytes, subscribe to
/// channels, handle incoming messages. LCM itself stays behind the pimpl.
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace romo::planning_iface {

class LcmBus {
 public:
  /// @param url an LCM provider URL; "" means LCM's default (LCM_DEFAULT_URL or udpm).
  /// @throws romo::Error naming the URL when LCM cannot open it.
  explicit LcmBus(const std::string& url);
  ~LcmBus();
  LcmBus(const LcmBus&) = delete;
  LcmBus& operator=(const LcmBus&) = delete;

  /// @throws romo::Error when LCM refuses the message (e.g. too large for the provider).
  void Publish(const std::string& channel, const std::vector<std::uint8_t>& data);

  /// Called from Handle() with the raw bytes of each message on a matching channel.
  using Handler = std::function<void(const std::string& channel, const std::uint8_t* data,
                                     std::size_t size, std::int64_t receive_utime)>;
  /// @param channel_regex LCM's channel regular expression ("ROMO_RIG_CLOUD.*").
  /// @param queue_capacity messages LCM holds for this subscription between its reader thread
  ///        and Handle(); beyond that it drops them unseen. LCM's default is 30, less than one
  ///        burst of a few frames of six rig clouds; 0 means unbounded.
  void Subscribe(const std::string& channel_regex, Handler handler, int queue_capacity = kLcmDefaultQueueCapacity);
  static constexpr int kLcmDefaultQueueCapacity = 30;

  /// Waits up to @p timeout_ms for one message and dispatches it.
  /// @return true when a message was handled, false on timeout.
  /// @throws romo::Error when LCM reports an error.
  bool Handle(int timeout_ms);

  const std::string& url() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace romo::planning_iface
