#!/usr/bin/env python3
"""Chart-script test: runs reports/charts.py (and stress_chart.py) on the golden reports in tests/data/reports
and checks that every promised file exists and is non-empty, that each chart drew
the series the report implies (counted from the report itself, not from the manifest),
and what a person sees: no two tick labels of any axis of any figure overlap (rendered with
Agg), every image of the page decodes as a PNG, the page opens on the overview table (one
row per model, one column per scenario), and the outputs stay small.

usage: charts_test.py CHARTS_PY REPORTS_DIR   (exit 77 = skipped: no matplotlib)
"""
import base64
import contextlib
import importlib.util
import io
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile

try:
    import matplotlib

    matplotlib.use("Agg")
    from PIL import Image
except ImportError:
    print(f"SKIPPED: {sys.executable} cannot import matplotlib; install Debian's python3-matplotlib "
          f"(ci/bootstrap does) to test the chart scripts")
    sys.exit(77)

failures = []


def check(cond, what):
    if not cond:
        failures.append(what)


def load_charts(charts_py):
    spec = importlib.util.spec_from_file_location("charts_under_test", charts_py)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def overlapping_tick_labels(fig):
    """Pairs of visible, non-empty tick labels on one axis whose rendered boxes intersect."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    clashes = []
    for ax in fig.axes:
        if not ax.get_visible():
            continue
        for axis in (ax.xaxis, ax.yaxis):
            lo, hi = sorted(axis.get_view_interval())
            boxes = []
            for tick in axis.get_major_ticks() + axis.get_minor_ticks():
                label = tick.label1
                loc = tick.get_loc()
                if loc is None or not (lo <= loc <= hi) or not label.get_visible() or not label.get_text():
                    continue
                boxes.append((label.get_text(), label.get_window_extent(renderer)))
            for i in range(len(boxes)):
                for j in range(i + 1, len(boxes)):
                    a, b = boxes[i][1], boxes[j][1]
                    w = min(a.x1, b.x1) - max(a.x0, b.x0)
                    h = min(a.y1, b.y1) - max(a.y0, b.y0)
                    if w > 0.5 and h > 0.5:
                        clashes.append(f"{ax.get_title().splitlines()[0] if ax.get_title() else '?'}: "
                                       f"{boxes[i][0]!r} and {boxes[j][0]!r}")
    return clashes


def run_on(charts_py, golden, tmp, out=None, extra=()):
    """charts.py in this process, every figure checked for overlapping tick labels as it
    is saved (its `save` wrapped)."""
    report = os.path.join(tmp, os.path.basename(golden))
    shutil.copy(golden, report)
    mod = load_charts(charts_py)
    original = mod.save

    def checked_save(fig, out_dir, stem, name, *rest, **kw):
        for clash in overlapping_tick_labels(fig):
            check(False, f"{os.path.basename(golden)}: {name}: tick labels overlap: {clash}")
        return original(fig, out_dir, stem, name, *rest, **kw)

    mod.save = checked_save
    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        try:
            code = mod.main([report, *(["--out-dir", out] if out else []), *extra])
        except SystemExit as e:  # argparse refusing an option
            code = e.code
    check(code == 0, f"{golden}: charts.py exit {code}: {err.getvalue()}")
    stem = os.path.join(out or tmp, os.path.splitext(os.path.basename(report))[0])
    with open(stem + "_charts.json") as f:
        manifest = json.load(f)
    with open(golden) as f:
        rep = json.load(f)
    return rep, manifest, stem


def check_page(page, rep):
    """Every <img> a decodable PNG; the overview the first table, a row per model (run
    label) and a column per scenario, each cell naming the verdict."""
    imgs = re.findall(r"<img[^>]*\ssrc=\"([^\"]*)\"", page)
    check(len(imgs) == page.count("<img"), "every <img> has a src")
    for src in imgs:
        check(src.startswith("data:image/png;base64,"), f"img is an inline PNG: {src[:40]}")
        data = base64.b64decode(src.split(",", 1)[1], validate=True)
        try:
            with Image.open(io.BytesIO(data)) as im:
                check(im.format == "PNG", f"img is {im.format}")
                im.load()
                check(im.size[0] > 100 and im.size[1] > 100, f"img size {im.size}")
        except OSError as e:
            check(False, f"img does not decode: {e}")
    tables = re.findall(r"<table[^>]*>.*?</table>", page, re.S)
    first_is_overview = bool(tables) and "class='overview'" in tables[0]
    check(first_is_overview, "the overview is the first table")
    if not first_is_overview:
        return
    check(page.index("<table") < page.index("<img"), "the overview comes before any chart")
    rows = re.findall(r"<tr>(.*?)</tr>", tables[0], re.S)
    names = list(dict.fromkeys(r["scenario"] for r in rep["runs"]))
    labels = list(dict.fromkeys(r["model"] + (f" {r['knob']['name']}={r['knob']['value']:g}" if "knob" in r else "")
                                for r in rep["runs"]))
    header = re.findall(r"<th>(.*?)</th>", rows[0])
    check(header[1:] == names, f"overview columns {header[1:]} != scenarios {names}")
    check([re.findall(r"<th>(.*?)</th>", r)[:1] for r in rows[1:]] == [[x] for x in labels],
          "overview: one row per model")
    for r in rows[1:]:
        check(len(re.findall(r"<td", r)) == len(names), "overview: a cell per scenario")
    statuses = {r["status"] for r in rep["runs"]}
    for st in statuses:
        check(st in tables[0], f"overview shows the verdict {st}")


def check_report(charts_py, golden, tmp):
    rep, m, stem = run_on(charts_py, golden, tmp)
    names = list(dict.fromkeys(r["scenario"] for r in rep["runs"]))
    # files: written, non-empty, PNG only for each chart (SVG only when asked), the summary and the page
    for kind in ("time_vs_error", "timeseries", "stages"):
        files = m["charts"][kind]["files"]
        check([os.path.splitext(f)[1] for f in files] == [".png"], f"{kind}: png only by default")
    expected = [f"{stem}_{k}.png" for k in ("time_vs_error", "timeseries", "stages")]
    expected += [f"{stem}_strands_{n}.png" for n in names]
    expected += [f"{stem}_summary.md", f"{stem}.html"]
    for f in expected:
        check(os.path.isfile(f) and os.path.getsize(f) > 0, f"missing or empty: {f}")
    check(not [f for f in os.listdir(os.path.dirname(stem)) if f.endswith(".svg")], "no SVG unless asked")
    with open(f"{stem}.png".replace(".png", "_time_vs_error.png"), "rb") as f:
        check(f.read(8) == b"\x89PNG\r\n\x1a\n", "time_vs_error.png is a PNG")
    page = open(f"{stem}.html", encoding="utf-8").read()
    check(page.count("data:image/png;base64,") == 3 + len(names), "report.html inlines every chart")
    check("src=\"http" not in page and "src='http" not in page, "report.html is self-contained")
    check_page(page, rep)
    md = open(f"{stem}_summary.md", encoding="utf-8").read()
    check(md.count("\n| ") - md.count("\n| model") == len(rep["runs"]), "summary: one table row per run")
    # small: the charts, summary and page of a golden report (6-12 runs of 160-192 vertices)
    outputs = sum(os.path.getsize(f) for f in expected)
    check(outputs < 600_000, f"outputs {outputs} bytes")
    check(os.path.getsize(f"{stem}.html") < 400_000, f"page {os.path.getsize(stem + '.html')} bytes")
    # one colour per stage name, none shared
    for p in m["charts"]["stages"]["panels"]:
        colours = p.get("colours", {})
        check(len(colours) == len(p["stages"]) and len(set(colours.values())) == len(colours),
              f"{p['scenario']}: one distinct colour per stage: {colours}")
    # the snapshots decode to the positions the deviation series was measured from
    lbar = {s["name"]: s["mean_strand_length"] for s in rep["scenarios"]}
    mod = load_charts(charts_py)
    for s in rep["scenarios"]:
        ref = {x["label"]: x for x in s["snapshots"]["reference"]["snapshots"]}
        for r in (r for r in rep["runs"] if r["scenario"] == s["name"]):
            for snap in r["snapshots"]:
                if not snap["strands"]:
                    continue
                sq = n = 0
                ref_flat = [mod.decode_strand(c) for c in ref[snap["label"]]["strands"]]
                for a, b in zip(mod.snapshot_strands(snap, ref_flat), ref_flat):
                    for p, q in zip(a, mod.points(b)):
                        sq += math.dist(p, q) ** 2
                        n += 1
                dev = math.sqrt(sq / n) / lbar[s["name"]]
                want = r["series"]["deviation_vs_reference"][snap["frame"]]
                check(abs(dev - want) < 1e-4, f"{s['name']} {r['model']} {snap['label']}: snapshot deviation "
                      f"{dev} != series {want}")

    for name in names:
        runs = [r for r in rep["runs"] if r["scenario"] == name]
        models = list(dict.fromkeys(r["model"] for r in runs))
        ok = [r for r in runs if r["status"] == "ok"]
        # every run that went to the end is drawn (stretched and unstable ones marked); the
        # runs that diverged (schema 1: "unstable" with a failure) are listed instead
        drawn = [r for r in runs if not mod.diverged(r)]
        tve = next(p for p in m["charts"]["time_vs_error"]["panels"] if p["scenario"] == name)
        check([s["model"] for s in tve["series"]] == [x for x in models if any(r["model"] == x for r in drawn)],
              f"{name}: time_vs_error series {tve['series']}")
        check(sum(s["points"] for s in tve["series"]) == len(drawn), f"{name}: one point per run that ran through")
        check(len(tve["diverged"]) == len(runs) - len(drawn), f"{name}: diverged runs listed")
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


def check_precision(precision_py, golden, tmp):
    """The `hairbench precision` diagram: a PNG next to the report; a report without its
    "precision" object is refused in one line."""
    report = os.path.join(tmp, "precision.json")
    shutil.copy(golden, report)
    r = subprocess.run([sys.executable, precision_py, report], capture_output=True, text=True)
    check(r.returncode == 0, f"precision_chart.py exit {r.returncode}: {r.stderr}")
    png = os.path.join(tmp, "precision.png")
    check(os.path.isfile(png) and os.path.getsize(png) > 0, f"missing or empty: {png}")
    with open(png, "rb") as f:
        check(f.read(8) == b"\x89PNG\r\n\x1a\n", "precision.png is a PNG")
    bad = os.path.join(tmp, "not_precision.json")
    with open(bad, "w", encoding="utf-8") as f:
        json.dump({"runs": []}, f)
    r = subprocess.run([sys.executable, precision_py, bad], capture_output=True, text=True)
    check(r.returncode != 0 and "not a precision report" in r.stderr and r.stderr.count("\n") == 1,
          f"a report without precision: exit {r.returncode}, {r.stderr!r}")


def check_asleep(charts_py, golden, tmp):
    """A scenario where one model sleeps (1e-5 ms a step) and another takes 4 ms: the time
    axis is not stretched over the sleeper's decades and its labels stay apart."""
    rep, m, stem = run_on(charts_py, golden, tmp)
    for p in m["charts"]["time_vs_error"]["panels"]:
        sleepers = [r["model"] for r in rep["runs"] if r["scenario"] == p["scenario"]
                    and r["timing"].get("roofline_ratio", 2.0) < 1.0]
        check(p.get("asleep") == sleepers, f"{p['scenario']}: asleep {p.get('asleep')} != {sleepers}")
    check(any(p.get("asleep") for p in m["charts"]["time_vs_error"]["panels"]), "asleep golden: a sleeper marked")
    page = open(f"{stem}.html", encoding="utf-8").read()
    check("<b>asleep</b>" in page, "asleep: the overview says so")


def run_doctored(charts_py, rep, tmp, name):
    """Charts a report changed in memory (written to its own folder, charted into
    another): the manifest and the output stem."""
    src, out = os.path.join(tmp, name + "_src"), os.path.join(tmp, name)
    os.makedirs(src)
    os.makedirs(out)
    doctored = os.path.join(src, name + ".json")
    with open(doctored, "w") as f:
        json.dump(rep, f)
    _, m, stem = run_on(charts_py, doctored, out)
    return m, stem


def check_unsound_reference(charts_py, golden, tmp):
    """A scenario whose reference is not ok: its deviations are no accuracy, so its panel
    has no Pareto front and the overview says why; the other scenarios keep theirs."""
    with open(golden) as f:
        rep = json.load(f)
    name = rep["runs"][0]["scenario"]
    for r in rep["runs"]:
        if r["scenario"] == name:
            r["metrics"]["deviation_vs_reference"].update(
                {"reference_status": "unstable", "reference_reason": "motion does not decay (test)"})
    m, stem = run_doctored(charts_py, rep, tmp, "unsound_reference")
    panels = {p["scenario"]: p for p in m["charts"]["time_vs_error"]["panels"]}
    check(panels[name]["pareto"] == [], f"unsound reference: {name} still has a Pareto front")
    others = [n for n in panels if n != name]
    check(bool(others) and all(panels[n]["pareto"] for n in others), "unsound reference: the other fronts kept")
    summary = open(f"{stem}_summary.md", encoding="utf-8").read()
    check("the reference is unstable here (motion does not decay (test))" in summary,
          "unsound reference: the overview says so")


def check_deformed(charts_py, golden, tmp):
    """A run that does not return (docs/verdicts.md, deformed): marked on the time-vs-error
    chart, never on its Pareto front, and its overview cell lilac with its class."""
    with open(golden) as f:
        rep = json.load(f)
    run = next(r for r in rep["runs"] if r["metrics"]["deviation_vs_reference"]["rms"] not in (0, None))
    run["status"] = "deformed"
    run["verdict"]["class"] = "deformed"
    run["verdict"]["reason"] = "does not return: 0.3 mean strand lengths (test)"
    m, stem = run_doctored(charts_py, rep, tmp, "deformed")
    panel = next(p for p in m["charts"]["time_vs_error"]["panels"] if p["scenario"] == run["scenario"])
    check(all(p["model"] != run["model"] for p in panel["pareto"]), f"deformed: {run['model']} on the Pareto front")
    page = open(f"{stem}.html", encoding="utf-8").read()
    check("background:#dcc3ee'><b>deformed" in page, "deformed: the overview cell is not lilac with its class")


def check_truth(charts_py, golden, tmp):
    """The truth panel (docs/truth.md): each run's kicked modes' frequency error and decay
    rate in its own table beside its speed, a run that could not be kicked with its reason,
    and no panel for a report without truth runs."""
    with open(golden) as f:
        rep = json.load(f)
    m, stem = run_doctored(charts_py, rep, tmp, "no_truth")
    check("Truth: the hanging chain" not in open(f"{stem}.html", encoding="utf-8").read(),
          "truth: a panel without truth runs")
    kicked, skipped = rep["runs"][0], rep["runs"][1]
    kicked["truth"] = {"modes": [
        {"mode": 1, "strands": 1, "masses": 6, "exact_omega": 7.82, "omega": 7.81, "frequency_error": -1.17e-3,
         "sigma": 0.0848, "damping_ratio": 0.0109, "share": 1.0},
        {"mode": 2, "strands": 1, "masses": 6, "exact_omega": 18.07, "omega": 18.05, "frequency_error": -9.44e-4,
         "sigma": 0.453, "damping_ratio": 0.0251, "share": 1.0}]}
    skipped["truth"] = {"skipped": "the model cannot start from a given state (test)"}
    m, stem = run_doctored(charts_py, rep, tmp, "truth")
    page = open(f"{stem}.html", encoding="utf-8").read()
    check("Truth: the hanging chain" in page, "truth: no panel")
    panel = page[page.index("Truth: the hanging chain"):]
    for text in ("-1.17e-03", "-9.44e-04", "0.0848", "0.453", "not kicked: the model cannot start from a given state"):
        check(text in panel, f"truth: {text!r} missing from the panel")


def check_material(charts_py, golden, tmp):
    """The material card (docs/metrics.md): each run's numbers over the reference's in its
    overview cell and its table row; the reference's own run shows its numbers."""
    with open(golden) as f:
        rep = json.load(f)
    for r in rep["runs"]:
        own = r["metrics"]["deviation_vs_reference"]["max"] == 0
        r["metrics"]["material"] = {"strands": 8, "settle_s": 1.5, "sag": 0.08, "stretch": 0.01, "sigma": 35.0,
                                    "omega": 54.0}
        if not own:
            r["metrics"]["material"]["vs_reference"] = {"sag": 0.42, "stretch": 1.0, "sigma": 0.31, "omega": 0.79}
    m, stem = run_doctored(charts_py, rep, tmp, "material")
    page = open(f"{stem}.html", encoding="utf-8").read()
    check("sag ×0.42 σ ×0.31 ω ×0.79" in page, "material: the ratios are not in the overview")
    check("sag 0.08 σ 35/s ω 54/s" in page, "material: the reference's own card is not shown")
    summary = open(f"{stem}_summary.md", encoding="utf-8").read()
    check("| sag ×0.42 σ ×0.31 ω ×0.79 |" in summary, "material: the ratios are not in the summary table")


def check_svg(charts_py, golden, tmp):
    """--svg: SVG next to every PNG, the strand lines an embedded raster, not paths."""
    out = os.path.join(tmp, "svg")
    os.makedirs(out)
    rep, m, stem = run_on(charts_py, golden, tmp, out, ["--svg"])
    for s in m["charts"]["strands"]:
        check([os.path.splitext(f)[1] for f in s["files"]] == [".png", ".svg"], f"--svg: {s['files']}")
        svg = [f for f in s["files"] if f.endswith(".svg")]
        check(bool(svg) and "<image" in open(svg[0], encoding="utf-8").read(), f"{svg}: strands rasterized")
    for kind in ("time_vs_error", "timeseries", "stages"):
        check(len(m["charts"][kind]["files"]) == 2, f"--svg: {kind}")


def guarded(what, fn, *args):
    """One check group; an exception in it (a file the script did not write) is a failure
    of that group, and the others still run."""
    try:
        return fn(*args)
    except Exception as e:  # noqa: BLE001 - reported, not swallowed
        check(False, f"{what}: {type(e).__name__}: {e}")
        return None


def check_compare(charts_py, data, tmp):
    rep, m = check_report(charts_py, os.path.join(data, "compare_report.json"), tmp)
    check(len(m["charts"]["strands"]) == 2, "compare: one strand picture per scenario")


def check_sweep(charts_py, data, tmp):
    rep, m = check_report(charts_py, os.path.join(data, "sweep_report.json"), tmp)
    unreached = [c for c in m["charts"]["strands"][0]["strands_per_panel"] if c == 0]
    check(len(unreached) >= 2, "sweep: the diverged runs' final frames are drawn as unreached")


def check_metric_table(charts_py, golden, tmp):
    """The charts draw what the report's metric table holds (metric_definitions): a metric
    added there, with its series and summary, gets a time-series panel and a table column;
    a report without the table is refused with one line."""
    with open(golden) as f:
        rep = json.load(f)
    rep["metric_definitions"].append(
        {"name": "twist", "unit": "1", "meaning": "test metric", "on_device": False, "cli": "",
         "against_reference": False, "timeseries_label": "twist (test)",
         "columns": [{"name": "twist", "reported": True, "follow_only": False}],
         "summaries": [{"key": "max", "column": "twist", "stat": "max", "label": "twist max (test)",
                        "format": "%.4f", "gate": None}]})
    for r in rep["runs"]:
        r["series"]["twist"] = [0.25] * len(r["series"]["t"])
        r["metrics"]["twist"] = {"max": 0.25}
    m, stem = run_doctored(charts_py, rep, tmp, "metric_table")
    for p in m["charts"]["timeseries"]["panels"]:
        check(p.get("twist") == sum(r["scenario"] == p["scenario"] for r in rep["runs"]),
              f"metric table: {p['scenario']} has no twist panel with a line per run: {p}")
    summary = open(f"{stem}_summary.md", encoding="utf-8").read()
    check("| twist max (test) |" in summary and "| 0.2500 |" in summary, "metric table: no twist column in the summary")
    del rep["metric_definitions"]
    bare = os.path.join(tmp, "no_definitions.json")
    with open(bare, "w") as f:
        json.dump(rep, f)
    r = subprocess.run([sys.executable, charts_py, bare], capture_output=True, text=True)
    check(r.returncode == 2 and r.stderr.count("\n") == 1 and "metric_definitions" in r.stderr,
          f"a report without metric_definitions: {r.returncode} {r.stderr}")


def check_bad(charts_py, tmp):
    """A report the script cannot read: exit 2, one line."""
    bad = os.path.join(tmp, "bad.json")
    with open(bad, "w") as f:
        f.write('{"schema": "something-else", "runs": []}')
    r = subprocess.run([sys.executable, charts_py, bad], capture_output=True, text=True)
    check(r.returncode == 2 and r.stderr.count("\n") == 1 and "schema" in r.stderr, f"bad report: {r.stderr}")


def main():
    charts_py, data = sys.argv[1], sys.argv[2]
    with tempfile.TemporaryDirectory() as tmp:
        guarded("compare", check_compare, charts_py, data, tmp)
        guarded("sweep", check_sweep, charts_py, data, tmp)
        guarded("asleep", check_asleep, charts_py, os.path.join(data, "compare_asleep.json"), tmp)
        guarded("--svg", check_svg, charts_py, os.path.join(data, "compare_report.json"), tmp)
        guarded("unsound reference", check_unsound_reference, charts_py, os.path.join(data, "compare_report.json"),
                tmp)
        guarded("material", check_material, charts_py, os.path.join(data, "compare_report.json"), tmp)
        guarded("deformed", check_deformed, charts_py, os.path.join(data, "compare_report.json"), tmp)
        guarded("truth", check_truth, charts_py, os.path.join(data, "compare_report.json"), tmp)
        guarded("metric table", check_metric_table, charts_py, os.path.join(data, "compare_report.json"), tmp)
        guarded("bad report", check_bad, charts_py, tmp)
        guarded("stress", check_stress, os.path.join(os.path.dirname(charts_py), "stress_chart.py"),
                os.path.join(data, "stress_small.json"), tmp)
        guarded("precision", check_precision, os.path.join(os.path.dirname(charts_py), "precision_chart.py"),
                os.path.join(data, "precision_small.json"), tmp)
    for f in failures:
        print("FAILED:", f)
    print(f"{'FAIL' if failures else 'ok'}: charts_test")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
