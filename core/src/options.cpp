#include "physval/core/options.hpp"

#include <cmath>
#include <sstream>
#include <string>

namespace physval {

OptionReader::OptionReader(const Scene& scene, const std::string& engine,
                           const std::vector<OptionSpec>& specs)
    : given_(nullptr), specs_(specs) {
  auto it = scene.engine_options.find(engine);
  if (it != scene.engine_options.end()) given_ = &it->second;
}

const OptionValue& OptionReader::value(const std::string& key) const {
  if (given_ != nullptr) {
    auto it = given_->find(key);
    if (it != given_->end()) return it->second;
  }
  for (const OptionSpec& s : specs_) {
    if (s.key == key) return s.default_value;
  }
  throw std::logic_error("engine option '" + key + "' is not declared");
}

bool OptionReader::get_bool(const std::string& key) const { return std::get<bool>(value(key)); }

std::int64_t OptionReader::get_int(const std::string& key) const {
  return std::get<std::int64_t>(value(key));
}

double OptionReader::get_double(const std::string& key) const {
  const OptionValue& v = value(key);
  if (const auto* i = std::get_if<std::int64_t>(&v)) return static_cast<double>(*i);
  return std::get<double>(v);
}

std::string OptionReader::get_string(const std::string& key) const {
  return std::get<std::string>(value(key));
}

std::string option_value_to_string(const OptionValue& v) {
  struct Visitor {
    std::string operator()(bool b) const { return b ? "true" : "false"; }
    std::string operator()(std::int64_t i) const { return std::to_string(i); }
    // The shortest decimal that reads back as the same double (0.2, not 0.20000000000000001).
    std::string operator()(double d) const {
      for (int digits = 6; digits <= 17; ++digits) {
        std::ostringstream os;
        os.precision(digits);
        os << d;
        if (std::stod(os.str()) == d || digits == 17) return os.str();
      }
      return {};
    }
    std::string operator()(const std::string& s) const { return s; }
  };
  return std::visit(Visitor{}, v);
}

std::string OptionRange::describe() const {
  auto num = [](double v) { return option_value_to_string(OptionValue{v}); };
  const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
  if (has_lo && has_hi) return "in [" + num(lo) + ", " + num(hi) + "]";
  if (has_lo) return (lo_open ? "> " : ">= ") + num(lo);
  if (has_hi) return "<= " + num(hi);
  return "any number";
}

const char* option_type_name(const OptionValue& v) {
  switch (v.index()) {
    case 0: return "boolean";
    case 1: return "integer";
    case 2: return "float";
    default: return "string";
  }
}

}  // namespace physval
