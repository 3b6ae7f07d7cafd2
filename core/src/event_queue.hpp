// The exact loop's events and the queue that hands them out in time order (see
// event_queue.cpp). Private to core/src.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace physval::core_detail {

enum class EventKind : std::uint8_t {
  Explode,    // a = body (the parent), b = emitter
  Pair,       // a < b, bodies
  Static,     // a = body, b = segment, feature = 0 face, 1 cap at from, 2 cap at to
  Stop,       // a = body sliding on its support comes to rest (friction)
  Leave,      // a = body's support point leaves the end of its segment
  Expire,     // a = particle reaches its lifetime
  Emit,       // a = body (a trail's parent) emits a particle, b = emitter
};

// 24 bytes: the version of b shares its word with the kind and the feature (versions
// are compared modulo 2^28, far more changes than one step can make).
struct Event {
  double time = 0.0;   // within the step, s from its start
  std::uint32_t a = 0, b = 0;
  std::uint32_t va = 0;       // version of a when computed
  std::uint32_t tag = 0;      // kind << 29 | feature << 28 | version of b (28 bits)

  static constexpr std::uint32_t kVersionMask = (1u << 28) - 1u;
  static Event make(double time, std::uint32_t a, std::uint32_t b, std::uint32_t va, std::uint32_t vb,
                    EventKind kind, std::uint8_t feature = 0) {
    return {time, a, b, va,
            (static_cast<std::uint32_t>(kind) << 29) | (static_cast<std::uint32_t>(feature & 1u) << 28) |
                (vb & kVersionMask)};
  }
  EventKind kind() const { return static_cast<EventKind>(tag >> 29); }
  std::uint8_t feature() const { return static_cast<std::uint8_t>((tag >> 28) & 1u); }
  std::uint32_t vb() const { return tag & kVersionMask; }
};

// The queue's order: time, then kind (so simultaneous events resolve in a fixed
// order), then bodies; total, so runs are bit-identical. True if x comes after y.
bool later(const Event& x, const Event& y);

// A calendar of the events of one step, [0, horizon): pop() returns the earliest by
// later(), exactly as one heap of all of them would, but only the events of the
// current slice of time sit in a heap; the rest wait in per-slice storage, so the
// heap stays in the cache however many bodies the scene has.
class EventQueue {
 public:
  // Empties the queue for a step of length horizon. Until the first pop(), pushes
  // are collected and then sorted into slices at once.
  void start(double horizon);
  void push(const Event& e);
  // Sorts the initial pushes into their slices and loads the first one.
  void seal();
  // Whether no event is left (once sealed).
  bool empty() const { return near_.empty(); }
  // Removes and returns the earliest event; requires seal() and !empty().
  Event pop();
  // The event that pop() returns next, if known (a hint: a push may come first).
  const Event* next() const { return near_.empty() ? nullptr : &near_.front(); }
  // Drops every event (the loop stops).
  void clear();
  // Storage for this many initial and late events, so steps need not allocate.
  void reserve(std::size_t initial, std::size_t late);
  std::size_t memory_bytes() const;

 private:
  std::uint32_t slice_of(double t) const;
  void load_slice();
  void load_next_slice();

  double horizon_ = 0.0;
  double scale_ = 0.0;               // slices per second
  std::uint32_t slices_ = 1;
  std::uint32_t current_ = 0;        // the slice whose events are in near_
  bool sealed_ = false;
  std::vector<Event> near_;          // 4-ary min-heap: the current slice
  std::vector<Event> initial_;       // pushes before seal()
  std::vector<Event> sorted_;        // initial_ by slice: [start_[s], start_[s + 1])
  std::vector<std::uint32_t> start_;
  std::vector<Event> late_;          // pushes after seal() for a later slice: a list each
  std::vector<std::uint32_t> late_next_;
  std::vector<std::uint32_t> late_head_;
};

}  // namespace physval::core_detail
