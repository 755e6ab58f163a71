#include "harness/charts.h"

#include <cstdio>
#include <cstdlib>
#include <spawn.h>
#include <sys/wait.h>
#include <vector>

extern char** environ;

namespace hairbench {

namespace {

// The chart scripts exit with this code, after one line, when it cannot import matplotlib.
constexpr int kNoMatplotlib = 3;

std::string later_command(const std::string& python, std::string_view name, const std::filesystem::path& report) {
  return (python.empty() ? std::string("/usr/bin/python3") : python) + " " + chart_script(name) + " " +
         report.string();
}

}  // namespace

std::string chart_python() {
  if (const char* env = std::getenv("HAIRBENCH_PYTHON"); env && *env) return env;
  return HAIRBENCH_PYTHON_DEFAULT;
}

std::string chart_script(std::string_view name) {
  return (std::filesystem::path(HAIRBENCH_CHART_SCRIPT).parent_path() / name).string();
}

int draw_charts(const std::filesystem::path& report, std::string_view name) {
  const std::string python = chart_python();
  const char* need = "a Python 3 interpreter that can import matplotlib (Debian: apt install python3-matplotlib, "
                     "which ci/bootstrap does)";
  if (python.empty()) {
    std::fprintf(stderr, "hairbench: charts not drawn: no Python 3 interpreter was found at configure time; install %s, then run: %s\n",
                 need, later_command(python, name, report).c_str());
    return 0;
  }
  std::fflush(stdout);
  const std::string script = chart_script(name);
  const std::string report_arg = report.string();
  std::vector<char*> argv = {const_cast<char*>(python.c_str()), const_cast<char*>(script.c_str()),
                             const_cast<char*>(report_arg.c_str()), nullptr};
  pid_t pid = 0;
  if (posix_spawn(&pid, python.c_str(), nullptr, nullptr, argv.data(), environ) != 0) {
    std::fprintf(stderr, "hairbench: charts not drawn: cannot start %s; install %s, then run: %s\n", python.c_str(),
                 need, later_command(python, name, report).c_str());
    return 0;
  }
  int status = 0;
  if (waitpid(pid, &status, 0) != pid || !WIFEXITED(status)) {
    std::fprintf(stderr, "hairbench: chart script did not finish; the report is %s\n", report_arg.c_str());
    return 1;
  }
  const int code = WEXITSTATUS(status);
  if (code == 0) return 0;
  // posix_spawn reports a missing file as exit 127 of the child.
  if (code == kNoMatplotlib || code == 127) {
    std::fprintf(stderr, "hairbench: charts not drawn: %s %s; install %s, then run: %s\n", python.c_str(),
                 code == 127 ? "cannot be run" : "cannot import matplotlib", need,
                 later_command(code == 127 ? "" : python, name, report).c_str());
    return 0;
  }
  std::fprintf(stderr, "hairbench: chart script failed (exit %d); the report is %s\n", code, report_arg.c_str());
  return 1;
}

}  // namespace hairbench
