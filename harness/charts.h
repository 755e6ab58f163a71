// The chart step at the end of compare and sweep: runs reports/charts.py on the report
// with the Python interpreter found at configure time (HAIRBENCH_PYTHON; the python3 on
// PATH may lack matplotlib), or says exactly how to run it later.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace hairbench {

// The interpreter: $HAIRBENCH_PYTHON when set, else the one found at configure time
// ("" when none was found).
std::string chart_python();
// A chart script in reports/ of the source tree: charts.py draws compare and sweep
// reports, stress_chart.py the stress heatmap.
std::string chart_script(std::string_view name = "charts.py");

// Draws the charts of `report` next to it with script `name`. Returns 0 when drawn or
// when they cannot be drawn here (no interpreter, or it cannot import matplotlib: a
// one-line note on stderr says what to install and the command to run later); 1 when
// the script failed.
int draw_charts(const std::filesystem::path& report, std::string_view name = "charts.py");

}  // namespace hairbench
