// The exact loop's event queue hands out events in exactly the order of one heap of
// all of them (a priority queue by later()), whatever the pushes in between: the
// calendar's slices must never reorder anything, or results would change.
#include <gtest/gtest.h>

#include <functional>
#include <queue>
#include <random>
#include <vector>

#include "../src/event_queue.hpp"

namespace physval::core_detail {

namespace {

using Reference = std::priority_queue<Event, std::vector<Event>, std::function<bool(const Event&, const Event&)>>;

bool same(const Event& x, const Event& y) {
  return x.time == y.time && x.a == y.a && x.b == y.b && x.va == y.va && x.tag == y.tag;
}

// Times drawn from a few values on purpose: many ties, broken by kind and bodies.
Event random_event(std::mt19937_64& rng, double t_min, double horizon) {
  const double u = static_cast<double>(rng() % 1000) / 1000.0;
  double t = t_min + (horizon - t_min) * u;
  if (rng() % 7 == 0) t = t_min;           // at the time it is found
  if (rng() % 50 == 0) t = horizon;        // at the step's end
  const auto kind = static_cast<EventKind>(rng() % 6);
  return Event::make(t, static_cast<std::uint32_t>(rng() % 20), static_cast<std::uint32_t>(rng() % 20),
                     static_cast<std::uint32_t>(rng() % 3), static_cast<std::uint32_t>(rng() % 3), kind,
                     static_cast<std::uint8_t>(rng() % 2));
}

// Pushes n initial events into both, then pops everything, pushing new events (not
// earlier than the one just popped) now and then; the two must agree throughout.
void check_against_reference(std::mt19937_64& rng, EventQueue& q, int n, double horizon, int late_per_pop) {
  Reference ref(later);
  q.start(horizon);
  for (int k = 0; k < n; ++k) {
    const Event e = random_event(rng, 0.0, horizon);
    q.push(e);
    ref.push(e);
  }
  q.seal();
  int popped = 0;
  while (!ref.empty()) {
    ASSERT_FALSE(q.empty());
    const Event got = q.pop();
    const Event want = ref.top();
    ref.pop();
    ASSERT_TRUE(same(got, want)) << "pop " << popped << ": time " << got.time << " vs " << want.time;
    ++popped;
    if (popped > 20 * n) continue;   // let it drain
    for (int k = 0; k < late_per_pop; ++k) {
      if (rng() % 3 != 0) continue;
      const Event e = random_event(rng, got.time, horizon);
      q.push(e);
      ref.push(e);
    }
  }
  EXPECT_TRUE(q.empty());
}

}  // namespace

TEST(CoreEventQueue, SameOrderAsOneHeap) {
  std::mt19937_64 rng(31);
  EventQueue q;
  for (int n : {0, 1, 2, 5, 64, 1000, 5000}) {
    SCOPED_TRACE(n);
    check_against_reference(rng, q, n, 1.0 / 60.0, 0);
    check_against_reference(rng, q, n, 1.0 / 60.0, 2);
    check_against_reference(rng, q, n, 1.0 / 60.0, 4);
  }
}

TEST(CoreEventQueue, DegenerateHorizons) {
  std::mt19937_64 rng(5);
  EventQueue q;
  check_against_reference(rng, q, 300, 0.0, 2);    // every event in one slice
  check_against_reference(rng, q, 300, 1e-300, 2);
  check_against_reference(rng, q, 300, 1e300, 2);
}

TEST(CoreEventQueue, PushesAfterTheLastSliceAndClear) {
  EventQueue q;
  q.start(1.0);
  q.push(Event::make(0.25, 1, 2, 0, 0, EventKind::Pair));
  q.push(Event::make(0.75, 3, 4, 0, 0, EventKind::Pair));
  q.seal();
  EXPECT_EQ(q.pop().a, 1u);
  EXPECT_EQ(q.pop().a, 3u);
  EXPECT_TRUE(q.empty());
  // Found while processing the last one: still handed out, in order.
  q.push(Event::make(1.0, 7, 8, 0, 0, EventKind::Pair));
  q.push(Event::make(0.75, 5, 6, 0, 0, EventKind::Pair));
  ASSERT_FALSE(q.empty());
  EXPECT_EQ(q.pop().a, 5u);
  EXPECT_EQ(q.pop().a, 7u);
  EXPECT_TRUE(q.empty());
  // clear() drops everything; start() makes it usable again.
  q.start(1.0);
  for (int k = 0; k < 10; ++k) q.push(Event::make(0.1 * k, static_cast<std::uint32_t>(k), 0, 0, 0, EventKind::Stop));
  q.seal();
  EXPECT_EQ(q.pop().a, 0u);
  q.clear();
  EXPECT_TRUE(q.empty());
  q.start(1.0);
  q.push(Event::make(0.5, 9, 0, 0, 0, EventKind::Stop));
  q.seal();
  EXPECT_EQ(q.pop().a, 9u);
  EXPECT_TRUE(q.empty());
}

}  // namespace physval::core_detail
