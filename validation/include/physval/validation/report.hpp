// The report a person opens: DIR/report.html, drawn from a results folder
// (DIR/results.json and DIR/series/<scenario>/<engine>.csv, as write_results leaves
// them). Per scenario: a metrics table per engine, and gnuplot pictures in DIR/plots/:
// energy over time (and its error on a log scale), momentum over time, the engines'
// trajectories overlaid on the reference's, and a contact timeline per engine against
// the reference. The page is self-contained HTML (inline style, no scripts) that links
// its PNGs by relative path, so the folder can be copied or archived whole.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "physval/validation/suite.hpp"

namespace physval {

// Writes DIR/report.html and DIR/plots/*.png. Throws std::runtime_error when
// DIR/results.json is missing or unreadable. When a plot cannot be drawn (gnuplot
// missing or failing) the page is still written, saying so where the plot would be,
// and then plot::PlotError is thrown naming every plot that failed.
void write_report(const std::filesystem::path& results_dir, const Progress& progress = {});

// The file name scenario and engine names get in series/ and plots/ (as write_results
// names them: characters other than [A-Za-z0-9_-] become '_').
std::string report_file_name(const std::string& name);

}  // namespace physval
