// A RunRecord as bytes (CBOR), to carry it from an isolated engine process back to
// the runner.
#pragma once

#include <cstdint>
#include <vector>

#include "physval/validation/run_record.hpp"

namespace physval {

std::vector<std::uint8_t> encode_run_record(const RunRecord& r);
RunRecord decode_run_record(const std::vector<std::uint8_t>& bytes);   // throws on bad input

}  // namespace physval
