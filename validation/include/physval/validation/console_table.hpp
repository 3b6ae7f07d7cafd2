// The table `physval run` and `gate` print: one block per scenario, one row per engine,
// readable at 100 columns.
#pragma once

#include <ostream>

#include "physval/validation/suite.hpp"

namespace physval {

void print_suite_table(std::ostream& os, const SuiteResult& result);

}  // namespace physval
