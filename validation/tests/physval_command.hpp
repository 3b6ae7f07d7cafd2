// Runs the real physval executable for the command-line tests: its exit status and
// everything it printed (stdout and stderr together).
#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace physval_test {

struct Result {
  int status = -1;
  std::string output;   // stdout and stderr
};

inline Result physval(const std::string& args) {
  Result r;
  const std::string cmd = std::string(PHYSVAL_EXE) + " " + args + " 2>&1";
  FILE* p = ::popen(cmd.c_str(), "r");
  if (p == nullptr) return r;
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
  const int w = ::pclose(p);
  r.status = WIFEXITED(w) ? WEXITSTATUS(w) : -1;
  return r;
}

}  // namespace physval_test
