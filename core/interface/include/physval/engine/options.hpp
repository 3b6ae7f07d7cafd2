// Engine options: each engine declares the keys of its scenario table ([core],
// [box2d], [bullet]) with a type, a default and a line of documentation. The loader
// validates a scenario against these declarations; engines read them through
// OptionReader, which falls back to the declared default.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "physval/engine/scene.hpp"

namespace physval {

struct OptionSpec {
  std::string key;
  OptionValue default_value;           // its alternative is the option's type
  std::vector<std::string> choices;    // for string options: the allowed values
  std::string doc;
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
