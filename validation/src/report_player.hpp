// The report's scene player: each scenario's bodies and barriers on a <canvas>, every
// engine overlaid on the reference, played back in the browser. This side packs what
// the player needs into the page: the series resampled onto at most kMaxFrames frames,
// positions quantized to 1/8192 of the scene's extent, delta and varint coded,
// deflated (zlib) and base64'd; the barrier geometry and body radii from
// series/<scenario>/scene.json. Private to report.cpp.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "report_figures.hpp"

namespace physval::report_detail {

struct PlayerSection {
  std::string html;                // the player's markup and its embedded data
  std::size_t frames = 0;
  std::size_t bodies = 0;
  std::size_t raw_bytes = 0;       // the same numbers as float64 (what JSON or a binary dump would carry)
  std::size_t coded_bytes = 0;     // after quantization, deltas and varints
  std::size_t packed_bytes = 0;    // after deflate
  std::size_t embedded_bytes = 0;  // base64 text in the page
};

constexpr std::size_t kMaxFrames = 600;
constexpr double kQuantizationSteps = 8192.0;   // per the scene's largest extent

// `colours`: each engine's colour, as the plots draw it (by its place in `engines`).
PlayerSection player_section(const ScenarioView& v, const std::vector<std::string>& engines,
                             const std::string& anchor);

// The player's style and script, once per page (inline: no network).
std::string player_head();
std::string player_script();

// Base64 and zlib, exposed for the tests.
std::string base64(const std::string& bytes);
std::string deflate_zlib(const std::string& bytes);

}  // namespace physval::report_detail
