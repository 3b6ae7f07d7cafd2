// DIR/report.html from DIR/results.json and DIR/series/: tables and gnuplot pictures.
// Reads only the files (never the in-memory suite), so `physval report DIR` works on
// any results folder, including one from another machine. Fields missing from an
// older or partial results.json leave their cell or plot out rather than failing.
#include "physval/validation/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "physval/validation/plot.hpp"
#include "physval/validation/results_json.hpp"
#include "markup_escape.hpp"
#include "report_figures.hpp"
#include "report_player.hpp"

namespace physval {

namespace fs = std::filesystem;
using nlohmann::json;
using report_detail::contact_figure;
using report_detail::energy_figure;
using report_detail::fmt;
using report_detail::member;
using report_detail::momentum_figure;
using report_detail::num;
using report_detail::overview_figure;
using report_detail::read_table;
using report_detail::reference_label;
using report_detail::ScenarioView;
using report_detail::str;
using report_detail::trajectory_figure;

namespace {

// ---- formatting -----------------------------------------------------------------

std::string html(const std::string& s) { return markup_escape(s); }

// A metric cell: the value, or a grey dash for null / missing ("does not apply").
std::string metric_cell(const json& metrics, const char* key, const char* unit = "") {
  const json& v = member(metrics, key);
  if (v.is_number()) return "<td class=num>" + fmt(v.get<double>()) + unit + "</td>";
  return "<td class=na title=\"does not apply or not measured\">&ndash;</td>";
}

// ---- the page -------------------------------------------------------------------

const char* kStyle = R"(
body { font-family: -apple-system, "Segoe UI", Roboto, "DejaVu Sans", sans-serif; margin: 2em auto;
       max-width: 1100px; padding: 0 1em; color: #222; line-height: 1.45; }
h1 { margin-bottom: 0.2em; }
h2 { border-bottom: 2px solid #ddd; padding-bottom: 0.2em; margin-top: 2.2em; }
.ctx, .note { color: #666; font-size: 0.9em; }
table { border-collapse: collapse; margin: 0.8em 0; font-size: 0.88em; }
th, td { border: 1px solid #ddd; padding: 0.3em 0.55em; text-align: left; vertical-align: top; }
th { background: #f4f4f4; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
td.na { color: #aaa; text-align: center; }
.ok { color: #176b2c; font-weight: 600; }
.bad { color: #b3261e; font-weight: 600; }
.grey { color: #888; }
.warn { color: #9a6700; font-weight: 600; }
figure { margin: 1.2em 0; }
figure img { max-width: 100%; border: 1px solid #eee; }
figcaption { color: #555; font-size: 0.9em; }
.missing { border: 1px dashed #b3261e; padding: 1em; color: #b3261e; }
details { margin: 0.5em 0; font-size: 0.9em; }
nav a { margin-right: 0.8em; }
)";

std::string status_html(const std::string& status) {
  const char* cls = status == "ok" ? "ok" : (status == "unsupported" ? "grey" : "bad");
  return "<span class=" + std::string(cls) + ">" + html(status.empty() ? "?" : status) + "</span>";
}

// Checks: enforced ones decide pass/fail; others are reported only.
std::string checks_html(const json& run) {
  const json& checks = member(run, "checks");
  if (!checks.is_array() || checks.empty()) return "<td class=na>&ndash;</td>";
  int enforced = 0, failed = 0, reported_failed = 0;
  std::string failures;
  for (const json& c : checks) {
    const bool pass = member(c, "pass").is_boolean() && c["pass"].get<bool>();
    const bool is_enforced = !member(c, "enforced").is_boolean() || c["enforced"].get<bool>();
    if (is_enforced) ++enforced;
    if (pass) continue;
    if (is_enforced) {
      ++failed;
    } else {
      ++reported_failed;
    }
    std::string line = html(str(c, "what"));
    if (auto v = num(c, "value")) {
      line.append(" ").append(fmt(*v));
    } else {
      line += " (not measured)";
    }
    if (auto l = num(c, "limit")) line.append(" &gt; ").append(fmt(*l));
    if (!is_enforced) line += " <span class=grey>(gate, not enforced)</span>";
    failures += "<br>" + line;
  }
  std::string head;
  if (failed > 0) {
    head = "<span class=bad>" + std::to_string(failed) + " of " + std::to_string(enforced) + " failed</span>";
  } else {
    head = "<span class=ok>" + std::to_string(enforced) + " passed</span>";
    if (reported_failed > 0) head += " <span class=warn>(" + std::to_string(reported_failed) + " gate limits exceeded)</span>";
  }
  return "<td>" + head + failures + "</td>";
}

std::string metrics_table(const ScenarioView& v) {
  std::ostringstream os;
  os << "<table><tr><th>engine</th><th>status</th><th>energy drift</th><th>momentum drift</th>"
        "<th>angular momentum drift</th><th>energy divergence</th><th>momentum divergence</th>"
        "<th>position divergence</th><th>first contact</th><th>contact time error</th><th>missed / extra contacts</th>"
        "<th title=\"deepest overlap of a body with another body or a barrier\">max penetration</th>"
        "<th title=\"bodies that left the region the scene's barriers enclose\">escaped bodies</th>"
        "<th>wall time</th><th>checks</th></tr>\n";
  for (const json* run : v.runs) {
    const json& m = member(*run, "metrics");
    const std::string status = str(*run, "status");
    os << "<tr><td><b>" << html(str(*run, "engine")) << "</b>";
    const std::string version = str(*run, "engine_version");
    if (!version.empty()) os << "<br><span class=grey>" << html(version) << " " << html(str(*run, "precision")) << "</span>";
    os << "</td><td>" << status_html(status);
    const std::string reason = str(*run, "reason");
    if (!reason.empty()) os << "<br><span class=grey>" << html(reason) << "</span>";
    os << "</td>" << metric_cell(m, "energy_drift") << metric_cell(m, "linear_momentum_drift")
       << metric_cell(m, "angular_momentum_drift") << metric_cell(m, "energy_divergence")
       << metric_cell(m, "linear_momentum_divergence") << metric_cell(m, "position_divergence", " m")
       << metric_cell(m, "first_contact_time", " s") << metric_cell(m, "contact_time_error", " s");
    const auto missed = num(m, "missed_contacts");
    const auto extra = num(m, "extra_contacts");
    if (missed || extra) {
      os << "<td class=num>" << (missed ? fmt(*missed, "%.0f") : "&ndash;") << " / " << (extra ? fmt(*extra, "%.0f") : "&ndash;")
         << "</td>";
    } else {
      os << "<td class=na>&ndash;</td>";
    }
    os << metric_cell(m, "max_penetration", " m");
    if (auto escaped = num(m, "escaped_bodies")) {
      os << "<td class=num" << (*escaped > 0.0 ? " style=\"color:#b3261e;font-weight:600\"" : "") << ">"
         << fmt(*escaped, "%.0f") << "</td>";
    } else {
      os << "<td class=na title=\"does not apply or not measured\">&ndash;</td>";
    }
    if (auto w = num(*run, "wall_seconds"); w && status != "unsupported") {
      os << "<td class=num>" << fmt(*w) << " s</td>";
    } else {
      os << "<td class=na>&ndash;</td>";
    }
    os << checks_html(*run) << "</tr>\n";
  }
  os << "</table>\n";
  return os.str();
}

std::string settings_html(const ScenarioView& v) {
  std::ostringstream os;
  bool any = false;
  os << "<details><summary>engine settings and limits hit</summary><table><tr><th>engine</th><th>dt</th>"
        "<th>settings</th><th>limits hit</th></tr>\n";
  for (const json* run : v.runs) {
    const json& settings = member(*run, "settings");
    const json& limits = member(*run, "limits_hit");
    if (str(*run, "status") == "unsupported" || (!settings.is_object() && !limits.is_array())) continue;
    any = true;
    os << "<tr><td>" << html(str(*run, "engine")) << "</td><td class=num>";
    if (auto dt = num(*run, "dt")) os << fmt(*dt) << " s";
    os << "</td><td>";
    if (settings.is_object()) {
      for (const auto& [k, val] : settings.items()) {
        os << html(k) << " = " << html(val.is_string() ? val.get<std::string>() : val.dump()) << "<br>";
      }
    }
    os << "</td><td>";
    if (limits.is_array()) {
      for (const json& l : limits) os << html(l.is_string() ? l.get<std::string>() : l.dump()) << "<br>";
    }
    os << "</td></tr>\n";
  }
  os << "</table></details>\n";
  return any ? os.str() : std::string();
}

struct Drawn {
  std::string file;        // relative to the results folder: plots/<name>.png
  std::string caption;
  std::string alt;
  std::string error;       // why it is missing ("" when drawn)
};

std::string figure_html(const Drawn& d) {
  if (!d.error.empty()) {
    return "<figure><div class=missing>" + html(d.alt) + " could not be drawn: " + html(d.error) + "</div></figure>\n";
  }
  return "<figure><img src=\"" + html(d.file) + "\" alt=\"" + html(d.alt) + "\" loading=lazy><figcaption>" +
         html(d.caption) + "</figcaption></figure>\n";
}

// A mark in the page where figure `i` goes once it is drawn (a control character, never
// in escaped HTML).
std::string figure_placeholder(std::size_t i) { return "\x01figure " + std::to_string(i) + "\x01"; }

std::string fill_placeholders(const std::string& page, const std::vector<Drawn>& drawn) {
  std::string out;
  out.reserve(page.size() + drawn.size() * 300);
  std::size_t pos = 0;
  for (std::size_t i = 0; i < drawn.size(); ++i) {
    const std::string mark = figure_placeholder(i);
    const std::size_t at = page.find(mark, pos);
    if (at == std::string::npos) continue;
    out.append(page, pos, at - pos);
    out += figure_html(drawn[i]);
    pos = at + mark.size();
  }
  out.append(page, pos, std::string::npos);
  return out;
}

}  // namespace

std::string report_file_name(const std::string& name) {
  std::string out;
  for (char c : name) out += (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-') ? c : '_';
  return out;
}

void write_report(const fs::path& dir, const Progress& progress) {
  auto say = [&](const std::string& line) {
    if (progress) progress(line);
  };
  const fs::path results_file = dir / "results.json";
  std::ifstream in(results_file);
  if (!in) throw std::runtime_error("no results to report: cannot read " + results_file.string());
  json results;
  try {
    in >> results;
  } catch (const std::exception& e) {
    throw std::runtime_error(results_file.string() + " is not valid JSON: " + e.what());
  }
  const json& runs = member(results, "runs");
  if (!runs.is_array()) throw std::runtime_error(results_file.string() + " has no \"runs\" array");

  std::vector<std::string> notes;
  // Engines in a fixed order: the context's list, then any others as they appear.
  std::vector<std::string> engines;
  const json& context = member(results, "context");
  if (member(context, "engines").is_array()) {
    for (const json& e : context["engines"]) {
      if (!str(e, "name").empty()) engines.push_back(str(e, "name"));
    }
  }
  std::vector<ScenarioView> views;
  auto view_of = [&](const std::string& name) -> ScenarioView& {
    for (ScenarioView& v : views) {
      if (v.name == name) return v;
    }
    views.push_back(ScenarioView{});
    views.back().name = name;
    return views.back();
  };
  for (const json& run : runs) {
    ScenarioView& v = view_of(str(run, "scenario", "(unnamed)"));
    v.runs.push_back(&run);
    const std::string engine = str(run, "engine");
    if (!engine.empty() && std::find(engines.begin(), engines.end(), engine) == engines.end()) engines.push_back(engine);
    if (auto dt = num(run, "dt"), steps = num(run, "steps"); dt && steps) v.duration = std::max(v.duration, *dt * *steps);
  }
  const json& references = member(results, "references");
  if (references.is_array()) {
    for (const json& ref : references) view_of(str(ref, "scenario", "(unnamed)")).reference = &ref;
  } else {
    notes.push_back("results.json has no \"references\": reference contacts and status are not shown.");
  }
  // Only engines that actually ran somewhere get a legend entry in the overview.
  std::vector<std::string> ran;
  for (const std::string& e : engines) {
    for (const json& run : runs) {
      if (str(run, "engine") == e && str(run, "status") != "unsupported") {
        ran.push_back(e);
        break;
      }
    }
  }

  for (ScenarioView& v : views) {
    const fs::path series_dir = dir / "series" / report_file_name(v.name);
    if (std::ifstream geometry(series_dir / "scene.json"); geometry) {
      try {
        geometry >> v.geometry;
      } catch (const std::exception&) {
        v.geometry = nullptr;   // drawn without barriers rather than not at all
        notes.push_back((series_dir / "scene.json").string() + " is not valid JSON: " + v.name + " is drawn without its barriers.");
      }
    }
    if (auto t = read_table(series_dir / "reference.csv")) v.sources.push_back({reference_label(v.reference), "", std::move(*t)});
    for (const json* run : v.runs) {
      const std::string engine = str(*run, "engine");
      if (engine.empty()) continue;
      if (auto t = read_table(series_dir / (report_file_name(engine) + ".csv"))) v.sources.push_back({engine, engine, std::move(*t)});
    }
  }

  const fs::path plots = dir / "plots";
  std::vector<std::string> failures;
  // Figures are queued while the page is written (a placeholder marks each one's place)
  // and drawn together by one gnuplot process at the end.
  std::vector<plot::FigureJob> jobs;
  std::vector<Drawn> drawn;
  auto draw = [&](plot::Figure fig, const std::string& name, const std::string& alt, const std::string& caption) {
    jobs.push_back({std::move(fig), plots / (name + ".png")});
    drawn.push_back(Drawn{"plots/" + name + ".png", caption, alt, ""});
    return figure_placeholder(drawn.size() - 1);
  };

  std::ostringstream page;
  page << "<!doctype html>\n<html lang=en><head><meta charset=utf-8><title>physval report</title>"
       << "<meta name=viewport content=\"width=device-width, initial-scale=1\"><style>" << kStyle
       << "</style>" << report_detail::player_head() << "</head><body>\n<h1>physval report</h1>\n<p class=ctx>";
  {
    std::vector<std::string> parts;
    const std::string version = str(context, "physval_version", str(results, "physval_version"));
    if (!version.empty()) parts.push_back("physval " + html(version));
    for (const char* key : {"date", "host", "build_type", "compiler"}) {
      if (!str(context, key).empty()) parts.push_back(html(str(context, key)));
    }
    if (member(context, "engines").is_array()) {
      std::string list;
      for (const json& e : context["engines"]) {
        if (!list.empty()) list += ", ";
        list += html(str(e, "name") + " " + str(e, "version") + " (" + str(e, "precision") + ")");
      }
      parts.push_back("engines: " + list);
    }
    for (std::size_t i = 0; i < parts.size(); ++i) page << (i ? " &middot; " : "") << parts[i];
  }
  page << "</p>\n";
  if (member(results, "gates_enforced").is_boolean()) {
    page << "<p class=note>" << (results["gates_enforced"].get<bool>() ? "Gate limits were enforced (physval gate)."
                                                                       : "Gate limits were reported, not enforced (physval run).")
         << "</p>\n";
  }
  for (const std::string& n : notes) page << "<p class=note>Note: " << html(n) << "</p>\n";

  // Summary: scenario x engine.
  page << "<h2>Summary</h2>\n<nav>";
  for (const ScenarioView& v : views) page << "<a href=\"#" << html(report_file_name(v.name)) << "\">" << html(v.name) << "</a> ";
  page << "</nav>\n<table><tr><th>scenario</th>";
  for (const std::string& e : engines) page << "<th>" << html(e) << "</th>";
  page << "</tr>\n";
  for (const ScenarioView& v : views) {
    page << "<tr><td><a href=\"#" << html(report_file_name(v.name)) << "\">" << html(v.name) << "</a></td>";
    for (const std::string& e : engines) {
      const json* run = nullptr;
      for (const json* r : v.runs) {
        if (str(*r, "engine") == e) run = r;
      }
      if (run == nullptr) {
        page << "<td class=na>&ndash;</td>";
        continue;
      }
      const std::string status = str(*run, "status");
      bool failed = false;
      if (member(*run, "checks").is_array()) {
        for (const json& c : (*run)["checks"]) {
          const bool enforced = !member(c, "enforced").is_boolean() || c["enforced"].get<bool>();
          if (enforced && !(member(c, "pass").is_boolean() && c["pass"].get<bool>())) failed = true;
        }
      }
      page << "<td>" << status_html(status);
      if (status == "ok") page << (failed ? " <span class=bad>checks failed</span>" : " <span class=ok>&#10003;</span>");
      // A divergence the scenario records as known (within its bound): the gate passes it,
      // and the cell says so rather than reading like a failure.
      const json& known = member(*run, "known_divergence");
      if (status == "diverged" && known.is_boolean() && known.get<bool>()) {
        page << " <span class=grey title=\"within the bound its scenario records in known_failures\">(known)</span>";
      }
      page << "</td>";
    }
    page << "</tr>\n";
  }
  page << "</table>\n";
  const bool any_divergence = std::any_of(runs.begin(), runs.end(), [](const json& run) {
    for (const char* m : {"position_divergence", "energy_divergence"}) {
      if (auto v = num(member(run, "metrics"), m); v && *v > 0.0) return true;
    }
    return false;
  });
  if (!any_divergence) {
    page << "<p class=note>No run has a measured divergence from a reference (none was available or converged), "
            "so there is no overview plot.</p>\n";
  } else {
    say("report: laying out the overview");
    page << (draw(overview_figure(views, ran), "overview", "divergence of every scenario and engine",
                             "Each engine's largest position divergence and its energy divergence from the scenario's "
                             "reference, per scenario. Log scale: one grid line is a factor of ten."));
  }

  report_detail::PlayerSection player_totals;
  std::size_t players = 0;
  std::size_t index = 0;
  for (const ScenarioView& v : views) {
    ++index;
    say("report: laying out " + v.name + " (" + std::to_string(index) + "/" + std::to_string(views.size()) + ")");
    const std::string base = report_file_name(v.name);
    page << "<h2 id=\"" << html(base) << "\">" << html(v.name) << "</h2>\n";
    if (v.reference != nullptr) {
      const json& ref = *v.reference;
      const bool available = member(ref, "available").is_boolean() && ref["available"].get<bool>();
      const bool converged = member(ref, "converged").is_boolean() && ref["converged"].get<bool>();
      page << "<p class=note>Reference: ";
      if (!available) {
        page << "<span class=warn>none</span>";
      } else {
        page << "core";
        if (auto dt = num(ref, "dt")) page << " at dt " << fmt(*dt) << " s";
        page << (converged ? ", <span class=ok>converged</span>" : ", <span class=warn>not converged</span>");
        if (auto ce = num(ref, "convergence_error")) page << " (two resolutions agree to " << fmt(*ce) << " m)";
      }
      if (!str(ref, "reason").empty()) page << " &mdash; " << html(str(ref, "reason"));
      page << "</p>\n";
    }
    page << metrics_table(v) << settings_html(v);
    page << "<p class=note>Drifts are relative to the run's own start; divergences are against the reference. "
            "&ndash; means the quantity is not conserved by this scene or could not be measured.</p>\n";

    if (v.sources.empty()) {
      page << "<p class=note>No time series in series/" << html(base) << "/: nothing to plot.</p>\n";
      continue;
    }
    {
      const report_detail::PlayerSection player = report_detail::player_section(v, engines, base + "-player");
      page << "<h3>Scene player</h3>\n" << player.html;
      player_totals.raw_bytes += player.raw_bytes;
      player_totals.coded_bytes += player.coded_bytes;
      player_totals.packed_bytes += player.packed_bytes;
      player_totals.embedded_bytes += player.embedded_bytes;
      ++players;
    }
    page << (draw(energy_figure(v, engines), base + "_energy", v.name + " energy over time",
                             "Top: total energy of each engine's run and of the reference. Bottom: how far each run's "
                             "energy has moved from its starting value, log scale (a straight rising line is a steady "
                             "drift; gaps are exact zeros)."));
    page << (draw(momentum_figure(v, engines), base + "_momentum", v.name + " momentum over time",
                             "Linear momentum (x and y) and angular momentum about the origin, per engine. Walls, "
                             "uniform gravity and drag change momentum; compare the engines with the reference."));
    page << (draw(trajectory_figure(v, engines), base + "_trajectories", v.name + " trajectories",
                             "The path of each body in each engine, drawn over the reference's (thick grey). Equal "
                             "scales on both axes."));
    if (auto contacts = contact_figure(v, engines)) {
      page << (draw(*contacts, base + "_contacts", v.name + " contact timeline",
                               "One row per engine: where it reported a contact beginning, coloured by the pair in "
                               "contact. Grey vertical lines: the reference's contact times."));
    } else {
      page << "<p class=note>No contacts in this scenario (reference and engines).</p>\n";
    }
  }
  if (players > 0) {
    auto kb = [](std::size_t bytes) { return fmt(static_cast<double>(bytes) / 1024.0, "%.0f") + " KB"; };
    page << "<p class=ctx>Scene players: " << players << ", their series resampled to at most "
         << report_detail::kMaxFrames << " frames and embedded as " << kb(player_totals.embedded_bytes)
         << " of text: " << kb(player_totals.raw_bytes) << " as float64, " << kb(player_totals.coded_bytes)
         << " quantized to 1/" << fmt(report_detail::kQuantizationSteps, "%.0f") << " of each scene and delta coded, "
         << kb(player_totals.packed_bytes) << " deflated, base64 in the page.</p>\n";
  }
  page << "<p class=ctx>Written by physval report from " << html(results_file.filename().string())
       << ". Plots drawn with gnuplot.</p>\n" << report_detail::player_script() << "</body></html>\n";

  say("report: drawing " + std::to_string(jobs.size()) + " plots with one gnuplot process");
  std::vector<std::string> errors;
  try {
    errors = plot::render_pngs(jobs);
  } catch (const std::exception& e) {   // gnuplot missing: every plot says why
    errors.assign(jobs.size(), e.what());
  }
  for (std::size_t i = 0; i < drawn.size(); ++i) {
    drawn[i].error = errors[i];
    if (!errors[i].empty()) failures.push_back(jobs[i].png.filename().string() + ": " + errors[i]);
  }
  write_file_atomically(dir / "report.html", fill_placeholders(page.str(), drawn));

  if (!failures.empty()) {
    std::string message = "report written to " + (dir / "report.html").string() + ", but " +
                          std::to_string(failures.size()) + " plot(s) could not be drawn:";
    for (const std::string& f : failures) message += "\n  " + f;
    throw plot::PlotError(message);
  }
}

}  // namespace physval
