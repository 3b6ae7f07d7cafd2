// A RunRecord as bytes, to carry it from an isolated engine process back to the runner
// (and into the reference cache). A flat binary stream of the record's own fields: the
// child writes it straight into the pipe through a small buffer, and the parent reads it
// straight into a RunRecord, so no intermediate tree or whole-message buffer holds a
// second copy of the series (what made the parent peak at several times the series'
// size on scenes of 100k bodies). The series travels as blocks (times, totals, the rows'
// sizes, the rows' states as they lie in memory), written from and read into place.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <vector>

#include "physval/validation/run_record.hpp"

namespace physval {

std::vector<std::uint8_t> encode_run_record(const RunRecord& r);
RunRecord decode_run_record(const std::vector<std::uint8_t>& bytes);   // throws on bad input

// Writes the record to a file descriptor (a pipe) through a 256 kB buffer (a series' blocks: straight from the record). False when a
// write fails.
bool write_run_record(int fd, const RunRecord& r);

// Reading a record from a file descriptor, waiting at most until `deadline`.
struct RecordTimeout : std::runtime_error {
  RecordTimeout() : std::runtime_error("timed out") {}
};
// Throws RecordTimeout at the deadline, std::runtime_error on a short or malformed
// stream. `bytes_read` says how much arrived (0: the writer sent nothing).
RunRecord read_run_record(int fd, std::optional<std::chrono::steady_clock::time_point> deadline,
                          std::size_t& bytes_read);
// The same, then one double the writer sent right after the record (a run worker's CPU
// for the run, see RunWorkers); nothing may follow it.
RunRecord read_run_record(int fd, std::optional<std::chrono::steady_clock::time_point> deadline,
                          std::size_t& bytes_read, double& after);

}  // namespace physval
