// The exact loop's event queue: a calendar over the step.
//
// One heap of every candidate event of a step costs a cache miss per level at a
// million bodies (hundreds of thousands of events, several megabytes), and each pop
// walks it from top to bottom. But the events of a step all fall in [0, dt): split
// that into slices of time, about two initial events each, and only the events of the
// current slice need a heap. The initial events (the broad phase's pairs, known at
// once) are counting-sorted into their slices; events found while the step runs go
// into the current slice's heap or, if later, onto their slice's list. A slice is
// loaded into the heap when the one before it is done.
//
// The order is exactly that of one heap of all events: slice_of() never decreases
// with time, so an event of a later slice is later than every event of the current
// one, and within the slice the heap orders by later(), a total order. An event
// pushed for an earlier slice than the current (none are: an event's time is at
// least the time it is found at) would go into the heap too, where it is still
// the earliest. So the results are bit-identical to the single heap's.
#include "event_queue.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace physval::core_detail {

namespace {

constexpr std::uint32_t kNil = std::numeric_limits<std::uint32_t>::max();

// A 4-ary min-heap: half the levels of a binary heap, four children in two cache lines.
void sift_up(std::vector<Event>& h, std::size_t i, const Event& e) {
  while (i > 0) {
    const std::size_t parent = (i - 1) / 4;
    if (!later(h[parent], e)) break;
    h[i] = h[parent];
    i = parent;
  }
  h[i] = e;
}

// Places e at position i or below, in a heap of h.size() entries (e must not refer
// into h).
void sift_down(std::vector<Event>& h, std::size_t i, const Event e) {
  const std::size_t n = h.size();
  for (;;) {
    const std::size_t first = 4 * i + 1;
    if (first >= n) break;
    std::size_t best = first;
    const std::size_t end = std::min(first + 4, n);
    for (std::size_t c = first + 1; c < end; ++c) {
      if (later(h[best], h[c])) best = c;
    }
    if (!later(e, h[best])) break;
    h[i] = h[best];
    i = best;
  }
  h[i] = e;
}

}  // namespace

bool later(const Event& x, const Event& y) {
  if (x.time != y.time) return x.time > y.time;
  const std::uint32_t kx = x.tag >> 28, ky = y.tag >> 28;   // kind and feature
  if ((kx >> 1) != (ky >> 1)) return (kx >> 1) > (ky >> 1);
  if (x.a != y.a) return x.a > y.a;
  if (x.b != y.b) return x.b > y.b;
  if (kx != ky) return kx > ky;
  if (x.va != y.va) return x.va > y.va;
  return x.tag > y.tag;
}

void EventQueue::start(double horizon) {
  horizon_ = horizon;
  sealed_ = false;
  near_.clear();
  initial_.clear();
  late_.clear();
  late_next_.clear();
}

std::uint32_t EventQueue::slice_of(double t) const {
  const double x = t * scale_;
  if (!(x > 0.0)) return 0;   // (also NaN)
  if (x >= static_cast<double>(slices_)) return slices_ - 1;
  return static_cast<std::uint32_t>(x);
}

void EventQueue::seal() {
  // About two initial events a slice; the late ones add a few more.
  slices_ = static_cast<std::uint32_t>(std::clamp<std::size_t>(initial_.size() / 2, 1, 1u << 30));
  scale_ = horizon_ > 0.0 && std::isfinite(horizon_) ? static_cast<double>(slices_) / horizon_ : 0.0;
  start_.assign(static_cast<std::size_t>(slices_) + 1, 0);
  for (const Event& e : initial_) ++start_[slice_of(e.time) + 1];
  for (std::uint32_t s = 0; s < slices_; ++s) start_[s + 1] += start_[s];
  sorted_.resize(initial_.size());
  // start_[s] serves as slice s's fill cursor; afterwards it is slice s + 1's start.
  for (const Event& e : initial_) sorted_[start_[slice_of(e.time)]++] = e;
  for (std::uint32_t s = slices_; s > 0; --s) start_[s] = start_[s - 1];
  start_[0] = 0;
  late_head_.assign(slices_, kNil);
  sealed_ = true;
  current_ = 0;
  load_slice();
  if (near_.empty()) load_next_slice();
}

void EventQueue::push(const Event& e) {
  if (!sealed_) {
    initial_.push_back(e);
    return;
  }
  const std::uint32_t s = slice_of(e.time);
  if (s <= current_) {
    near_.push_back(e);
    sift_up(near_, near_.size() - 1, e);
    return;
  }
  late_.push_back(e);
  late_next_.push_back(late_head_[s]);
  late_head_[s] = static_cast<std::uint32_t>(late_.size() - 1);
}

Event EventQueue::pop() {
  const Event top = near_.front();
  const Event last = near_.back();
  near_.pop_back();
  if (!near_.empty()) {
    sift_down(near_, 0, last);
  } else {
    load_next_slice();
  }
  return top;
}

// Puts the current slice's events into near_ (empty) and makes it a heap.
void EventQueue::load_slice() {
  const std::uint32_t s = current_;
  near_.insert(near_.end(), sorted_.begin() + start_[s], sorted_.begin() + start_[s + 1]);
  for (std::uint32_t k = late_head_[s]; k != kNil; k = late_next_[k]) near_.push_back(late_[k]);
  late_head_[s] = kNil;
  const std::size_t n = near_.size();
  if (n < 2) return;
  for (std::size_t i = (n - 2) / 4 + 1; i-- > 0;) {
    const Event e = near_[i];   // (a copy: sift_down overwrites position i)
    sift_down(near_, i, e);
  }
}

void EventQueue::load_next_slice() {
  while (near_.empty() && current_ + 1 < slices_) {
    ++current_;
    load_slice();
  }
}

void EventQueue::clear() {
  near_.clear();
  current_ = slices_;   // nothing further to load
}

void EventQueue::reserve(std::size_t initial, std::size_t late) {
  near_.reserve(64);
  initial_.reserve(initial);
  sorted_.reserve(initial);
  late_.reserve(late);
  late_next_.reserve(late);
}

std::size_t EventQueue::memory_bytes() const {
  return (near_.capacity() + initial_.capacity() + sorted_.capacity() + late_.capacity()) * sizeof(Event) +
         (start_.capacity() + late_next_.capacity() + late_head_.capacity()) * sizeof(std::uint32_t);
}

}  // namespace physval::core_detail
