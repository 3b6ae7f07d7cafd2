#include "physval/validation/sweep_shard.hpp"

#include <stdexcept>

namespace physval {

namespace {

RunStatus status_named(const std::string& s) {
  if (s == "ok") return RunStatus::Ok;
  if (s == "diverged") return RunStatus::Diverged;
  if (s == "unsupported") return RunStatus::Unsupported;
  return RunStatus::Error;
}

std::optional<double> number(const nlohmann::json& j, const char* key) {
  if (!j.contains(key) || !j[key].is_number()) return std::nullopt;
  return j[key].get<double>();
}

}  // namespace

SweepResult sweep_from_shards(const std::vector<nlohmann::json>& shards) {
  if (shards.empty()) throw std::invalid_argument("no sweep shards");
  const nlohmann::json& first = shards.front();
  SweepResult r;
  r.scenario = first.at("scenario").get<std::string>();
  r.duration = first.at("duration").get<double>();
  const nlohmann::json& ref = first.at("reference");
  r.reference_available = ref.value("available", false);
  r.reference_converged = ref.value("converged", false);
  r.reference_dt = ref.contains("dt") && ref["dt"].is_number() ? ref["dt"].get<double>() : 0.0;
  r.reference_reason = ref.value("reason", "");
  const std::size_t total = first.at("shard").at("points").size();
  std::vector<std::optional<SweepPoint>> points(total);
  for (const nlohmann::json& doc : shards) {
    if (doc.at("reference") != ref) {
      throw std::invalid_argument("the shards' references differ (" + doc.at("reference").dump() + " against " + ref.dump() +
                                  "): they did not sweep the same reference");
    }
    const nlohmann::json& mine = doc.at("shard").at("mine");
    const nlohmann::json& list = doc.at("points");
    if (mine.size() != list.size()) throw std::invalid_argument("a sweep shard's point list and its index list differ in length");
    for (std::size_t k = 0; k < list.size(); ++k) {
      const nlohmann::json& j = list[k];
      const std::size_t index = mine[k].at("index").get<std::size_t>();
      if (index >= total || points[index]) throw std::invalid_argument("sweep point " + std::to_string(index) + " out of range or twice");
      SweepPoint p;
      p.engine = j.at("engine").get<std::string>();
      p.setting = j.at("setting").get<std::string>();
      p.dt = j.at("dt").get<double>();
      const nlohmann::json& planned = first["shard"]["points"][index];
      if (planned.at("engine") != j["engine"] || planned.at("setting") != j["setting"] || planned.at("dt") != j["dt"]) {
        throw std::invalid_argument("sweep point " + std::to_string(index) + " is not the one the split planned");
      }
      p.steps = j.at("steps").get<long>();
      p.simulated_seconds = j.at("simulated_seconds").get<double>();
      p.status = status_named(j.at("status").get<std::string>());
      p.reason = j.value("reason", "");
      p.repetitions = j.value("repetitions", 0);
      p.runs = j.value("runs", 0L);
      p.wall_per_sim_median = number(j, "wall_per_sim_median").value_or(0.0);
      p.wall_per_sim_min = number(j, "wall_per_sim_min").value_or(0.0);
      p.wall_per_sim_max = number(j, "wall_per_sim_max").value_or(0.0);
      p.spread = number(j, "spread").value_or(0.0);
      p.spread_warning = j.value("spread_warning", false);
      p.position_error = number(j, "position_error");
      p.energy_error = number(j, "energy_error");
      p.contact_time_error = number(j, "contact_time_error");
      if (j.contains("checks_failed")) p.checks_failed = j.at("checks_failed").get<std::vector<std::string>>();
      for (const nlohmann::json& kv : mine[k].at("engine_settings")) {
        p.engine_settings.push_back({kv.at(0).get<std::string>(), kv.at(1).get<std::string>()});
      }
      points[index] = std::move(p);
    }
  }
  for (std::size_t i = 0; i < total; ++i) {
    if (!points[i]) throw std::invalid_argument("sweep point " + std::to_string(i) + " of " + std::to_string(total) + " is in no shard");
    r.points.push_back(std::move(*points[i]));
  }
  r.notes = first.at("shard").at("notes").get<std::vector<std::string>>();
  if (std::string note = sweep_spread_note(r.points, first["shard"].value("spread_warning", 0.25)); !note.empty()) {
    r.notes.push_back(std::move(note));
  }
  analyse_sweep(r);
  return r;
}

}  // namespace physval
