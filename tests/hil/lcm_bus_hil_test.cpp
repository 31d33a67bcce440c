// LcmBus over real LCM multicast (udpm://, inside netns-run): how many messages a subscription
// keeps while nobody handles them. LCM's reader thread queues at most the subscription's capacity
// and drops the rest unseen; romo fuse relies on a larger capacity to survive bursts of rig clouds
// while its receiving thread waits for a core (memq:// has no reader thread and never drops, so
// this needs udpm://).
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "romo/core/check.hpp"
#include "romo/planning_iface/lcm_bus.hpp"
#include "status_listener.hpp"

namespace romo::hil {
namespace {

namespace pi = romo::planning_iface;

// Publishes @p burst messages while the subscriber does not handle, then handles what was kept.
int KeptOfBurst(int port, int burst, int queue_capacity, std::size_t message_bytes) {
  // A kernel buffer that holds the whole burst (the default 208 kB does not hold 60 fragmented
  // 6.4 kB messages), so that only LCM's queue decides; 4 MB is within netns-run's rmem_max.
  pi::LcmBus receiver(LcmUrl(port) + "&recv_buf_size=4194304");
  int received = 0;
  receiver.Subscribe("BURST", [&](const std::string&, const std::uint8_t*, std::size_t, std::int64_t) { ++received; },
                     queue_capacity);
  pi::LcmBus sender(LcmUrl(port));
  for (int i = 0; i < burst; ++i) sender.Publish("BURST", std::vector<std::uint8_t>(message_bytes, static_cast<std::uint8_t>(i)));
  // LCM's reader thread takes the whole burst off the socket meanwhile (a few hundred kB on
  // loopback: milliseconds), queueing what the capacity allows.
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  while (receiver.Handle(200)) {
  }
  return received;
}

TEST(LcmBusHilTest, DefaultCapacityDropsABurstBeyondThirtyUnseen) {
  // Why fuse asks for more: LCM's default keeps 30 of a 100-message burst (31 when the reader
  // thread has already handed the first to dispatch before the queue filled).
  const int kept = KeptOfBurst(7821, 100, pi::LcmBus::kLcmDefaultQueueCapacity, 200);
  EXPECT_GE(kept, pi::LcmBus::kLcmDefaultQueueCapacity);
  EXPECT_LE(kept, pi::LcmBus::kLcmDefaultQueueCapacity + 1);
}

TEST(LcmBusHilTest, LargerCapacityKeepsTheWholeBurst) {
  // Small messages and fragmented ones (LCM fragments anything over 1400 bytes) alike.
  EXPECT_EQ(KeptOfBurst(7822, 100, 512, 200), 100);
  EXPECT_EQ(KeptOfBurst(7823, 60, 512, 6400), 60);
}

TEST(LcmBusHilTest, NegativeCapacityIsRefusedNamingTheChannel) {
  pi::LcmBus bus(LcmUrl(7824));
  try {
    bus.Subscribe("BURST", [](const std::string&, const std::uint8_t*, std::size_t, std::int64_t) {}, -1);
    FAIL() << "a negative capacity was accepted";
  } catch (const romo::Error& e) {
    EXPECT_NE(std::string(e.what()).find("'BURST'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace romo::hil
