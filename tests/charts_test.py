#!/usr/bin/env python3
"""Chart-script test: runs reports/charts.py (and stress_chart.py) on the golden reports in tests/data/reports
and checks that every promised file exists and is non-empty, and that each chart drew
the series the report implies (counted from the report itself, not from the manifest).

usage: charts_test.py CHARTS_PY REPORTS_DIR   (exit 77 = skipped: no matplotlib)
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile

try:
    import matplotlib  # noqa: F401
except ImportError:
    print(f"SKIPPED: {sys.executable} cannot import matplotlib; install Debian's python3-matplotlib "
          f"(ci/bootstrap does) to test the chart scripts")
    sys.exit(77)

failures = []


def check(cond, what):
    if not cond:
        failures.append(what)


def run_on(charts_py, golden, tmp):
    report = os.path.join(tmp, os.path.basename(golden))
    shutil.copy(golden, report)
    r = subprocess.run([sys.executable, charts_py, report], capture_output=True, text=True)
    check(r.returncode == 0, f"{golden}: charts.py exit {r.returncode}: {r.stderr}")
    stem = os.path.splitext(report)[0]
    with open(stem + "_charts.json") as f:
        manifest = json.load(f)
    with open(golden) as f:
        rep = json.load(f)
    return rep, manifest, stem


def check_report(charts_py, golden, tmp):
    rep, m, stem = run_on(charts_py, golden, tmp)
    names = list(dict.fromkeys(r["scenario"] for r in rep["runs"]))
    # files: written, non-empty, PNG and SVG for each chart, the summary and the page
    for kind in ("time_vs_error", "timeseries", "stages"):
        files = m["charts"][kind]["files"]
        check(sorted(os.path.splitext(f)[1] for f in files) == [".png", ".svg"], f"{kind}: png+svg")
    expected = [f"{stem}_{k}.{e}" for k in ("time_vs_error", "timeseries", "stages") for e in ("png", "svg")]
    expected += [f"{stem}_strands_{n}.{e}" for n in names for e in ("png", "svg")]
    expected += [f"{stem}_summary.md", f"{stem}.html"]
    for f in expected:
        check(os.path.isfile(f) and os.path.getsize(f) > 0, f"missing or empty: {f}")
    with open(f"{stem}.png".replace(".png", "_time_vs_error.png"), "rb") as f:
        check(f.read(8) == b"\x89PNG\r\n\x1a\n", "time_vs_error.png is a PNG")
    page = open(f"{stem}.html", encoding="utf-8").read()
    check(page.count("data:image/png;base64,") == 3 + len(names), "report.html inlines every chart")
    check("src=\"http" not in page and "src='http" not in page, "report.html is self-contained")
    md = open(f"{stem}_summary.md", encoding="utf-8").read()
    check(md.count("\n| ") - md.count("\n| model") == len(rep["runs"]), "summary: one table row per run")

    for name in names:
        runs = [r for r in rep["runs"] if r["scenario"] == name]
        models = list(dict.fromkeys(r["model"] for r in runs))
        ok = [r for r in runs if r["status"] == "ok"]
        tve = next(p for p in m["charts"]["time_vs_error"]["panels"] if p["scenario"] == name)
        # one line per model with a stable run, through one point per stable knob value
        check([s["model"] for s in tve["series"]] == [x for x in models if any(r["model"] == x for r in ok)],
              f"{name}: time_vs_error series {tve['series']}")
        check(sum(s["points"] for s in tve["series"]) == len(ok), f"{name}: one point per stable run")
        check(len(tve["unstable"]) == len(runs) - len(ok), f"{name}: unstable runs listed")
        # the Pareto front: non-empty, non-dominated, and every other stable run dominated by it
        front = [(p["step_ms"], p["deviation"]) for p in tve["pareto"]]
        check(bool(front) or not ok, f"{name}: Pareto front empty")
        for r in ok:
            pt = (r["timing"]["step_ms"]["median"], r["metrics"]["deviation_vs_reference"]["rms"])
            if pt in front:
                check(not any(q[0] <= pt[0] and q[1] <= pt[1] and q != pt for q in front), f"{name}: {pt} dominated")
            else:
                check(any(q[0] <= pt[0] and q[1] <= pt[1] for q in front), f"{name}: {pt} off the front, undominated")
        ts = next(p for p in m["charts"]["timeseries"]["panels"] if p["scenario"] == name)
        check(ts["deviation_vs_reference"] == len(runs) and ts["jaggedness"] == len(runs), f"{name}: timeseries lines")
        info = next(s for s in rep["scenarios"] if s["name"] == name)
        check(ts["phases"] == len(info["phases"]), f"{name}: phases shaded")
        st = next(p for p in m["charts"]["stages"]["panels"] if p["scenario"] == name)
        check(st["bars"] == len(runs), f"{name}: one bar per run")
        check({"integrate", "length", "local_shape"} <= set(st["stages"]), f"{name}: stages {st['stages']}")
        sp = next(p for p in m["charts"]["strands"] if p["scenario"] == name)
        check(sp["frames"] == ["most_violent", "final"], f"{name}: strand frames {sp['frames']}")
        check(sp["panels"] == 2 * len(sp["columns"]), f"{name}: 2 frames x columns panels")
        # the reference gets its own column when no run is the reference itself
        shares_ref = any(r["model"] == info["snapshots"]["reference"]["model"]
                         and r["metrics"]["deviation_vs_reference"]["max"] == 0 for r in runs)
        check(len(sp["columns"]) == len(runs) + (0 if shares_ref else 1), f"{name}: strand columns {sp['columns']}")
        n = len(info["snapshots"]["strands"])
        for count in sp["strands_per_panel"]:
            check(count in (0, n), f"{name}: a panel draws all {n} snapshot strands or none (unreached)")
        check(sp["max_deviation"] > 0, f"{name}: strands coloured by a non-zero deviation")
    return rep, m


def check_stress(stress_py, golden, tmp):
    """The `hairbench stress` heatmap: PNG and SVG written next to the report."""
    report = os.path.join(tmp, "stress.json")
    shutil.copy(golden, report)
    r = subprocess.run([sys.executable, stress_py, report], capture_output=True, text=True)
    check(r.returncode == 0, f"stress_chart.py exit {r.returncode}: {r.stderr}")
    for ext in ("png", "svg"):
        f = os.path.join(tmp, f"stress_heatmap.{ext}")
        check(os.path.isfile(f) and os.path.getsize(f) > 0, f"missing or empty: {f}")
    with open(os.path.join(tmp, "stress_heatmap.png"), "rb") as f:
        check(f.read(8) == b"\x89PNG\r\n\x1a\n", "stress_heatmap.png is a PNG")


def main():
    charts_py, data = sys.argv[1], sys.argv[2]
    with tempfile.TemporaryDirectory() as tmp:
        rep, m = check_report(charts_py, os.path.join(data, "compare_report.json"), tmp)
        check(len(m["charts"]["strands"]) == 2, "compare: one strand picture per scenario")
        rep, m = check_report(charts_py, os.path.join(data, "sweep_report.json"), tmp)
        unreached = [c for c in m["charts"]["strands"][0]["strands_per_panel"] if c == 0]
        check(len(unreached) >= 2, "sweep: the unstable runs' final frames are drawn as unreached")
        # a report the script cannot read: exit 2, one line
        bad = os.path.join(tmp, "bad.json")
        with open(bad, "w") as f:
            f.write('{"schema": "something-else", "runs": []}')
        r = subprocess.run([sys.executable, charts_py, bad], capture_output=True, text=True)
        check(r.returncode == 2 and r.stderr.count("\n") == 1 and "schema" in r.stderr, f"bad report: {r.stderr}")
        check_stress(os.path.join(os.path.dirname(charts_py), "stress_chart.py"),
                     os.path.join(data, "stress_small.json"), tmp)
    for f in failures:
        print("FAILED:", f)
    print(f"{'FAIL' if failures else 'ok'}: charts_test")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
