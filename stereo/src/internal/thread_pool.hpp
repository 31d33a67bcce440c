#pragma once
// A fixed set of worker threads running queued tasks; Run() blocks until a batch is done.
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <queue>
#include <thread>
#include <vector>

namespace romo::stereo::internal {

class ThreadPool {
 public:
  explicit ThreadPool(int threads) {
    for (int i = 0; i < threads; ++i) workers_.emplace_back([this] { Work(); });
  }
  ~ThreadPool() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    for (auto& t : workers_) t.join();
  }
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  int size() const { return static_cast<int>(workers_.size()); }

  /// Runs task(i) for i in [0, n) on the workers and waits for all of them.
  /// Tasks must not throw (callers catch inside).
  void Run(std::size_t n, const std::function<void(std::size_t)>& task) {
    std::unique_lock<std::mutex> lock(mutex_);
    pending_ += n;
    for (std::size_t i = 0; i < n; ++i) queue_.push([&task, i] { task(i); });
    wake_.notify_all();
    done_.wait(lock, [this] { return pending_ == 0; });
  }

 private:
  void Work() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      wake_.wait(lock, [this] { return stop_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stop_ and nothing left
      std::function<void()> job = std::move(queue_.front());
      queue_.pop();
      lock.unlock();
      job();
      lock.lock();
      if (--pending_ == 0) done_.notify_all();
    }
  }

  std::vector<std::thread> workers_;
  std::queue<std::function<void()>> queue_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  std::size_t pending_ = 0;
  bool stop_ = false;
};

}  // namespace romo::stereo::internal
