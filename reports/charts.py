#!/usr/bin/env python3
"""Charts, a Markdown summary and a self-contained HTML page from a hairbench report.

usage: charts.py REPORT.json [--out-dir DIR]

Writes next to the report (or into DIR), STEM being the report's file name without .json:
  STEM_time_vs_error.png/.svg   median step time against deviation (log-log), one line per
                                model through its knob values, the Pareto front marked
  STEM_timeseries.png/.svg      deviation and jaggedness over time, script phases shaded
  STEM_stages.png/.svg          time per solver stage, stacked, per run
  STEM_strands_SCENARIO.png/.svg  the most violent and the final frame of every run, strands
                                coloured by per-vertex deviation from the reference
  STEM_summary.md               the summary tables
  STEM.html                     tables and every chart, images inlined: one file to open
  STEM_charts.json              manifest of what was drawn (files, series, Pareto points)

Needs Python 3 with matplotlib (Debian: python3-matplotlib). Exit codes: 0 done; 2 the
report cannot be read; 3 matplotlib cannot be imported (the hairbench CLI relies on it).
"""

import argparse
import base64
import html
import json
import math
import os
import sys

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker
    from matplotlib.collections import LineCollection
    from matplotlib.patches import Circle, Patch
except ImportError as e:  # the CLI turns exit 3 into "install python3-matplotlib"
    print(f"charts.py: {sys.executable} cannot import matplotlib ({e}); install Debian's python3-matplotlib "
          f"and run it with /usr/bin/python3", file=sys.stderr)
    sys.exit(3)

PHASE_COLOURS = {"move": "tab:blue", "oscillate": "tab:orange", "wind": "tab:green"}
STAGE_ORDER = ["integrate", "global_shape", "local_shape", "length", "collision"]


class ReportError(Exception):
    pass


def num(v):
    """JSON number or null -> float (NaN for null)."""
    return float("nan") if v is None else float(v)


def fmt(v, spec=".3g"):
    return "–" if v is None or (isinstance(v, float) and not math.isfinite(v)) else format(v, spec)


def knob_text(run):
    k = run.get("knob")
    return "" if not k else f"{k['name']}={k['value']:g}"


def run_label(run):
    k = knob_text(run)
    return run["model"] + (f" {k}" if k else "")


def load(path):
    try:
        with open(path, encoding="utf-8") as f:
            report = json.load(f)
    except (OSError, ValueError) as e:
        raise ReportError(f"{path}: cannot read the report: {e}")
    if report.get("schema") != "hairbench-report" or not isinstance(report.get("runs"), list):
        raise ReportError(f"{path}: schema: not a hairbench-report")
    return report


def scenario_names(report):
    names = []
    for r in report["runs"]:
        if r["scenario"] not in names:
            names.append(r["scenario"])
    return names


def scenario_info(report, name):
    for s in report.get("scenarios", []):
        if s["name"] == name:
            return s
    return None


def model_colours(report):
    models = []
    for r in report["runs"]:
        if r["model"] not in models:
            models.append(r["model"])
    cmap = plt.get_cmap("tab10")
    return {m: cmap(i % 10) for i, m in enumerate(models)}


def run_colour(colours, run, runs_of_model):
    """The model's colour; in a sweep, lighter for smaller knob values."""
    base = colours[run["model"]]
    if len(runs_of_model) < 2 or "knob" not in run:
        return base
    values = sorted(r["knob"]["value"] for r in runs_of_model)
    rank = values.index(run["knob"]["value"]) / (len(values) - 1)
    mix = 0.55 * (1.0 - rank)  # towards white
    return tuple(c + (1.0 - c) * mix for c in base[:3]) + (1.0,)


def reference_text(run):
    dev = run["metrics"]["deviation_vs_reference"]
    ref = dev.get("reference", "han_m1")
    o = dev.get("reference_overrides")
    if o:
        ref += " (" + ", ".join(f"{k} {v:g}" for k, v in sorted(o.items())) + ")"
    return ref


def grid(n, ncols_max=3, w=5.2, h=4.0):
    ncols = min(ncols_max, max(1, n))
    nrows = (n + ncols - 1) // ncols
    fig, axes = plt.subplots(nrows, ncols, figsize=(w * ncols, h * nrows), squeeze=False)
    flat = [a for row in axes for a in row]
    for a in flat[n:]:
        a.set_visible(False)
    return fig, flat[:n]


def save(fig, out_dir, stem, name, written):
    paths = []
    for ext in ("png", "svg"):
        p = os.path.join(out_dir, f"{stem}_{name}.{ext}")
        fig.savefig(p, dpi=90 if ext == "png" else None, bbox_inches="tight")
        paths.append(p)
    plt.close(fig)
    written.extend(paths)
    return paths


def pareto_front(points):
    """Points (time, error, payload) not dominated by another (no other is at least as
    fast and at least as accurate, and strictly better in one)."""
    front = []
    for p in points:
        dominated = any(q[0] <= p[0] and q[1] <= p[1] and (q[0] < p[0] or q[1] < p[1]) for q in points)
        if not dominated:
            front.append(p)
    return sorted(front, key=lambda p: p[0])


# --- run time vs error ------------------------------------------------------------------

def chart_time_vs_error(report, out_dir, stem, written):
    names = scenario_names(report)
    colours = model_colours(report)
    fig, axes = grid(len(names))
    panels = []
    for ax, name in zip(axes, names):
        runs = [r for r in report["runs"] if r["scenario"] == name]
        stable = []
        unstable = []
        for r in runs:
            t = num(r["timing"]["step_ms"]["median"])
            e = num(r["metrics"]["deviation_vs_reference"]["rms"])
            if r["status"] == "ok" and math.isfinite(t) and math.isfinite(e):
                stable.append((t, e, r))
            else:
                unstable.append(run_label(r))
        positive = [e for _, e, _ in stable if e > 0]
        # log axes cannot show 0: runs identical to the reference sit on a floor line.
        floor = (min(positive) / 4.0) if positive else 1e-6
        series = []
        for model in dict.fromkeys(r["model"] for r in runs):
            pts = sorted((p for p in stable if p[2]["model"] == model),
                         key=lambda p: p[2].get("knob", {}).get("value", 0.0))
            if not pts:
                continue
            xs = [max(e, floor) for _, e, _ in pts]
            ys = [t for t, _, _ in pts]
            ax.plot(xs, ys, "-o", color=colours[model], label=model, ms=5, lw=1.5)
            for (t, e, r), x in zip(pts, xs):
                if "knob" in r:
                    ax.annotate(f"{r['knob']['value']:g}", (x, t), textcoords="offset points", xytext=(4, 4),
                                fontsize=7, color=colours[model])
                if e == 0:
                    ax.annotate("= reference", (x, t), textcoords="offset points", xytext=(4, -10), fontsize=7)
            series.append({"model": model, "points": len(pts)})
        front = pareto_front(stable)
        if front:
            fx = [max(e, floor) for _, e, _ in front]
            fy = [t for t, _, _ in front]
            ax.step(fx, fy, where="post", color="black", lw=1, ls="--", alpha=0.6)
            ax.scatter(fx, fy, s=110, facecolors="none", edgecolors="black", lw=1.3, label="Pareto front", zorder=5)
        if positive and any(e == 0 for _, e, _ in stable):
            ax.axvline(floor, color="grey", lw=0.6, ls=":")
        ax.set_xscale("log")
        ax.set_yscale("log")
        # milliseconds as plain numbers (not 4x10^1); deviations keep the log labels
        ax.yaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
        ax.yaxis.set_minor_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
        ax.set_xlabel("deviation vs reference (RMS over frames, / L̄)")
        ax.set_ylabel("median step time (ms)")
        knob = next((r["knob"]["name"] for r in runs if "knob" in r), None)
        title = f"{name}: run time vs error" + (f" over {knob}" if knob else "")
        ax.set_title(title + f"\nreference {reference_text(runs[0])}", fontsize=9)
        if unstable:
            ax.text(0.01, 0.01, "unstable: " + ", ".join(unstable), transform=ax.transAxes, fontsize=7,
                    color="tab:red", va="bottom")
        ax.grid(True, which="both", alpha=0.25)
        ax.legend(fontsize=7)
        panels.append({
            "scenario": name,
            "series": series,
            "pareto": [{"model": r["model"], "knob": r.get("knob"), "step_ms": t, "deviation": e}
                       for t, e, r in front],
            "unstable": unstable,
        })
    fig.tight_layout()
    return {"files": save(fig, out_dir, stem, "time_vs_error", written), "panels": panels}


# --- deviation and jaggedness over time -------------------------------------------------

def shade_phases(ax, info):
    for p in (info or {}).get("phases", []):
        ax.axvspan(p["start"], p["end"], color=PHASE_COLOURS.get(p["kind"], "grey"), alpha=0.12, lw=0)


def chart_timeseries(report, out_dir, stem, written):
    names = scenario_names(report)
    colours = model_colours(report)
    fig, axes = plt.subplots(len(names), 2, figsize=(13, 3.3 * len(names)), squeeze=False)
    panels = []
    for row, name in zip(axes, names):
        runs = [r for r in report["runs"] if r["scenario"] == name]
        info = scenario_info(report, name)
        panel = {"scenario": name, "phases": len((info or {}).get("phases", []))}
        for ax, key, ylabel in ((row[0], "deviation_vs_reference", "deviation vs reference (/ L̄)"),
                                (row[1], "jaggedness", "jaggedness")):
            shade_phases(ax, info)
            drawn = 0
            for r in runs:
                same_model = [q for q in runs if q["model"] == r["model"]]
                t = [num(v) for v in r["series"].get("t", [])]
                y = [num(v) for v in r["series"].get(key, [])]
                if not t:  # a report without the time axis: frame times from dt
                    t = [(i + 1) * r["dt"] for i in range(len(y))]
                ax.plot(t, y, color=run_colour(colours, r, same_model), lw=1.2, label=run_label(r))
                drawn += 1
            for f in (info or {}).get("snapshots", {}).get("frames", []):
                if f["label"] == "most_violent":
                    ax.axvline(f["t"], color="black", lw=0.8, ls=":")
            ax.set_xlabel("time (s)")
            ax.set_ylabel(ylabel)
            ax.set_title(f"{name}: {key.replace('_', ' ')}", fontsize=9)
            ax.grid(True, alpha=0.25)
            panel[key] = drawn
        handles, labels = row[0].get_legend_handles_labels()
        kinds = dict.fromkeys(p["kind"] for p in (info or {}).get("phases", []))
        handles += [Patch(color=PHASE_COLOURS.get(k, "grey"), alpha=0.25) for k in kinds]
        labels += [f"phase: {k}" for k in kinds]
        if info and info.get("snapshots", {}).get("frames"):
            handles.append(plt.Line2D([], [], color="black", lw=0.8, ls=":"))
            labels.append("most violent frame")
        row[1].legend(handles, labels, fontsize=7, loc="upper right", ncol=2 if len(labels) > 8 else 1)
        panels.append(panel)
    fig.tight_layout()
    return {"files": save(fig, out_dir, stem, "timeseries", written), "panels": panels}


# --- stage time breakdown ---------------------------------------------------------------

def chart_stages(report, out_dir, stem, written):
    names = scenario_names(report)
    fig, axes = grid(len(names), ncols_max=2, w=6.5, h=4.2)
    cmap = plt.get_cmap("Set2")
    all_stages = []
    for r in report["runs"]:
        for s in r["timing"].get("stage_ms", {}):
            if s not in all_stages:
                all_stages.append(s)
    all_stages.sort(key=lambda s: (STAGE_ORDER.index(s) if s in STAGE_ORDER else len(STAGE_ORDER), s))
    stage_colour = {s: cmap(i % 8) for i, s in enumerate(all_stages)}
    stage_colour["untimed"] = (0.8, 0.8, 0.8, 1.0)
    panels = []
    for ax, name in zip(axes, names):
        runs = [r for r in report["runs"] if r["scenario"] == name]
        labels = [run_label(r) for r in runs]
        bottom = [0.0] * len(runs)
        segments = []
        for stage in all_stages + ["untimed"]:
            vals = []
            for r in runs:
                st = r["timing"].get("stage_ms", {})
                if stage == "untimed":
                    # step time not inside any named stage (the model's own bookkeeping)
                    mean = num(r["timing"]["step_ms"]["mean"])
                    v = mean - sum(num(x) for x in st.values()) if math.isfinite(mean) else 0.0
                    vals.append(max(v, 0.0))
                else:
                    v = num(st.get(stage))
                    vals.append(v if math.isfinite(v) else 0.0)
            if not any(vals):
                continue
            ax.bar(range(len(runs)), vals, bottom=bottom, color=stage_colour[stage], label=stage)
            bottom = [b + v for b, v in zip(bottom, vals)]
            segments.append(stage)
        # Stages a scene did not need are 0 ms; name them over the bar so "skipped" is
        # visible rather than silently absent (issue 8).
        skipped_runs = 0
        for i, r in enumerate(runs):
            skipped = sorted(r["timing"].get("stage_skipped_steps", {}))
            if skipped:
                skipped_runs += 1
                ax.annotate("skipped: " + ", ".join(skipped), (i, bottom[i]), xytext=(0, 3),
                            textcoords="offset points", ha="center", va="bottom", fontsize=6, rotation=90)
        ax.set_xticks(range(len(runs)))
        ax.set_xticklabels(labels, rotation=40 if len(runs) > 3 else 0, ha="right" if len(runs) > 3 else "center",
                           fontsize=7)
        ax.set_ylabel("ms per step (mean)")
        ax.set_title(f"{name}: time per solver stage", fontsize=9)
        ax.legend(fontsize=7)
        ax.grid(True, axis="y", alpha=0.25)
        panels.append({"scenario": name, "bars": len(runs), "stages": segments, "runs_with_skipped": skipped_runs})
    fig.tight_layout()
    return {"files": save(fig, out_dir, stem, "stages", written), "panels": panels}


# --- strand pictures --------------------------------------------------------------------

def camera(points, centre):
    """Orthographic view from the front, 30 degrees to the right and 15 degrees above:
    the same camera for every panel of a frame, centred on the head."""
    yaw, pitch = math.radians(30.0), math.radians(15.0)
    cy, sy, cp, sp = math.cos(yaw), math.sin(yaw), math.cos(pitch), math.sin(pitch)
    out = []
    for x, y, z in points:
        x, y, z = x - centre[0], y - centre[1], z - centre[2]
        x, z = cy * x + sy * z, -sy * x + cy * z  # yaw about y
        y, z = cp * y - sp * z, sp * y + cp * z  # pitch about x
        out.append((x, y))
    return out


def strand_points(flat):
    return [(num(flat[i]), num(flat[i + 1]), num(flat[i + 2])) for i in range(0, len(flat) - 2, 3)]


def chart_strands(report, out_dir, stem, written):
    out = []
    colours = None
    for name in scenario_names(report):
        info = scenario_info(report, name)
        snaps = (info or {}).get("snapshots")
        if not snaps or not snaps.get("frames"):
            continue
        runs = [r for r in report["runs"] if r["scenario"] == name]
        ref = snaps["reference"]
        ref_by_label = {s["label"]: s for s in ref["snapshots"]}
        columns = [(run_label(r), {s["label"]: s for s in r.get("snapshots", [])}) for r in runs]
        # The reference is shown too when it is not one of the runs (another setting).
        if not any(r["model"] == ref["model"] and not r["metrics"]["deviation_vs_reference"]["max"] for r in runs):
            columns.insert(0, ("reference " + reference_text(runs[0]).replace(" (", "\n(").replace(", ", ",\n", 1),
                               ref_by_label))
        frames = snaps["frames"]
        lbar = info["mean_strand_length"]
        fig, axes = plt.subplots(len(frames), len(columns), figsize=(2.5 * len(columns) + 1.0, 2.7 * len(frames)),
                                 squeeze=False)
        vmax = 0.0
        collections = []
        r_head = info.get("head_radius", 0.1)
        box = [-r_head, -r_head, r_head, r_head]  # the view: head and every strand, same in all panels
        for fi, frame in enumerate(frames):
            centre = frame["head"]["translation"]
            ref_snap = ref_by_label.get(frame["label"])
            for ci, (label, by_label) in enumerate(columns):
                ax = axes[fi][ci]
                ax.set_aspect("equal")
                ax.set_xticks([])
                ax.set_yticks([])
                ax.add_patch(Circle((0, 0), r_head, color="0.85", zorder=0))
                if fi == 0:
                    ax.set_title(label, fontsize=7)
                if ci == 0:
                    ax.set_ylabel(f"{frame['label'].replace('_', ' ')}\nframe {frame['frame']}, t={frame['t']:.2f} s",
                                  fontsize=8)
                snap = by_label.get(frame["label"])
                if not snap or not snap.get("strands"):
                    ax.text(0, 0, "not reached\n(unstable)", ha="center", va="center", fontsize=8, color="tab:red")
                    collections.append(None)
                    continue
                segs, devs = [], []
                for si, flat in enumerate(snap["strands"]):
                    pts = strand_points(flat)
                    refp = strand_points(ref_snap["strands"][si]) if ref_snap and ref_snap.get("strands") else None
                    d = [math.dist(p, q) / lbar for p, q in zip(pts, refp)] if refp else [0.0] * len(pts)
                    xy = camera(pts, centre)
                    for v in range(len(xy) - 1):
                        segs.append([xy[v], xy[v + 1]])
                        devs.append(0.5 * (d[v] + d[v + 1]))
                for seg in segs:
                    for x, y in seg:
                        if math.isfinite(x) and math.isfinite(y):
                            box = [min(box[0], x), min(box[1], y), max(box[2], x), max(box[3], y)]
                finite = [x for x in devs if math.isfinite(x)]
                vmax = max([vmax] + finite)
                lc = LineCollection(segs, cmap="viridis", linewidths=0.7)
                lc.set_array(devs)
                ax.add_collection(lc)
                collections.append((lc, len(snap["strands"])))
        # A blown-up run must not shrink everyone else's picture: at most 3 L-bar around the head.
        lim = r_head + 3.0 * lbar
        box = [max(box[0], -lim), max(box[1], -lim), min(box[2], lim), min(box[3], lim)]
        pad = 0.05 * max(box[2] - box[0], box[3] - box[1])
        for ax in (a for row in axes for a in row):
            ax.set_xlim(box[0] - pad, box[2] + pad)
            ax.set_ylim(box[1] - pad, box[3] + pad)
        drawn = [c for c in collections if c]
        vmax = vmax if vmax > 0 else 1e-6
        for lc, _ in drawn:
            lc.set_clim(0.0, vmax)
        if drawn:
            cb = fig.colorbar(drawn[0][0], ax=[a for row in axes for a in row], shrink=0.8, pad=0.01)
            cb.set_label("per-vertex deviation |p − p_ref| / L̄", fontsize=8)
        fig.suptitle(f"{name}: {len(snaps['strands'])} strands of the groom, coloured by deviation from the "
                     f"reference ({reference_text(runs[0])})", fontsize=10)
        files = save(fig, out_dir, stem, f"strands_{name}", written)
        out.append({"scenario": name, "files": files, "frames": [f["label"] for f in frames],
                    "columns": [c[0] for c in columns], "panels": len(collections),
                    "strands_per_panel": [c[1] if c else 0 for c in collections], "max_deviation": vmax})
    return out


# --- tables -----------------------------------------------------------------------------

COLUMNS = ["model", "knob", "status", "median step ms", "ns/vertex", "deviation RMS", "deviation max",
           "jaggedness mean", "length error RMS", "rest shape error", "penetration max (m)", "Pareto"]


def table_rows(report, name, pareto):
    rows = []
    front = {(p["model"], json.dumps(p["knob"], sort_keys=True)) for p in pareto}
    for r in report["runs"]:
        if r["scenario"] != name:
            continue
        m = r["metrics"]
        on_front = (r["model"], json.dumps(r.get("knob"), sort_keys=True)) in front
        status = r["status"] if r["status"] == "ok" else f"{r['status']} at frame {r['failure']['frame']}"
        rows.append([r["model"], knob_text(r) or "–", status, fmt(r["timing"]["step_ms"]["median"]),
                     fmt(r["timing"]["ns_per_vertex"], ".1f"), fmt(m["deviation_vs_reference"]["rms"]),
                     fmt(m["deviation_vs_reference"]["max"]), fmt(m["jaggedness"]["mean"]),
                     fmt(m["length_error"]["rms"], ".2g"), fmt(m["rest_shape_error"]),
                     fmt(m["penetration"]["max"], ".2g"), "yes" if on_front else ""])
    return rows


def scenario_notes(report, name):
    info = scenario_info(report, name)
    notes = []
    runs = [r for r in report["runs"] if r["scenario"] == name]
    notes.append(f"reference: {reference_text(runs[0])}; {runs[0]['groom']['strands']} strands, "
                 f"{runs[0]['groom']['vertices']} vertices, {runs[0]['frames']} frames")
    if info:
        phases = "; ".join(f"{p['start']:.2f}–{p['end']:.2f} s {p['label']}" for p in info.get("phases", []))
        notes.append("phases: " + (phases or "none (the head holds still)"))
        for f in info.get("snapshots", {}).get("frames", []):
            if f["label"] == "most_violent":
                notes.append(f"most violent frame: {f['frame']} (t = {f['t']:.3f} s), reference kinetic energy "
                             f"relative to the head {fmt(f['violence'])} m²/s²")
    return notes


def context_line(report):
    c = report.get("context", {})
    return (f"{c.get('date', '?')} · git {c.get('git_sha', '?')} · {c.get('cpu', '?')} · "
            f"{c.get('threads', '?')} threads · {c.get('build_type', '?')} · {c.get('compiler', '?')}")


def write_markdown(report, path, pareto_by_scenario):
    lines = ["# hairbench report", "", context_line(report), ""]
    for name in scenario_names(report):
        lines += [f"## {name}", ""]
        lines += [f"- {n}" for n in scenario_notes(report, name)]
        lines += ["", "| " + " | ".join(COLUMNS) + " |", "|" + "---|" * len(COLUMNS)]
        for row in table_rows(report, name, pareto_by_scenario.get(name, [])):
            lines.append("| " + " | ".join(row) + " |")
        lines.append("")
    lines += ["Deviation is RMS over vertices / L̄ (mean rest strand length) per frame; the table gives the RMS "
              "and max over frames. Pareto: no other run of the scenario is both faster (median step) and "
              "closer to the reference.", ""]
    with open(path, "w", encoding="utf-8") as f:
        f.write("\n".join(lines))


def img_tag(png, alt):
    with open(png, "rb") as f:
        data = base64.b64encode(f.read()).decode("ascii")
    return f'<figure><img alt="{html.escape(alt)}" src="data:image/png;base64,{data}"><figcaption>' \
           f'{html.escape(alt)}</figcaption></figure>'


def write_html(report, path, charts, pareto_by_scenario):
    e = html.escape
    parts = ["<!DOCTYPE html><html><head><meta charset='utf-8'><title>hairbench report</title><style>",
             "body{font-family:sans-serif;margin:1.5em;max-width:1800px}table{border-collapse:collapse;"
             "font-size:13px;margin:0.5em 0 1.5em}td,th{border:1px solid #ccc;padding:3px 7px;text-align:right}"
             "td:first-child,td:nth-child(2),td:nth-child(3){text-align:left}th{background:#eee}"
             "img{max-width:100%}figure{margin:1em 0}figcaption{color:#555;font-size:13px}"
             "tr.front td{background:#eef7ee}",
             "</style></head><body>", "<h1>hairbench report</h1>", f"<p>{e(context_line(report))}</p>"]
    for name in scenario_names(report):
        parts.append(f"<h2>{e(name)}</h2><ul>")
        parts += [f"<li>{e(n)}</li>" for n in scenario_notes(report, name)]
        parts.append("</ul><table><tr>" + "".join(f"<th>{e(c)}</th>" for c in COLUMNS) + "</tr>")
        for row in table_rows(report, name, pareto_by_scenario.get(name, [])):
            cls = " class='front'" if row[-1] else ""
            parts.append(f"<tr{cls}>" + "".join(f"<td>{e(c)}</td>" for c in row) + "</tr>")
        parts.append("</table>")
    parts.append("<h2>Charts</h2>")
    parts.append(img_tag(charts["time_vs_error"]["files"][0], "Run time against error (log–log); the Pareto front "
                         "is ringed"))
    parts.append(img_tag(charts["timeseries"]["files"][0], "Deviation from the reference and jaggedness over "
                         "time; script phases shaded, the most violent frame dotted"))
    parts.append(img_tag(charts["stages"]["files"][0], "Time per solver stage (mean per step)"))
    for s in charts["strands"]:
        parts.append(img_tag(s["files"][0], f"{s['scenario']}: most violent and final frame, strands coloured by "
                             f"per-vertex deviation from the reference"))
    parts.append("</body></html>")
    with open(path, "w", encoding="utf-8") as f:
        f.write("\n".join(parts))


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("report")
    ap.add_argument("--out-dir", help="where to write (default: the report's folder)")
    args = ap.parse_args(argv)
    try:
        report = load(args.report)
        if not report["runs"]:
            raise ReportError(f"{args.report}: runs: the report has no runs")
    except ReportError as e:
        print(f"charts.py: {e}", file=sys.stderr)
        return 2
    out_dir = args.out_dir or os.path.dirname(os.path.abspath(args.report))
    os.makedirs(out_dir, exist_ok=True)
    stem = os.path.splitext(os.path.basename(args.report))[0]
    plt.rcParams.update({"font.size": 8, "svg.fonttype": "none"})

    written = []
    charts = {
        "time_vs_error": chart_time_vs_error(report, out_dir, stem, written),
        "timeseries": chart_timeseries(report, out_dir, stem, written),
        "stages": chart_stages(report, out_dir, stem, written),
        "strands": chart_strands(report, out_dir, stem, written),
    }
    pareto = {p["scenario"]: p["pareto"] for p in charts["time_vs_error"]["panels"]}
    md = os.path.join(out_dir, f"{stem}_summary.md")
    write_markdown(report, md, pareto)
    page = os.path.join(out_dir, f"{stem}.html")
    write_html(report, page, charts, pareto)
    written += [md, page]
    manifest = os.path.join(out_dir, f"{stem}_charts.json")
    with open(manifest, "w", encoding="utf-8") as f:
        json.dump({"report": os.path.abspath(args.report), "files": written, "charts": charts}, f, indent=1)
    print(f"charts: wrote {page} and {len(written) - 1} more files (manifest {manifest})")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
