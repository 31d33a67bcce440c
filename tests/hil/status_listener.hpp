#pragma once
// Collects the perception status messages (ROMO_PERCEPTION_STATUS) a process under test publishes,
// on a thread of its own, for hardware-in-loop fault tests.
#include <atomic>
#include <chrono>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "romo/planning_iface/lcm_bus.hpp"
#include "romo/planning_iface/messages.hpp"

namespace romo::hil {

/// LCM multicast that never leaves the namespace (netns-run routes 224.0.0.0/4 to loopback).
inline std::string LcmUrl(int port) {
  return "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0";
}

class StatusListener {
 public:
  explicit StatusListener(const std::string& url) : bus_(url) {
    bus_.Subscribe(planning_iface::kPerceptionStatusChannel,
                   [this](const std::string&, const std::uint8_t* data, std::size_t size, std::int64_t) {
                     std::string why;
                     auto status = planning_iface::DecodePerceptionStatus(data, size, &why);
                     std::lock_guard<std::mutex> lock(mutex_);
                     if (!status) {
                       ++undecodable_;
                       return;
                     }
                     for (const auto& event : status->events) events_.push_back(event);
                     statuses_.push_back(std::move(*status));
                   });
    thread_ = std::thread([this] {
      while (!stop_) bus_.Handle(50);
    });
  }
  ~StatusListener() {
    stop_ = true;
    thread_.join();
  }

  std::vector<planning_iface::PerceptionStatus> statuses() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return statuses_;
  }
  /// Every event of every status so far (each status carries the events new since the last).
  std::vector<std::string> events() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return events_;
  }
  /// frames_processed of the latest status, or -1 before the first.
  std::int64_t frames_processed() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return statuses_.empty() ? -1 : statuses_.back().frames_processed;
  }
  bool HasEvent(const std::string& a, const std::string& b = "") const {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& event : events_) {
      if (event.find(a) != std::string::npos && event.find(b) != std::string::npos) return true;
    }
    return false;
  }
  /// Waits until @p done holds (polled every 20 ms); false after @p timeout_s.
  bool WaitFor(const std::function<bool()>& done, double timeout_s) const {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (std::chrono::steady_clock::now() < deadline) {
      if (done()) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return done();
  }
  int undecodable() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return undecodable_;
  }

 private:
  planning_iface::LcmBus bus_;
  mutable std::mutex mutex_;
  std::vector<planning_iface::PerceptionStatus> statuses_;
  std::vector<std::string> events_;
  int undecodable_ = 0;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace romo::hil
