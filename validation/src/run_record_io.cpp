#include "physval/validation/run_record_io.hpp"

#include <nlohmann/json.hpp>

namespace physval {

using nlohmann::json;

namespace {

json state_to(const BodyState& s) {
  return json::array({s.position.x, s.position.y, s.velocity.x, s.velocity.y, s.angle, s.angular_velocity, s.alive});
}
BodyState state_from(const json& j) {
  BodyState s;
  s.position = {j.at(0).get<double>(), j.at(1).get<double>()};
  s.velocity = {j.at(2).get<double>(), j.at(3).get<double>()};
  s.angle = j.at(4).get<double>();
  s.angular_velocity = j.at(5).get<double>();
  s.alive = j.at(6).get<bool>();
  return s;
}
json states_to(const std::vector<BodyState>& v) {
  json a = json::array();
  for (const BodyState& s : v) a.push_back(state_to(s));
  return a;
}
std::vector<BodyState> states_from(const json& j) {
  std::vector<BodyState> v;
  v.reserve(j.size());
  for (const json& e : j) v.push_back(state_from(e));
  return v;
}
// NaN and infinity survive CBOR; optional values travel as null.
json opt(const std::optional<double>& v) { return v ? json(*v) : json(nullptr); }
std::optional<double> opt(const json& j) {
  if (j.is_null()) return std::nullopt;
  return j.get<double>();
}

}  // namespace

std::vector<std::uint8_t> encode_run_record(const RunRecord& r) {
  json j;
  j["scenario"] = r.scenario;
  j["engine"] = r.engine;
  j["engine_version"] = r.engine_version;
  j["precision"] = r.precision;
  j["dt"] = r.dt;
  j["steps"] = r.steps;
  j["steps_planned"] = r.steps_planned;
  j["status"] = static_cast<int>(r.status);
  j["reason"] = r.reason;
  j["diverged_at"] = opt(r.diverged_at);
  j["wall_seconds"] = r.wall_seconds;
  j["load_seconds"] = r.load_seconds;
  j["settings"] = r.settings;
  j["limits_hit"] = r.limits_hit;
  json bodies = json::array();
  for (const BodyMeta& b : r.bodies) bodies.push_back(json::array({b.name, b.mass, b.radius, b.is_static}));
  j["bodies"] = bodies;
  json contacts = json::array();
  for (const ContactRecord& c : r.contacts) contacts.push_back(json::array({c.a, c.b, c.time, c.step}));
  j["contacts"] = contacts;
  json probes = json::array();
  for (const Probe& p : r.probes) {
    probes.push_back(json::array({p.body, p.max_y, p.max_y_time, p.revolutions, p.last_full_rev_time, p.full_revolutions}));
  }
  j["probes"] = probes;
  json time = r.series.time, totals = json::array(), states = json::array();
  for (const Totals& t : r.series.totals) {
    totals.push_back(json::array({t.kinetic, t.potential, t.momentum.x, t.momentum.y, t.angular_momentum}));
  }
  for (const auto& s : r.series.states) states.push_back(states_to(s));
  j["series"] = {{"time", time}, {"totals", totals}, {"states", states}};
  j["final_states"] = states_to(r.final_states);
  const ContainmentRecord& c = r.containment;
  j["containment"] = json::array({c.measured, c.max_penetration, opt(c.max_penetration_time), c.max_penetration_what,
                                  c.escaped_bodies ? json(*c.escaped_bodies) : json(nullptr), opt(c.first_escape_time),
                                  c.first_escape});
  return json::to_cbor(j);
}

RunRecord decode_run_record(const std::vector<std::uint8_t>& bytes) {
  const json j = json::from_cbor(bytes);
  RunRecord r;
  r.scenario = j.at("scenario").get<std::string>();
  r.engine = j.at("engine").get<std::string>();
  r.engine_version = j.at("engine_version").get<std::string>();
  r.precision = j.at("precision").get<std::string>();
  r.dt = j.at("dt").get<double>();
  r.steps = j.at("steps").get<long>();
  r.steps_planned = j.at("steps_planned").get<long>();
  r.status = static_cast<RunStatus>(j.at("status").get<int>());
  r.reason = j.at("reason").get<std::string>();
  r.diverged_at = opt(j.at("diverged_at"));
  r.wall_seconds = j.at("wall_seconds").get<double>();
  r.load_seconds = j.at("load_seconds").get<double>();
  r.settings = j.at("settings").get<std::vector<Setting>>();
  r.limits_hit = j.at("limits_hit").get<std::vector<std::string>>();
  for (const json& b : j.at("bodies")) {
    r.bodies.push_back({b.at(0).get<std::string>(), b.at(1).get<double>(), b.at(2).get<double>(), b.at(3).get<bool>()});
  }
  for (const json& c : j.at("contacts")) {
    r.contacts.push_back({c.at(0).get<std::string>(), c.at(1).get<std::string>(), c.at(2).get<double>(), c.at(3).get<long>()});
  }
  for (const json& p : j.at("probes")) {
    Probe pr;
    pr.body = p.at(0).get<std::string>();
    pr.max_y = p.at(1).get<double>();
    pr.max_y_time = p.at(2).get<double>();
    pr.revolutions = p.at(3).get<double>();
    pr.last_full_rev_time = p.at(4).get<double>();
    pr.full_revolutions = p.at(5).get<int>();
    r.probes.push_back(pr);
  }
  const json& s = j.at("series");
  r.series.time = s.at("time").get<std::vector<double>>();
  for (const json& t : s.at("totals")) {
    Totals x;
    x.kinetic = t.at(0).get<double>();
    x.potential = t.at(1).get<double>();
    x.momentum = {t.at(2).get<double>(), t.at(3).get<double>()};
    x.angular_momentum = t.at(4).get<double>();
    r.series.totals.push_back(x);
  }
  for (const json& st : s.at("states")) r.series.states.push_back(states_from(st));
  r.final_states = states_from(j.at("final_states"));
  const json& c = j.at("containment");
  r.containment.measured = c.at(0).get<bool>();
  r.containment.max_penetration = c.at(1).get<double>();
  r.containment.max_penetration_time = opt(c.at(2));
  r.containment.max_penetration_what = c.at(3).get<std::string>();
  if (!c.at(4).is_null()) r.containment.escaped_bodies = c.at(4).get<int>();
  r.containment.first_escape_time = opt(c.at(5));
  r.containment.first_escape = c.at(6).get<std::string>();
  return r;
}

}  // namespace physval
