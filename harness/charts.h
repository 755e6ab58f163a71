// The chart step at the end of compare and sweep: runs reports/charts.py on the report
// with the Python interpreter found at configure time (HAIRBENCH_PYTHON; the python3 on
// PATH may lack matplotlib), or says exactly how to run it later.
#pragma once

#include <filesystem>
#include <string>

namespace hairbench {

// The interpreter: $HAIRBENCH_PYTHON when set, else the one found at configure time
// ("" when none was found).
std::string chart_python();
// The chart script (reports/charts.py in the source tree).
std::string chart_script();

// Draws the charts next to `report`. Returns 0 when drawn or when they cannot be drawn
// here (no interpreter, or it cannot import matplotlib: a one-line note on stderr says
// what to install and the command to run later); 1 when the script failed.
int draw_charts(const std::filesystem::path& report);

}  // namespace hairbench
