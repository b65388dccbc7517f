#pragma once

#include <atomic>
#include <boost/lockfree/spsc_queue.hpp>
#include <chrono>
#include <cstddef>
#include <memory>
#include <thread>

/// @file
/// A bounded single-producer/single-consumer lock-free queue of owned objects, on
/// boost::lockfree::spsc_queue of raw pointers.

namespace omnislam::pipeline {

/// Result of a waiting pop.
enum class PopStatus { kItem, kTimeout, kClosed };

/// Bounded SPSC queue passing std::unique_ptr<T> between exactly two threads.
///
/// Contract: one producer thread calls try_push/push/close, one consumer thread calls
/// try_pop/pop/size_for_consumer. Neither side ever takes a lock. Ownership moves with the
/// object: a successful push releases it into the queue, a pop hands it to the consumer,
/// and objects still queued at destruction are deleted. close() tells the consumer that
/// nothing more will come; pop() then returns kClosed once the queue is empty. Waiting is
/// a short spin, then yield, then 50-200 us sleeps, so an idle stage costs no CPU.
template <typename T>
class SpscQueue {
 public:
  using Clock = std::chrono::steady_clock;

  explicit SpscQueue(std::size_t capacity) : queue_(capacity), capacity_(capacity) {}
  SpscQueue(const SpscQueue &) = delete;
  SpscQueue &operator=(const SpscQueue &) = delete;
  ~SpscQueue() {
    queue_.consume_all([](T *item) { delete item; });
  }

  /// Producer: moves `item` into the queue unless it is full; on false `item` is untouched.
  [[nodiscard]] bool try_push(std::unique_ptr<T> &item) {
    if (!queue_.push(item.get())) return false;
    static_cast<void>(item.release());
    return true;
  }

  /// Producer: waits until there is room or `abort` becomes true (then returns false and
  /// `item` is still the caller's).
  [[nodiscard]] bool push(std::unique_ptr<T> &item, const std::atomic<bool> &abort) {
    for (int attempt = 0;; ++attempt) {
      if (try_push(item)) return true;
      if (abort.load(std::memory_order_relaxed)) return false;
      back_off(attempt);
    }
  }

  /// Producer: no more items will be pushed.
  void close() { closed_.store(true, std::memory_order_release); }

  /// Consumer: the next item, or nullptr when empty.
  [[nodiscard]] std::unique_ptr<T> try_pop() {
    T *item = nullptr;
    return queue_.pop(item) ? std::unique_ptr<T>(item) : nullptr;
  }

  /// Consumer: waits for an item until `deadline`. kClosed only once the producer closed
  /// the queue and every item pushed before has been taken.
  [[nodiscard]] PopStatus pop(std::unique_ptr<T> &item,
                              Clock::time_point deadline = Clock::time_point::max()) {
    for (int attempt = 0;; ++attempt) {
      item = try_pop();
      if (item) return PopStatus::kItem;
      if (closed_.load(std::memory_order_acquire)) {
        item = try_pop();  // pushed between the failed pop and the close
        return item ? PopStatus::kItem : PopStatus::kClosed;
      }
      if (Clock::now() >= deadline) return PopStatus::kTimeout;
      back_off(attempt);
    }
  }

  /// Consumer: items waiting now.
  [[nodiscard]] std::size_t size_for_consumer() const { return queue_.read_available(); }

  [[nodiscard]] std::size_t capacity() const { return capacity_; }

 private:
  static void back_off(int attempt) {
    using namespace std::chrono_literals;
    if (attempt < 16) {
      std::this_thread::yield();
    } else {
      std::this_thread::sleep_for(attempt < 64 ? 50us : 200us);
    }
  }

  boost::lockfree::spsc_queue<T *> queue_;
  std::size_t capacity_;
  std::atomic<bool> closed_{false};
};

}  // namespace omnislam::pipeline
