// The reproduce report as Markdown and as one self-contained HTML page: three summary
// tables (claims, setup, measurements: counted apart), then per paper each claim with the
// paper's sentence, the settings it ran at, why its bounds, and its chart.
#include "harness/reproduce.h"

#include "harness/reproduce/rows.h"

#include <fstream>
#include <sstream>

namespace hairbench {

using nlohmann::json;
using reproduce::num;

namespace {

std::string jnum_str(const json& v) { return v.is_number() ? num(v.get<double>()) : "-"; }

std::string bounds(const json& c) {
  const json& lo = c["holds_if"]["min"];
  const json& hi = c["holds_if"]["max"];
  if (c["verdict"] == "not testable") return "-";
  if (!lo.is_null() && !hi.is_null()) return jnum_str(lo) + " to " + jnum_str(hi);
  if (!lo.is_null()) return ">= " + jnum_str(lo);
  if (!hi.is_null()) return "<= " + jnum_str(hi);
  return "-";
}

std::string values(const json& v) {
  std::string s;
  for (const json& x : v) s += (s.empty() ? "" : ", ") + jnum_str(x);
  return s;
}

// A claim's published or measured cell: its plain numbers first (the absolute values a
// reader compares with the paper's), then the tested quantity the verdict reads.
std::string claim_value(const json& c, const char* which) {
  const std::string tested = jnum_str(c[which]);
  if (!c.contains("numbers") || c["numbers"].empty()) return tested;
  std::string s;
  for (const json& n : c["numbers"]) s += (s.empty() ? "" : ", ") + n["label"].get<std::string>() + " " + jnum_str(n[which]);
  return s + "; tested " + tested;
}

// The same numbers as one line of the claim's details ("" when it has none).
std::string numbers_line(const json& c) {
  if (!c.contains("numbers") || c["numbers"].empty()) return "";
  std::string s;
  for (const json& n : c["numbers"])
    s += (s.empty() ? "" : ", ") + n["label"].get<std::string>() + " " + jnum_str(n["measured"]) + " (published " +
         jnum_str(n["published"]) + ")";
  return s;
}

std::string joined(const json& v) {
  std::string s;
  for (const json& x : v) s += (s.empty() ? "" : ", ") + x.get<std::string>();
  return s;
}

std::string chart_name(const json& paper, const json& claim) {
  return paper["id"].get<std::string>() + "_" + claim["id"].get<std::string>() + ".png";
}

std::string md_cell(std::string s) {
  for (std::size_t i = 0; (i = s.find('|', i)) != std::string::npos; i += 2) s.replace(i, 1, "\\|");
  for (char& ch : s)
    if (ch == '\n') ch = ' ';
  return s;
}

std::string html_escape(const std::string& s) {
  std::string o;
  for (char ch : s) {
    switch (ch) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      default: o += ch;
    }
  }
  return o;
}

std::string base64(const std::string& bytes) {
  static constexpr char k[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string o;
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) | (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                       static_cast<unsigned char>(bytes[i + 2]);
    o += {k[v >> 18], k[(v >> 12) & 63], k[(v >> 6) & 63], k[v & 63]};
  }
  if (i + 1 == bytes.size()) {
    const unsigned v = static_cast<unsigned char>(bytes[i]) << 16;
    o += {k[v >> 18], k[(v >> 12) & 63], '=', '='};
  } else if (i + 2 == bytes.size()) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) | (static_cast<unsigned char>(bytes[i + 1]) << 8);
    o += {k[v >> 18], k[(v >> 12) & 63], k[(v >> 6) & 63], '='};
  }
  return o;
}

std::string context_line(const json& r) {
  const json& ctx = r["context"];
  std::ostringstream o;
  o << ctx["cpu"].get<std::string>() << ", " << ctx["threads"] << " of " << ctx["hardware_threads"]
    << " hardware threads; load average " << jnum_str(r["load_average"]["start"]) << " at start, "
    << jnum_str(r["load_average"]["end"]) << " at end; git " << ctx["git_sha"].get<std::string>() << "; wall time "
    << num(r["wall_s"].get<double>()) << " s"
    << (r["frames_cap"].is_null() ? "" : "; frames capped at " + std::to_string(r["frames_cap"].get<int>()) +
                                             " (a quick run: the verdicts are not the papers' settings')");
  return o.str();
}

std::string counts_line(const json& r) {
  const json& s = r["summary"];
  std::ostringstream o;
  o << "Claims: " << s["claims"]["holds"] << " hold, " << s["claims"]["differs"] << " differ, "
    << s["claims"]["not_testable"] << " not testable here. Setup: " << s["setup"]["matches"] << " of "
    << s["setup"]["matches"].get<int>() + s["setup"]["mismatches"].get<int>()
    << " rows match the papers' configuration (a setup row is never counted as a claim). Measurements: "
    << s["measurements"] << " hardware-dependent numbers beside the papers' (no verdict).";
  return o.str();
}

}  // namespace

std::string reproduce_markdown(const json& r) {
  std::ostringstream o;
  o << "# hairbench reproduce\n\n" << context_line(r) << "\n\n" << counts_line(r) << "\n";
  o << "\n## Claims\n\n| paper | claim | the paper says | quantity | published | measured | holds if | verdict | "
       "reason |\n|---|---|---|---|---:|---:|---|---|---|\n";
  for (const json& p : r["papers"])
    for (const json& c : p["claims"])
      o << "| " << p["id"].get<std::string>() << " | " << c["id"].get<std::string>() << " | "
        << md_cell(c["source"]["quote"].get<std::string>() + " (" + c["source"]["where"].get<std::string>() + ")")
        << " | " << md_cell(c["quantity"]) << " | " << md_cell(claim_value(c, "published")) << " | "
        << md_cell(claim_value(c, "measured"))
        << " | " << bounds(c) << " | " << c["verdict"].get<std::string>() << " | " << md_cell(c["reason"]) << " |\n";
  o << "\n## Setup\n\n| paper | setup | the paper | this run | verdict |\n|---|---|---|---|---|\n";
  for (const json& p : r["papers"])
    for (const json& s : p["setups"])
      o << "| " << p["id"].get<std::string>() << " | " << md_cell(s["id"].get<std::string>() + ": " + s["what"].get<std::string>())
        << " | " << md_cell(s["published"]) << " | " << md_cell(s["measured"]) << " | " << s["verdict"].get<std::string>()
        << " |\n";
  o << "\n## Measurements\n\n| paper | measurement | columns | published | measured | unit |\n|---|---|---|---|---|---|\n";
  for (const json& p : r["papers"])
    for (const json& m : p["measurements"])
      o << "| " << p["id"].get<std::string>() << " | " << md_cell(m["id"].get<std::string>() + ": " + m["what"].get<std::string>())
        << " | " << md_cell(joined(m["columns"])) << " | " << values(m["published"]) << " | " << values(m["measured"])
        << " | " << md_cell(m["unit"]) << " |\n";

  o << "\n## Details\n";
  for (const json& p : r["papers"]) {
    o << "\n### " << p["id"].get<std::string>() << ": " << p["paper"].get<std::string>() << "\n";
    for (const json& c : p["claims"]) {
      o << "\n#### " << c["id"].get<std::string>() << ": " << c["verdict"].get<std::string>() << "\n\n> "
        << c["source"]["quote"].get<std::string>() << " (" << c["source"]["where"].get<std::string>() << ")\n\n";
      if (const std::string n = numbers_line(c); !n.empty()) o << "- beside the paper's: " << n << "\n";
      o << "- settings: " << c["settings"].get<std::string>() << "\n- quantity: " << c["quantity"].get<std::string>()
        << " = " << jnum_str(c["measured"]) << " (published " << jnum_str(c["published"]) << "; holds if "
        << bounds(c) << ")\n- why these bounds: " << c["threshold_why"].get<std::string>() << "\n- measured: "
        << c["detail"].get<std::string>() << "\n";
      if (!c["reason"].get<std::string>().empty()) o << "- reason: " << c["reason"].get<std::string>() << "\n";
      if (!c["chart"].is_null()) o << "\n![" << c["chart"]["title"].get<std::string>() << "](charts/" << chart_name(p, c) << ")\n";
    }
    for (const json& m : p["measurements"])
      if (!m["note"].get<std::string>().empty())
        o << "\n- measurement " << m["id"].get<std::string>() << ": " << m["note"].get<std::string>() << "\n";
    for (const json& s : p["setups"])
      if (!s["note"].get<std::string>().empty())
        o << "\n- setup " << s["id"].get<std::string>() << ": " << s["note"].get<std::string>() << "\n";
  }
  return o.str();
}

std::string reproduce_html(const json& r, const std::filesystem::path& charts_dir) {
  std::ostringstream o;
  auto e = [](const json& s) { return html_escape(s.is_string() ? s.get<std::string>() : s.dump()); };
  auto es = [](const std::string& s) { return html_escape(s); };
  auto verdict = [&](const json& row) {
    std::string v = row["verdict"];
    std::string cls = v;
    for (char& ch : cls)
      if (ch == ' ') ch = '_';
    return "<td class=\"" + cls + "\">" + es(v) + "</td>";
  };
  o << "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>hairbench reproduce</title>\n<style>"
       "body{font-family:sans-serif;margin:2em;max-width:90em}table{border-collapse:collapse;margin:1em 0}"
       "td,th{border:1px solid #ccc;padding:.25em .5em;text-align:left;vertical-align:top}"
       "td.holds,td.matches{background:#d8f5d8}td.differs,td.mismatch{background:#f9dcdc}"
       "td.not_testable{background:#eee}.note{color:#555}blockquote{border-left:3px solid #ccc;margin-left:0;"
       "padding-left:1em}</style></head><body>\n";
  o << "<h1>hairbench reproduce</h1>\n<p class=\"note\">" << es(context_line(r)) << "</p>\n<p>" << es(counts_line(r))
    << "</p>\n";
  o << "<h2>Claims</h2>\n<table><tr><th>paper</th><th>claim</th><th>the paper says</th><th>quantity</th>"
       "<th>published</th><th>measured</th><th>holds if</th><th>verdict</th><th>reason</th></tr>\n";
  for (const json& p : r["papers"])
    for (const json& c : p["claims"])
      o << "<tr><td>" << e(p["id"]) << "</td><td><a href=\"#" << e(p["id"]) << "_" << e(c["id"]) << "\">" << e(c["id"])
        << "</a></td><td>" << e(c["source"]["quote"]) << " (" << e(c["source"]["where"]) << ")</td><td>"
        << e(c["quantity"]) << "</td><td>" << es(claim_value(c, "published")) << "</td><td>"
        << es(claim_value(c, "measured")) << "</td><td>" << es(bounds(c)) << "</td>" << verdict(c) << "<td>"
        << e(c["reason"]) << "</td></tr>\n";
  o << "</table>\n<h2>Setup</h2>\n<p class=\"note\">Whether the runs are the papers' configuration; never counted "
       "as a claim.</p>\n<table><tr><th>paper</th><th>setup</th><th>the paper</th><th>this run</th><th>verdict</th>"
       "</tr>\n";
  for (const json& p : r["papers"])
    for (const json& s : p["setups"])
      o << "<tr><td>" << e(p["id"]) << "</td><td>" << e(s["id"]) << ": " << e(s["what"]) << "</td><td>"
        << e(s["published"]) << "</td><td>" << e(s["measured"]) << "</td>" << verdict(s) << "</tr>\n";
  o << "</table>\n<h2>Measurements</h2>\n<p class=\"note\">Numbers that depend on the machine or on the papers' "
       "code, beside the papers'; no verdict.</p>\n<table><tr><th>paper</th><th>measurement</th><th>columns</th>"
       "<th>published</th><th>measured</th><th>unit</th><th>note</th></tr>\n";
  for (const json& p : r["papers"])
    for (const json& m : p["measurements"])
      o << "<tr><td>" << e(p["id"]) << "</td><td>" << e(m["id"]) << ": " << e(m["what"]) << "</td><td>"
        << es(joined(m["columns"])) << "</td><td>" << es(values(m["published"])) << "</td><td>"
        << es(values(m["measured"])) << "</td><td>" << e(m["unit"]) << "</td><td>" << e(m["note"]) << "</td></tr>\n";
  o << "</table>\n";
  for (const json& p : r["papers"]) {
    o << "<h2>" << e(p["id"]) << ": " << e(p["paper"]) << "</h2>\n";
    for (const json& c : p["claims"]) {
      o << "<h3 id=\"" << e(p["id"]) << "_" << e(c["id"]) << "\">" << e(c["id"]) << ": " << e(c["verdict"])
        << "</h3>\n<blockquote>" << e(c["source"]["quote"]) << " (" << e(c["source"]["where"]) << ")</blockquote>\n<ul>";
      if (const std::string n = numbers_line(c); !n.empty()) o << "<li>beside the paper's: " << es(n) << "</li>";
      o << "<li>settings: " << e(c["settings"]) << "</li><li>quantity: " << e(c["quantity"]) << " = "
        << es(jnum_str(c["measured"])) << " (published " << es(jnum_str(c["published"])) << "; holds if "
        << es(bounds(c)) << ")</li><li>why these bounds: " << e(c["threshold_why"]) << "</li><li>measured: "
        << e(c["detail"]) << "</li>";
      if (!c["reason"].get<std::string>().empty()) o << "<li>reason: " << e(c["reason"]) << "</li>";
      o << "</ul>\n";
      if (!c["chart"].is_null()) {
        std::ifstream in(charts_dir / chart_name(p, c), std::ios::binary);
        if (in) {
          std::stringstream bytes;
          bytes << in.rdbuf();
          o << "<img alt=\"" << e(c["chart"]["title"]) << "\" src=\"data:image/png;base64," << base64(bytes.str())
            << "\">\n";
        }
      }
    }
  }
  o << "</body></html>\n";
  return o.str();
}

}  // namespace hairbench
