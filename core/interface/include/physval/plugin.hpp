// Optional header-only C++17 layer over physval/plugin.h: write an engine plugin as a
// C++ class and let this file build the C function table, turning exceptions into
// error statuses and keeping returned strings alive. Depends on plugin.h and the
// standard library only.
//
//   class MyEngine {
//    public:
//     static const physval_info& info();                 // static storage
//     void load(const physval_scene& scene, const physval_host& host);   // may throw
//     void step(double dt);                              // may throw
//     double time() const;
//     std::size_t body_count() const;
//     physval_body_meta body_meta(std::size_t i) const;
//     void read_states(physval_body_state* out, std::size_t n) const;
//     const std::vector<physval_contact>& contacts() const;     // of the last step
//     std::vector<std::pair<std::string, std::string>> settings() const;
//     std::vector<std::string> limits_hit() const;       // optional (see below)
//     std::string broken_guarantee() const;              // optional
//   };
//   PHYSVAL_PLUGIN_DEFINE(MyEngine)
//
// limits_hit and broken_guarantee may be omitted: the default is "none".
#pragma once

#include <cstddef>
#include <exception>
#include <new>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "physval/plugin.h"

namespace physval_plugin {

// Reads the scene's option `key` (every declared option is present at load).
inline const physval_option_value* find_option(const physval_scene& scene, const char* key) {
  for (std::size_t i = 0; i < scene.option_count; ++i) {
    if (std::string(scene.options[i].key) == key) return &scene.options[i].value;
  }
  return nullptr;
}
inline double option_double(const physval_scene& s, const char* key, double fallback) {
  const physval_option_value* v = find_option(s, key);
  if (v == nullptr) return fallback;
  return v->type == PHYSVAL_OPTION_INT ? static_cast<double>(v->i) : v->d;
}
inline long long option_int(const physval_scene& s, const char* key, long long fallback) {
  const physval_option_value* v = find_option(s, key);
  return v == nullptr ? fallback : static_cast<long long>(v->i);
}
inline bool option_bool(const physval_scene& s, const char* key, bool fallback) {
  const physval_option_value* v = find_option(s, key);
  return v == nullptr ? fallback : v->b != 0;
}
inline std::string option_string(const physval_scene& s, const char* key, const std::string& fallback) {
  const physval_option_value* v = find_option(s, key);
  return v == nullptr || v->s == nullptr ? fallback : std::string(v->s);
}

namespace detail {

template <class T, class = void>
struct has_limits_hit : std::false_type {};
template <class T>
struct has_limits_hit<T, std::void_t<decltype(std::declval<const T&>().limits_hit())>> : std::true_type {};
template <class T, class = void>
struct has_broken_guarantee : std::false_type {};
template <class T>
struct has_broken_guarantee<T, std::void_t<decltype(std::declval<const T&>().broken_guarantee())>>
    : std::true_type {};

template <class E>
struct Box {
  E engine;
  std::string error;
  std::vector<std::pair<std::string, std::string>> setting_strings;
  std::vector<physval_setting> setting_view;
  std::vector<std::string> limit_strings;
  std::vector<const char*> limit_view;
  std::string broken;
};

template <class E>
Box<E>* box(physval_engine* e) { return reinterpret_cast<Box<E>*>(e); }
template <class E>
const Box<E>* box(const physval_engine* e) { return reinterpret_cast<const Box<E>*>(e); }

template <class E, class F>
physval_status guarded(physval_engine* e, F&& f) {
  Box<E>* b = box<E>(e);
  try {
    f(b->engine);
    return 0;
  } catch (const std::exception& ex) {
    b->error = ex.what();
  } catch (...) {
    b->error = "unknown exception";
  }
  if (b->error.empty()) b->error = "failed";
  return 1;
}

template <class E>
const physval_plugin_table_v1* table() {
  static const physval_plugin_table_v1 t = [] {
    physval_plugin_table_v1 v{};
    v.abi_version = PHYSVAL_PLUGIN_ABI_VERSION;
    v.struct_size = sizeof(physval_plugin_table_v1);
    v.info = []() -> const physval_info* { return &E::info(); };
    v.create = []() -> physval_engine* {
      try {
        return reinterpret_cast<physval_engine*>(new Box<E>());
      } catch (...) {
        return nullptr;
      }
    };
    v.destroy = [](physval_engine* e) { delete box<E>(e); };
    v.last_error = [](const physval_engine* e) { return box<E>(e)->error.c_str(); };
    v.load = [](physval_engine* e, const physval_scene* s, const physval_host* h) {
      return guarded<E>(e, [&](E& en) { en.load(*s, *h); });
    };
    v.step = [](physval_engine* e, double dt) { return guarded<E>(e, [&](E& en) { en.step(dt); }); };
    v.time = [](const physval_engine* e) { return box<E>(e)->engine.time(); };
    v.body_count = [](const physval_engine* e) { return box<E>(e)->engine.body_count(); };
    v.body_meta = [](const physval_engine* e, std::size_t i) { return box<E>(e)->engine.body_meta(i); };
    v.read_states = [](const physval_engine* e, physval_body_state* out, std::size_t n) {
      box<E>(e)->engine.read_states(out, n);
    };
    v.contacts = [](const physval_engine* e, const physval_contact** out, std::size_t* n) {
      const std::vector<physval_contact>& c = box<E>(e)->engine.contacts();
      *out = c.data();
      *n = c.size();
    };
    v.settings = [](const physval_engine* e, const physval_setting** out, std::size_t* n) {
      Box<E>* b = const_cast<Box<E>*>(box<E>(e));
      b->setting_strings = b->engine.settings();
      b->setting_view.clear();
      for (const auto& [k, val] : b->setting_strings) b->setting_view.push_back({k.c_str(), val.c_str()});
      *out = b->setting_view.data();
      *n = b->setting_view.size();
    };
    v.limits_hit = [](const physval_engine* e, const char* const** out, std::size_t* n) {
      Box<E>* b = const_cast<Box<E>*>(box<E>(e));
      b->limit_strings.clear();
      if constexpr (has_limits_hit<E>::value) b->limit_strings = b->engine.limits_hit();
      b->limit_view.clear();
      for (const std::string& s : b->limit_strings) b->limit_view.push_back(s.c_str());
      *out = b->limit_view.data();
      *n = b->limit_view.size();
    };
    v.broken_guarantee = [](const physval_engine* e) -> const char* {
      Box<E>* b = const_cast<Box<E>*>(box<E>(e));
      b->broken.clear();
      if constexpr (has_broken_guarantee<E>::value) b->broken = b->engine.broken_guarantee();
      return b->broken.c_str();
    };
    return v;
  }();
  return &t;
}

}  // namespace detail
}  // namespace physval_plugin

// Defines the plugin's one exported entry point for the engine class E.
#define PHYSVAL_PLUGIN_DEFINE(E)                                                            \
  extern "C" PHYSVAL_PLUGIN_EXPORT const physval_plugin_table_v1* physval_plugin_v1(uint32_t) { \
    return ::physval_plugin::detail::table<E>();                                            \
  }
