#include "romo/planning_iface/lcm_bus.hpp"

#include <lcm/lcm-cpp.hpp>

#include "romo/core/check.hpp"

namespace romo::planning_iface {

class LcmBus::Impl {
 public:
  explicit Impl(const std::string& u) : url(u), lcm(u) {}

  struct Subscription {
    Handler handler;
    // LCM's C callback: its C++ template wrapper fails UBSan's vptr check (LCM 1.3.1), so the
    // subscription goes through the C API with this plain, non-polymorphic receiver.
    static void Receive(const lcm_recv_buf_t* rbuf, const char* channel, void* user) {
      static_cast<Subscription*>(user)->handler(
          channel, static_cast<const std::uint8_t*>(rbuf->data), rbuf->data_size, rbuf->recv_utime);
    }
  };

  std::string url;
  lcm::LCM lcm;
  std::vector<std::unique_ptr<Subscription>> subscriptions;
};

LcmBus::LcmBus(const std::string& url) : impl_(std::make_unique<Impl>(url)) {
  if (!impl_->lcm.good()) {
    Fail("LCM: cannot open provider '" + url +
         "' (udpm:// needs a multicast route: run inside netns-run; memq:// works anywhere)");
  }
}

LcmBus::~LcmBus() = default;

void LcmBus::Publish(const std::string& channel, const std::vector<std::uint8_t>& data) {
  if (impl_->lcm.publish(channel, data.data(), static_cast<unsigned int>(data.size())) != 0) {
    Fail("LCM: publishing " + std::to_string(data.size()) + " bytes on " + channel + " via '" +
         impl_->url + "' failed");
  }
}

void LcmBus::Subscribe(const std::string& channel_regex, Handler handler, int queue_capacity) {
  if (queue_capacity < 0) {
    Fail("LCM: queue capacity " + std::to_string(queue_capacity) + " for '" + channel_regex + "' is negative");
  }
  auto sub = std::make_unique<Impl::Subscription>();
  sub->handler = std::move(handler);
  lcm_subscription_t* subscription = lcm_subscribe(impl_->lcm.getUnderlyingLCM(), channel_regex.c_str(),
                                                   &Impl::Subscription::Receive, sub.get());
  if (subscription == nullptr) {
    Fail("LCM: cannot subscribe to '" + channel_regex + "' on '" + impl_->url + "'");
  }
  lcm_subscription_set_queue_capacity(subscription, queue_capacity);
  impl_->subscriptions.push_back(std::move(sub));
}

bool LcmBus::Handle(int timeout_ms) {
  const int r = impl_->lcm.handleTimeout(timeout_ms);
  if (r < 0) Fail("LCM: handling messages on '" + impl_->url + "' failed");
  return r > 0;
}

const std::string& LcmBus::url() const { return impl_->url; }

}  // namespace romo::planning_iface
