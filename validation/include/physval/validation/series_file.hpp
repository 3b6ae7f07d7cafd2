// A run's time series as `physval run` leaves it in DIR/series/<scenario>/<engine>.bin
// (README, "Series files"): the columns t, energy, kinetic, potential, px, py,
// angular_momentum, then x_<body>, y_<body> of each body (at most kMaxBodiesInSeries;
// NaN where a body is not alive or not there), one row a sample. The file holds the
// doubles themselves (no text to make, half the bytes of the CSV), so that writing it costs
// about what copying it does; `--series-csv` writes DIR/series/.../<engine>.csv instead,
// and `physval series-csv DIR` turns .bin files into the same CSV, byte for byte.
//
// Layout: a first line "physval-series 1 ROWS COLUMNS\n", the CSV's header line (the
// column names joined by commas) padded with spaces to end at a multiple of 8 bytes and
// ended by "\n", then ROWS x COLUMNS IEEE-754 doubles, little-endian, row after row.
// numpy: np.fromfile(f, "<f8", offset=o).reshape(ROWS, COLUMNS), o = the second line's end.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "physval/validation/run_record.hpp"

namespace physval {

// The report's scene player draws every body, so the series hold up to this many.
constexpr std::size_t kMaxBodiesInSeries = 400;

enum class SeriesFormat { Binary, Csv };

// A series as rows of doubles (row-major), with its column names.
struct SeriesTable {
  std::vector<std::string> names;
  std::size_t rows = 0;
  std::vector<double> values;   // rows x names.size()
};

// The CSV header line of a run's series (column names joined by commas, no newline).
std::string series_header(const RunRecord& r);
// The run's series values, row-major, into `out` (resized): columns as series_header names.
// Returns the column count.
std::size_t series_values(const RunRecord& r, std::vector<double>& out);

// The CSV text of a series: the header line, then each row's numbers as %.12g ("nan" for
// NaN), comma-separated, each row ended by "\n". What `--series-csv` writes.
// write_series_csv writes it from `o` on (room for series_csv_capacity bytes) and returns
// its end; append_series_csv appends it to a string.
std::size_t series_csv_capacity(std::size_t header_size, std::size_t rows, std::size_t columns);
char* write_series_csv(char* o, std::string_view header, const double* values, std::size_t rows, std::size_t columns);
void append_series_csv(std::string& out, std::string_view header, const double* values, std::size_t rows,
                       std::size_t columns);
// The .bin file's two text lines (layout above), which the doubles follow.
std::string series_binary_prefix(std::string_view header, std::size_t rows, std::size_t columns);
// The .bin file's bytes for a series (layout above).
void append_series_binary(std::string& out, std::string_view header, const double* values, std::size_t rows,
                          std::size_t columns);

// Reads a .bin series file (nullopt: no such file; throws std::runtime_error when it is
// not a well-formed series file).
std::optional<SeriesTable> read_series_binary(const std::filesystem::path& file);

// `physval series-csv DIR`: beside every DIR/series/<scenario>/<label>.bin, its CSV
// <label>.csv (what --series-csv would have written). Returns the files written.
std::size_t convert_series_to_csv(const std::filesystem::path& dir);

}  // namespace physval
