// Errors in a user's input, each naming the file, line, column and key at fault.
#pragma once

#include <string>
#include <vector>

namespace physval {

struct Diagnostic {
  std::string file;
  int line = 0;      // 1-based; 0 when unknown
  int column = 0;    // 1-based; 0 when unknown
  std::string key;   // dotted path of the key at fault, e.g. "bodies[1].mass"
  std::string message;
  // "file:line:column: key: message"
  std::string str() const;
};

using Diagnostics = std::vector<Diagnostic>;

}  // namespace physval
