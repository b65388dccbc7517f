#include <atomic>
#include <catch2/catch.hpp>
#include <cstdint>
#include <memory>
#include <thread>

#include "omnislam/pipeline/spsc_queue.hpp"

using omnislam::pipeline::PopStatus;
using omnislam::pipeline::SpscQueue;

namespace {

// Counts live instances, so a test sees every object deleted exactly once.
struct Counted {
  static inline std::atomic<int> alive{0};
  explicit Counted(std::uint64_t v) : value(v) { alive.fetch_add(1); }
  ~Counted() { alive.fetch_sub(1); }
  Counted(const Counted &) = delete;
  Counted &operator=(const Counted &) = delete;
  std::uint64_t value;
};

}  // namespace

TEST_CASE("queue: bounded, FIFO, failed push leaves the item with the caller") {
  SpscQueue<Counted> queue(2);
  CHECK(queue.capacity() == 2);
  auto a = std::make_unique<Counted>(1);
  auto b = std::make_unique<Counted>(2);
  auto c = std::make_unique<Counted>(3);
  CHECK(queue.try_push(a));
  CHECK(queue.try_push(b));
  CHECK_FALSE(queue.try_push(c));
  REQUIRE(c);
  CHECK(c->value == 3);
  CHECK(a == nullptr);
  CHECK(queue.size_for_consumer() == 2);
  CHECK(queue.try_pop()->value == 1);
  CHECK(queue.try_pop()->value == 2);
  CHECK(queue.try_pop() == nullptr);
}

TEST_CASE("queue: pop times out when empty, reports closed only once drained") {
  SpscQueue<Counted> queue(4);
  std::unique_ptr<Counted> item;
  CHECK(queue.pop(item, SpscQueue<Counted>::Clock::now() + std::chrono::milliseconds(5)) ==
        PopStatus::kTimeout);
  auto x = std::make_unique<Counted>(7);
  REQUIRE(queue.try_push(x));
  queue.close();
  CHECK(queue.pop(item) == PopStatus::kItem);
  CHECK(item->value == 7);
  CHECK(queue.pop(item) == PopStatus::kClosed);
}

TEST_CASE("queue: blocking push gives up on abort") {
  SpscQueue<Counted> queue(1);
  std::atomic<bool> abort{true};
  auto a = std::make_unique<Counted>(1);
  auto b = std::make_unique<Counted>(2);
  REQUIRE(queue.push(a, abort));
  CHECK_FALSE(queue.push(b, abort));
  CHECK(b);
}

TEST_CASE("queue: the destructor deletes what is still queued") {
  const int before = Counted::alive.load();
  {
    SpscQueue<Counted> queue(8);
    for (std::uint64_t i = 0; i < 5; ++i) {
      auto item = std::make_unique<Counted>(i);
      REQUIRE(queue.try_push(item));
    }
    CHECK(Counted::alive.load() == before + 5);
  }
  CHECK(Counted::alive.load() == before);
}

TEST_CASE("queue: two-thread stress keeps order and checksum, frees everything") {
  constexpr std::uint64_t kItems = 200000;
  const int before = Counted::alive.load();
  SpscQueue<Counted> queue(16);
  std::atomic<bool> never{false};
  bool pushed_all = true;  // Catch2 assertions are not thread-safe: check after join
  std::thread producer([&] {
    for (std::uint64_t i = 1; i <= kItems; ++i) {
      auto item = std::make_unique<Counted>(i);
      if (i % 2 == 0) {
        while (!queue.try_push(item)) std::this_thread::yield();
      } else {
        pushed_all = queue.push(item, never) && pushed_all;
      }
    }
    queue.close();
  });
  std::uint64_t sum = 0, expected_next = 1, received = 0;
  bool in_order = true;
  std::unique_ptr<Counted> item;
  while (queue.pop(item) == PopStatus::kItem) {
    in_order = in_order && item->value == expected_next;
    ++expected_next;
    sum += item->value;
    ++received;
    item.reset();
  }
  producer.join();
  CHECK(pushed_all);
  CHECK(in_order);
  CHECK(received == kItems);
  CHECK(sum == kItems * (kItems + 1) / 2);
  CHECK(Counted::alive.load() == before);
}
