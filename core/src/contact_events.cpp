// Contact events, and the pairs that pass through each other.
//
// When a contact "begins": at every impact of two objects, unless the same two
// touched within the preceding step length (dt). So a bounce after a flight of more
// than one step is a new contact each time, while a ball settling, resting, sliding
// along the floor or micro-bouncing under a pressing force is one contact, reported
// at the impact that started it. Each touching pair is remembered with the time it last
// touched (a resting body is touching its support at the end of every step), so a body
// with several partners (a ball in a pile, in a V, on top of a pyramid) begins each
// pair once.
// Pairs whose collision-matrix response is "event" raise one event when they start
// to overlap and pass through; they are remembered while they overlap.
#include <algorithm>
#include <cmath>

#include "world.hpp"

namespace physval::core_detail {

std::uint32_t static_partner_key(const ObjectRef& owner) {
  return 0x80000000u | (static_cast<std::uint32_t>(owner.kind) << 28) | (owner.index & 0x0fffffffu);
}

std::uint64_t contact_key(std::uint32_t i, std::uint32_t partner) {
  if (partner & 0x80000000u) return (static_cast<std::uint64_t>(i) << 32) | partner;
  return (static_cast<std::uint64_t>(std::min(i, partner)) << 32) | std::max(i, partner);
}

void touch_contact(World& w, std::uint32_t i, std::uint32_t partner, double t_abs) {
  if (w.any_forces) w.last_touch[contact_key(i, partner)] = t_abs;
}

void forget_old_contacts(World& w, double t0, double dt) {
  // A contact this step is at t >= t0 and continues a touch no older than dt before it.
  std::erase_if(w.last_touch, [&](const auto& kv) { return kv.second < t0 - dt; });
}

void record_contact(World& w, std::uint32_t i, std::uint32_t partner_body, const Segment* seg, double t_abs,
                    double window) {
  const std::uint32_t partner = seg ? static_partner_key(seg->owner) : partner_body;
  bool continuing = false;
  if (w.any_forces) {
    auto [it, fresh] = w.last_touch.try_emplace(contact_key(i, partner), t_abs);
    continuing = !fresh && t_abs - it->second <= window;
    it->second = t_abs;
  }
  if (continuing) return;
  ContactEvent e;
  e.time = t_abs;
  if (seg) {
    e.a = {ObjectRef::Kind::Body, i};
    e.b = seg->owner;
  } else {
    e.a = {ObjectRef::Kind::Body, std::min(i, partner_body)};
    e.b = {ObjectRef::Kind::Body, std::max(i, partner_body)};
  }
  w.contacts.push_back(e);
}

std::uint64_t pair_key(std::uint32_t i, std::uint32_t j) {
  const std::uint32_t a = std::min(i, j), b = std::max(i, j);
  return (static_cast<std::uint64_t>(a) << 32) | b;
}

std::uint64_t static_key(std::uint32_t i, std::uint32_t segment) {
  return (static_cast<std::uint64_t>(i) << 32) | 0x80000000u | segment;
}

bool is_passing(const World& w, std::uint64_t key) {
  return std::binary_search(w.passing.begin(), w.passing.end(), key);
}

void add_passing(World& w, std::uint64_t key) {
  auto it = std::lower_bound(w.passing.begin(), w.passing.end(), key);
  if (it == w.passing.end() || *it != key) w.passing.insert(it, key);
}

void prune_passing(World& w) {
  auto still_overlapping = [&](std::uint64_t key) {
    const auto i = static_cast<std::uint32_t>(key >> 32);
    const auto lo = static_cast<std::uint32_t>(key & 0xffffffffu);
    if (!w.alive(i)) return false;
    if (lo & 0x80000000u) {
      const Segment& s = w.statics.segments[lo & 0x7fffffffu];
      const Vec2 p = w.pos[i];
      const double u = std::clamp(dot(p - s.from, s.dir), 0.0, s.length);
      return length(p - (s.from + u * s.dir)) <= w.radius[i];
    }
    if (!w.alive(lo)) return false;
    const double R = w.radius[i] + w.radius[lo];
    return length_squared(w.pos[lo] - w.pos[i]) <= R * R;
  };
  w.passing.erase(std::remove_if(w.passing.begin(), w.passing.end(),
                                 [&](std::uint64_t k) { return !still_overlapping(k); }),
                  w.passing.end());
}

}  // namespace physval::core_detail
