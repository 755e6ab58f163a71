// Runs the hairbench binary (HAIRBENCH_EXE, set by the test's CMake target) and captures
// its exit code and output.
#pragma once

#include <cstdio>
#include <string>
#include <sys/wait.h>

namespace hairbench::test {

struct CliResult {
  int code;
  std::string out;
};

// `env` is prepended to the command line ("NAME=VALUE ..."); `streams` says what `out`
// captures: both streams by default, standard output alone with "2>/dev/null".
inline CliResult run_cli(const std::string& args, const std::string& env = "", const std::string& streams = "2>&1") {
  const std::string cmd = env + "\"" + HAIRBENCH_EXE + "\" " + args + " " + streams;
  CliResult r{-1, {}};
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, p)) r.out += buf;
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

}  // namespace hairbench::test
