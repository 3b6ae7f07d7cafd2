// Engine options: each engine declares the keys of its scenario table ([core],
// [box2d], [bullet]) with a type, a default and a line of documentation. The loader
// validates a scenario against these declarations; engines read them through
// OptionReader, which falls back to the declared default.
#pragma once

#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "physval/engine/scene.hpp"

namespace physval {

// The values a numeric option accepts: lo <= v <= hi, or lo < v when lo_open. The
// loader checks every given integer and float against it (`physval check`, exit 2).
struct OptionRange {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;

  static OptionRange any() { return {}; }
  static OptionRange at_least(double v) { return {v, std::numeric_limits<double>::infinity(), false}; }
  static OptionRange above(double v) { return {v, std::numeric_limits<double>::infinity(), true}; }
  static OptionRange between(double a, double b) { return {a, b, false}; }
  bool contains(double v) const { return (lo_open ? v > lo : v >= lo) && v <= hi; }
  std::string describe() const;   // ">= 1", "> 0", "in [0, 1]"
};

struct OptionSpec {
  std::string key;
  OptionValue default_value;           // its alternative is the option's type
  std::vector<std::string> choices;    // for string options: the allowed values
  std::string doc;
  OptionRange range = OptionRange::any();   // numeric options: the values accepted
  // A boolean option that only works with another option in a range (Bullet's `ccd` needs
  // `contact_processing_threshold` > 0): when this option is true (given or by default),
  // the option `needs_key` (given or by default) must lie in `needs_range`. The loader
  // refuses a scene that breaks it (file:line:col and key, exit 2), as it refuses a value
  // out of its own range: the engine cannot run it, and that is bad input, not a run error.
  std::string needs_key{};
  OptionRange needs_range = OptionRange::any();
};

class OptionReader {
 public:
  OptionReader(const Scene& scene, const std::string& engine, const std::vector<OptionSpec>& specs);
  bool get_bool(const std::string& key) const;
  std::int64_t get_int(const std::string& key) const;
  double get_double(const std::string& key) const;   // ints are widened
  std::string get_string(const std::string& key) const;

 private:
  const OptionValue& value(const std::string& key) const;
  const EngineOptions* given_;
  const std::vector<OptionSpec>& specs_;
};

std::string option_value_to_string(const OptionValue& v);
const char* option_type_name(const OptionValue& v);

}  // namespace physval
