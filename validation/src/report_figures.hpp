// What the report draws, from a results folder read into plain views: the series
// CSVs as tables, each scenario's runs and reference, and the figures built from them
// (energy, momentum, trajectories, contact timeline, the suite overview). Private to
// report.cpp and report_figures.cpp.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "physval/validation/plot.hpp"

namespace physval::report_detail {

using nlohmann::json;

// Tolerant JSON access: a missing or mistyped field reads as absent.
std::string str(const json& j, const char* key, const std::string& fallback = "");
std::optional<double> num(const json& j, const char* key);
const json& member(const json& j, const char* key);

std::string fmt(double v, const char* spec = "%.3g");

// A series CSV: named columns of numbers ("nan" where a body no longer exists).
struct Table {
  std::vector<std::string> names;
  std::vector<std::vector<double>> columns;
  const std::vector<double>* column(const std::string& name) const {
    for (std::size_t i = 0; i < names.size(); ++i) {
      if (names[i] == name) return &columns[i];
    }
    return nullptr;
  }
  std::size_t rows() const { return columns.empty() ? 0 : columns.front().size(); }
  // Body names, from the x_<name> / y_<name> column pairs, in file order.
  std::vector<std::string> bodies() const {
    std::vector<std::string> out;
    for (const std::string& n : names) {
      if (n.size() > 2 && n.compare(0, 2, "x_") == 0 && column("y_" + n.substr(2)) != nullptr) {
        out.push_back(n.substr(2));
      }
    }
    return out;
  }
};

std::optional<Table> read_table(const std::filesystem::path& file);

struct Source {
  std::string label;     // legend: engine name, or "reference"
  std::string engine;    // "" for the reference
  Table table;
};

struct ScenarioView {
  std::string name;
  std::vector<const json*> runs;
  const json* reference = nullptr;
  std::vector<Source> sources;   // the reference first (drawn underneath), then engines
  double duration = 0.0;
  json geometry;                 // series/<scenario>/scene.json (null when absent): bodies, barriers
};

std::string reference_label(const json* ref);

// An engine's colour in every plot and in the player: by its place among all engines.
std::string engine_colour(const std::vector<std::string>& engines, const std::string& engine);
constexpr const char* kReferenceColour = "#a8a8a8";

plot::Figure energy_figure(const ScenarioView& v, const std::vector<std::string>& engines);
plot::Figure momentum_figure(const ScenarioView& v, const std::vector<std::string>& engines);
plot::Figure trajectory_figure(const ScenarioView& v, const std::vector<std::string>& engines);
// nullopt when no run and no reference has a contact.
// Points per contact, or the rate of contacts when there are too many to show.
std::optional<plot::Figure> contact_figure(const ScenarioView& v, const std::vector<std::string>& engines);
// Every scenario's position and energy divergence, one point per engine.
plot::Figure overview_figure(const std::vector<ScenarioView>& views, const std::vector<std::string>& engines);

}  // namespace physval::report_detail
