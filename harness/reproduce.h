// `hairbench reproduce`: runs the configurations behind the papers' published
// tables (reports/published/*.json) on this machine and writes a report with, per row,
// the published value, the measured one, and the comparison that survives a change of
// hardware (ratios between methods, growth with size, time shares), each with a verdict.
// The papers' qualitative claims become checks of the same form.
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace hairbench {

inline constexpr const char* kReproducePapers[] = {"han2012", "halen2007", "plante2001"};

struct ReproduceOptions {
  std::vector<std::string> papers;  // in kReproducePapers order
  int frames = 0;                   // > 0: every run stops after this many frames (quick runs)
  int threads = 0;                  // 0: every hardware thread
  std::string device;               // Vulkan device for Han & Harada's GPU table
  std::filesystem::path out = "reports/out/reproduce";
};

// The tables named on the command line (each of kReproducePapers or "all") as
// ReproduceOptions::papers, in kReproducePapers order; throws InputError naming a bad one.
std::vector<std::string> select_papers(const std::vector<std::string>& names);

// One comparison or claim: it holds when `measured` is finite and within [min, max]
// (either bound may be open). The verdict is computed from these fields only, so a
// reader can recompute it from the JSON.
struct ReproduceCheck {
  std::string id{}, claim{}, quantity{};
  std::optional<double> published{};  // the paper's value of the quantity, when it gives one
  std::string published_text{};       // how the paper states it, when not a single number
  double measured = 0.0;
  std::optional<double> min{}, max{};
  std::string detail{};        // the measured values the quantity was computed from
  std::string why_differs{};   // the likely cause, reported only when it differs
};
nlohmann::json check_json(const ReproduceCheck& c);

// Runs the selected papers; `log` gets one line per configuration as it starts.
nlohmann::json run_reproduce(const ReproduceOptions& opt, const std::function<void(const std::string&)>& log);

// The report as Markdown, and as one self-contained HTML page.
std::string reproduce_markdown(const nlohmann::json& report);
std::string reproduce_html(const nlohmann::json& report);

// The command: run, write OUT/reproduce.{json,md,html}, print the verdict table.
int cmd_reproduce(const ReproduceOptions& opt);

}  // namespace hairbench
