#!/usr/bin/env python3
"""Charts, a Markdown summary and a self-contained HTML page from a hairbench report.

usage: charts.py REPORT.json [--out-dir DIR] [--svg]
       charts.py REPORT.json --animate SCENARIO [--out-dir DIR]   (writes STEM_SCENARIO.gif only)

Writes next to the report (or into DIR), STEM being the report's file name without .json:
  STEM_time_vs_error.png        median step time against deviation (log-log), one line per
                                model through its knob values, the Pareto front marked; a run
                                asleep through the scenario (a step faster than streaming its
                                state once) is drawn on the time axis's floor, marked "asleep"
  STEM_timeseries.png           deviation and jaggedness over time, script phases shaded
  STEM_stages.png               time per solver stage, stacked, per run, one colour per stage
                                name in the report; stages a run skipped are listed in the legend
  STEM_strands_SCENARIO.png     the most violent and the final frame of every run, strands
                                coloured by per-vertex deviation from the reference
  STEM_summary.md               the summary tables
  STEM.html                     first an overview (a table of runs by scenarios: verdict, step
                                time relative to the reference model, deviation, jaggedness,
                                coloured by deviation), the truth panel, a motion player per
                                scenario (reports/player.js, inlined, over the report's
                                animation frames), then the time-vs-error chart, then the
                                per-scenario tables and every other chart; PNGs inlined: one file
  STEM_charts.json              manifest of what was drawn (files, series, Pareto points)

PNGs are written with a 256-colour palette (a few hundred kilobytes for a default compare's
pictures). --svg (or HAIRBENCH_SVG=1 in the environment, for the hairbench CLI) also writes
every chart as SVG, the strand lines rasterized inside it. Reads schema_version 1 (snapshot
strands as coordinate lists), 2 (encoded strands, see decode_strand) and 3 (context.devices
as objects with the GPU clock).

Needs Python 3 with matplotlib (Debian: python3-matplotlib). Exit codes: 0 done; 2 the
report cannot be read; 3 matplotlib cannot be imported (the hairbench CLI relies on it).
"""

import argparse
import base64
import html
import io
import json
import math
import os
import sys
import textwrap
import zlib

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.colors
    import matplotlib.ticker
    from matplotlib.collections import LineCollection
    from matplotlib.patches import Circle, Patch
    from PIL import Image  # matplotlib's own PNG dependency
except ImportError as e:  # the CLI turns exit 3 into "install python3-matplotlib"
    print(f"charts.py: {sys.executable} cannot import matplotlib ({e}); install Debian's python3-matplotlib "
          f"and run it with /usr/bin/python3", file=sys.stderr)
    sys.exit(3)

# Runs whose verdict is not ok, on the time-vs-error chart (docs/verdicts.md).
STATUS_MARKERS = {"stretched": "s", "deformed": "D", "unstable": "X"}
PHASE_COLOURS = {"move": "tab:blue", "oscillate": "tab:orange", "wind": "tab:green"}
# Stages in the order a step runs them: the order of core/stage.h's name table.
STAGE_ORDER = ["upload", "dispatch", "references", "pose", "integrate", "global_shape", "local_shape", "length",
               "collision", "body_collision", "self_interaction", "rebuild", "follow_hairs", "sleep"]
SCHEMA_VERSIONS = (1, 2, 3)
# Distinct stage colours: tab20's saturated then light halves, its greys left out (grey
# is "untimed").
STAGE_PALETTE = [plt.get_cmap("tab20")(i) for i in list(range(0, 14, 2)) + [16, 18] + list(range(1, 14, 2)) + [17, 19]]
UNTIMED_COLOUR = (0.75, 0.75, 0.75, 1.0)
PNG_DPI = 90


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


def diverged(run):
    """Whether the run stopped early (schema version 1 called that "unstable")."""
    return run["status"] == "diverged" or ("verdict" not in run and run.get("failure") is not None)


def verdict_text(run):
    """The run's verdict class and, where one was decided, its frame: "ok", "stretched at
    frame 12", "diverged at frame 3" (docs/verdicts.md). Reports of schema version 1 have
    only status and failure."""
    v = run.get("verdict")
    frame = v.get("frame") if v else (run.get("failure") or {}).get("frame")
    return run["status"] if frame is None else f"{run['status']} at frame {frame}"


def run_label(run):
    k = knob_text(run)
    return run["model"] + (f" {k}" if k else "")


def load(path):
    try:
        with open(path, encoding="utf-8") as f:
            report = json.load(f)
    except (OSError, ValueError) as e:
        raise ReportError(f"cannot read the report: {e}")
    if report.get("schema") != "hairbench-report" or not isinstance(report.get("runs"), list):
        raise ReportError("schema: not a hairbench-report")
    if report.get("schema_version") not in SCHEMA_VERSIONS:
        raise ReportError(f"schema_version: {report.get('schema_version')!r} is not one of {SCHEMA_VERSIONS}")
    defs = report.get("metric_definitions")
    if not isinstance(defs, list) or not all(isinstance(d, dict) and isinstance(d.get("summaries"), list)
                                             and isinstance(d.get("columns"), list) for d in defs):
        raise ReportError("metric_definitions: missing or not a list of metrics (a report from a hairbench "
                          "before the metric table: run hairbench again)")
    return report


def timeseries_panels(report):
    """(series key, y label) of each metric drawn over time (metric_definitions)."""
    return [(next(c["name"] for c in d["columns"] if c["reported"]), d["timeseries_label"])
            for d in report["metric_definitions"] if d.get("timeseries_label")]


def summary_columns(report):
    """(metric, summary) of each summary the tables show (metric_definitions, in order)."""
    return [(d, s) for d in report["metric_definitions"] for s in d["summaries"] if s.get("label")]


def summary_value(run, metric, summary):
    v = run["metrics"].get(metric["name"])
    return v if not summary["key"] else (v or {}).get(summary["key"])


def asleep(run):
    """A run whose median step is faster than streaming its state once (roofline ratio
    under 1) did not move its hair: the model slept through the scenario. Without a
    roofline (GPU models), a step under 0.1 microseconds is shorter than any dispatch."""
    ratio = run["timing"].get("roofline_ratio")
    if ratio is not None:
        return ratio < 1.0
    t = num(run["timing"]["step_ms"]["median"])
    return math.isfinite(t) and t < 1e-4


def machine_of(report):
    """Run -> index of the machine that timed it, in a report merged from shards
    (hairbench merge); None in a report of one process."""
    shards = {sh["index"]: sh["machine"] for sh in (report.get("merge") or {}).get("shards", [])}
    return lambda run: shards.get(run.get("shard"))


def machine_groups(report, runs):
    """The runs split by the machine that timed them, [(label, runs)], so that no chart
    compares times from two machines; one group (label None) for a report of one machine,
    or when the merge was told --mix-machines (then mixed_note marks it)."""
    merge = report.get("merge") or {}
    if len(merge.get("machines", [])) < 2 or merge.get("mix_machines"):
        return [(None, runs)]
    which = machine_of(report)
    groups = {}
    for r in runs:
        groups.setdefault(which(r), []).append(r)
    return [(f"timed on machine {m + 1}: {merge['machines'][m]}", rs) for m, rs in sorted(groups.items())]


def mixed_note(report, runs):
    """With --mix-machines, where the runs' times come from more than one machine: the
    mark a chart carries."""
    merge = report.get("merge") or {}
    which = machine_of(report)
    machines = {which(r) for r in runs}
    if merge.get("mix_machines") and len(machines) > 1:
        return f"times from {len(machines)} machines mixed (--mix-machines)"
    return None


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
    ref = dev["reference"]
    o = dev.get("reference_overrides")
    if o:
        ref += " (" + ", ".join(f"{k} {v:g}" for k, v in sorted(o.items())) + ")"
    if not reference_ok(run):
        ref += ", itself " + dev["reference_status"]
    return ref


def reference_ok(run):
    """Whether the run's reference is ok on its scenario (reports before the field: yes)."""
    return run["metrics"]["deviation_vs_reference"].get("reference_status", "ok") == "ok"


def grid(n, ncols_max=3, w=5.2, h=4.0):
    ncols = min(ncols_max, max(1, n))
    nrows = (n + ncols - 1) // ncols
    fig, axes = plt.subplots(nrows, ncols, figsize=(w * ncols, h * nrows), squeeze=False)
    flat = [a for row in axes for a in row]
    for a in flat[n:]:
        a.set_visible(False)
    return fig, flat[:n]


def save(fig, out_dir, stem, name, written, svg):
    """PNG (a 256-colour palette: a third of the bytes of full colour, the same picture
    for lines and flat fills) and, when asked, SVG."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=PNG_DPI, bbox_inches="tight")
    paths = [os.path.join(out_dir, f"{stem}_{name}.png")]
    Image.open(buf).convert("RGB").quantize(256).save(paths[0], optimize=True)
    if svg:
        paths.append(os.path.join(out_dir, f"{stem}_{name}.svg"))
        fig.savefig(paths[1], bbox_inches="tight")
    plt.close(fig)
    written.extend(paths)
    return paths


def log_axis(axis, plain, dense_decades):
    """Readable log-axis labels whatever the range: 1-2-5 in each decade while the view
    spans at most `dense_decades` (room for them), decades only (at most ~8) beyond;
    never every minor tick. Under two ticks in view, matplotlib's LogLocator falls back
    to linear ticks, which is what a sliver of a decade needs."""
    lo, hi = sorted(axis.get_view_interval())
    decades = math.log10(hi / lo) if lo > 0 and hi > 0 else 0.0
    if decades > dense_decades:
        axis.set_major_locator(matplotlib.ticker.LogLocator(base=10.0, numticks=8))
        axis.set_minor_locator(matplotlib.ticker.LogLocator(base=10.0, subs=tuple(range(2, 10)), numticks=12))
    else:
        axis.set_major_locator(matplotlib.ticker.LogLocator(base=10.0, subs=(1.0, 2.0, 5.0), numticks=12))
        axis.set_minor_locator(matplotlib.ticker.LogLocator(base=10.0, subs=(3.0, 4.0, 6.0, 7.0, 8.0, 9.0),
                                                            numticks=12))
    axis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g") if plain else
                             matplotlib.ticker.LogFormatterSciNotation(labelOnlyBase=False))
    axis.set_minor_formatter(matplotlib.ticker.NullFormatter())


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

def machine_panels(report):
    """(scenario, machine label, runs) per chart panel: a scenario's runs, split by the
    machine that timed them (machine_groups)."""
    out = []
    for name in scenario_names(report):
        for label, runs in machine_groups(report, [r for r in report["runs"] if r["scenario"] == name]):
            out.append((name, label, runs))
    return out


def chart_time_vs_error(report, out_dir, stem, written, svg):
    colours = model_colours(report)
    split = machine_panels(report)
    fig, axes = grid(len(split))
    panels = []
    for ax, (name, machine, runs) in zip(axes, split):
        # Every run that went to the end is drawn; a stretched, deformed or unstable one is marked (its
        # numbers are real, its behaviour is not what the method promises). A run that
        # diverged has no comparable numbers and is named in the corner.
        stable = []
        stopped = []
        for r in runs:
            t = num(r["timing"]["step_ms"]["median"])
            e = num(r["metrics"]["deviation_vs_reference"]["rms"])
            if not diverged(r) and math.isfinite(t) and math.isfinite(e):
                stable.append((t, e, r))
            else:
                stopped.append(run_label(r))
        positive = [e for _, e, _ in stable if e > 0]
        # log axes cannot show 0: runs identical to the reference sit on a floor line.
        floor = (min(positive) / 4.0) if positive else 1e-6
        # A model asleep through the scenario (a few microseconds a step) would stretch the
        # time axis over decades nobody reads: it sits on the axis floor, marked.
        awake_t = [t for t, _, r in stable if not asleep(r) and t > 0]
        t_floor = min(awake_t) / 3.0 if awake_t else 1e-3
        sleepers = [run_label(r) for _, _, r in stable if asleep(r)]
        series = []
        for model in dict.fromkeys(r["model"] for r in runs):
            pts = sorted((p for p in stable if p[2]["model"] == model),
                         key=lambda p: p[2].get("knob", {}).get("value", 0.0))
            if not pts:
                continue
            xs = [max(e, floor) for _, e, _ in pts]
            ys = [t_floor if asleep(r) else t for t, _, r in pts]
            ax.plot(xs, ys, "-", color=colours[model], label=model, lw=1.5)
            for (t, e, r), x, y in zip(pts, xs, ys):
                sleeping = asleep(r)
                marker = STATUS_MARKERS.get(r["status"], "v" if sleeping else "o")
                ax.plot([x], [y], marker, color=colours[model], ms=7 if sleeping or marker != "o" else 5,
                        mfc="white" if sleeping or marker != "o" else colours[model], zorder=6)
                if "knob" in r:
                    ax.annotate(f"{r['knob']['value']:g}", (x, y), textcoords="offset points", xytext=(4, 4),
                                fontsize=7, color=colours[model])
                if e == 0:
                    ax.annotate("= reference", (x, y), textcoords="offset points", xytext=(4, -10), fontsize=7)
            series.append({"model": model, "points": len(pts)})
        # Against a reference that is not ok a deviation is no measure of accuracy: no front.
        sound = all(reference_ok(r) for r in runs)
        front = pareto_front([p for p in stable if p[2]["status"] == "ok"]) if sound else []
        if not sound:
            ax.text(0.5, 0.5, "the reference is not ok here:\ndeviations are not accuracy, no Pareto front",
                    transform=ax.transAxes, fontsize=8, color="tab:red", ha="center", va="center", alpha=0.8)
        for status, marker in STATUS_MARKERS.items():
            if any(r["status"] == status for _, _, r in stable):
                ax.plot([], [], marker, color="grey", mfc="white", label=status + " (docs/verdicts.md)")
        if front:
            fx = [max(e, floor) for _, e, _ in front]
            fy = [t_floor if asleep(r) else t for t, _, r in front]
            ax.step(fx, fy, where="post", color="black", lw=1, ls="--", alpha=0.6)
            ax.scatter(fx, fy, s=110, facecolors="none", edgecolors="black", lw=1.3, label="Pareto front", zorder=5)
        if positive and any(e == 0 for _, e, _ in stable):
            ax.axvline(floor, color="grey", lw=0.6, ls=":")
        if sleepers:
            ax.axhline(t_floor, color="grey", lw=0.6, ls=":")
            ax.plot([], [], "v", color="grey", mfc="white",
                    label=textwrap.fill("asleep (step ≈ 0 ms, drawn at the floor): " + ", ".join(sleepers), 40))
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("deviation vs reference (RMS over frames, / L̄)")
        ax.set_ylabel("median step time (ms)")
        knob = next((r["knob"]["name"] for r in runs if "knob" in r), None)
        title = f"{name}: run time vs error" + (f" over {knob}" if knob else "")
        mixed = mixed_note(report, runs)
        if machine:
            title += "\n" + textwrap.shorten(machine, 70)
        if mixed:
            title += "\n" + mixed
            ax.text(0.99, 0.99, "times from different machines", transform=ax.transAxes, fontsize=7,
                    color="tab:red", ha="right", va="top")
        ax.set_title(title + f"\nreference {reference_text(runs[0])}", fontsize=9)
        if stopped:
            ax.text(0.01, 0.01, "diverged: " + ", ".join(stopped), transform=ax.transAxes, fontsize=7,
                    color="tab:red", va="bottom")
        ax.grid(True, which="both", alpha=0.25)
        ax.legend(fontsize=7)
        panels.append({
            "scenario": name,
            "machine": machine,
            "mixed_machines": bool(mixed),
            "series": series,
            "pareto": [{"model": r["model"], "knob": r.get("knob"), "step_ms": t, "deviation": e}
                       for t, e, r in front],
            "diverged": stopped,
            "asleep": sleepers,
        })
    fig.tight_layout()
    for ax in axes:  # after the layout has fixed the view limits
        # deviations in powers of ten (wide labels: 1-2-5 only within a decade); milliseconds
        # as plain numbers (not 4x10^1), short enough for 1-2-5 over a few decades
        log_axis(ax.xaxis, plain=False, dense_decades=1.0)
        log_axis(ax.yaxis, plain=True, dense_decades=2.5)
    return {"files": save(fig, out_dir, stem, "time_vs_error", written, svg), "panels": panels}


# --- deviation and jaggedness over time -------------------------------------------------

def shade_phases(ax, info):
    for p in (info or {}).get("phases", []):
        ax.axvspan(p["start"], p["end"], color=PHASE_COLOURS.get(p["kind"], "grey"), alpha=0.12, lw=0)


def chart_timeseries(report, out_dir, stem, written, svg):
    names = scenario_names(report)
    colours = model_colours(report)
    metrics = timeseries_panels(report)
    fig, axes = plt.subplots(len(names), len(metrics), figsize=(6.5 * len(metrics), 3.3 * len(names)),
                             squeeze=False)
    panels = []
    for row, name in zip(axes, names):
        runs = [r for r in report["runs"] if r["scenario"] == name]
        info = scenario_info(report, name)
        panel = {"scenario": name, "phases": len((info or {}).get("phases", []))}
        for ax, (key, ylabel) in zip(row, metrics):
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
        row[-1].legend(handles, labels, fontsize=7, loc="upper right", ncol=2 if len(labels) > 8 else 1)
        panels.append(panel)
    fig.tight_layout()
    return {"files": save(fig, out_dir, stem, "timeseries", written, svg), "panels": panels}


# --- stage time breakdown ---------------------------------------------------------------

def stage_colours(report):
    """One colour per stage name in the report, the same in every panel, no two alike."""
    names = []
    for r in report["runs"]:
        for s in r["timing"].get("stage_ms", {}):
            if s not in names:
                names.append(s)
    names.sort(key=lambda s: (STAGE_ORDER.index(s) if s in STAGE_ORDER else len(STAGE_ORDER), s))
    if len(names) <= len(STAGE_PALETTE):
        palette = STAGE_PALETTE[:len(names)]
    else:  # more names than the table: hues spread evenly
        palette = [matplotlib.colors.hsv_to_rgb((i / len(names), 0.65, 0.85)) for i in range(len(names))]
    colours = {s: tuple(matplotlib.colors.to_rgba(c)) for s, c in zip(names, palette)}
    colours["untimed"] = UNTIMED_COLOUR
    return names, colours


def chart_stages(report, out_dir, stem, written, svg):
    split = machine_panels(report)
    fig, axes = grid(len(split), ncols_max=2, w=7.5, h=4.2)
    all_stages, stage_colour = stage_colours(report)
    panels = []
    for ax, (name, machine, runs) in zip(axes, split):
        labels = [run_label(r) for r in runs]
        bottom = [0.0] * len(runs)
        segments = []
        handles = []
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
            handles.append(ax.bar(range(len(runs)), vals, bottom=bottom, color=stage_colour[stage], label=stage))
            bottom = [b + v for b, v in zip(bottom, vals)]
            segments.append(stage)
        # Stages a scene did not need are 0 ms: the legend (outside the bars) says which
        # run skipped which, in how many of its steps, so "skipped" is not silently absent.
        skipped_lines = []
        for r in runs:
            skipped = r["timing"].get("stage_skipped_steps", {})
            if skipped:
                steps = r.get("frames_run", r["frames"])
                by_count = {}
                for stage, n in sorted(skipped.items()):
                    by_count.setdefault(n, []).append(stage)
                text = f"{run_label(r)}: " + "; ".join(f"{', '.join(st)} {n}/{steps}" for n, st in by_count.items())
                skipped_lines.append(textwrap.fill(text, 44, subsequent_indent="   "))
        labels_all = [h.get_label() for h in handles]
        if skipped_lines:
            handles.append(Patch(visible=False))
            labels_all.append("skipped in (steps/run):\n" + "\n".join(skipped_lines))
        ax.legend(handles, labels_all, fontsize=6, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0)
        ax.set_xticks(range(len(runs)))
        ax.set_xticklabels(labels, rotation=90, fontsize=7)
        ax.set_ylabel("ms per step (mean)")
        mixed = mixed_note(report, runs)
        ax.set_title(f"{name}: time per solver stage" + (f"\n{textwrap.shorten(machine, 80)}" if machine else "")
                     + (f"\n{mixed}" if mixed else ""), fontsize=9, color="tab:red" if mixed else "black")
        ax.grid(True, axis="y", alpha=0.25)
        panels.append({"scenario": name, "machine": machine, "mixed_machines": bool(mixed), "bars": len(runs), "stages": segments, "runs_with_skipped": len(skipped_lines),
                       "colours": {s: matplotlib.colors.to_hex(stage_colour[s]) for s in segments}})
    fig.tight_layout()
    return {"files": save(fig, out_dir, stem, "stages", written, svg), "panels": panels}


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


B64 = {c: i for i, c in enumerate("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/")}


def zigzag_varints(data):
    """Bytes of LEB128 varints (7 bits a byte, low first, the high bit set while more
    follow), each a zigzag-mapped signed integer -> (the integers, whether the last varint
    is whole)."""
    out = []
    z = shift = 0
    for b in data:
        z |= (b & 0x7F) << shift
        shift += 7
        if b & 0x80:
            continue
        out.append((z >> 1) ^ -(z & 1))
        z = shift = 0
    return out, shift == 0


def decode_strand(code, ref=None):
    """A snapshot strand -> [x0, y0, z0, x1, ...] in metres. Schema 1: the list itself;
    schema 2 (reports/report.h, encode_snapshot_strand): base64 of zigzag LEB128 varints,
    each the residual of a coordinate in 10-micrometre units (less the reference strand
    `ref`'s, decoded, for a snapshot marked relative_to_reference) from its prediction by
    the same axis of the two vertices before it; null: no finite position."""
    if code is None:
        return []
    if isinstance(code, list):
        return [num(v) for v in code]
    try:
        data = base64.b64decode(code, validate=True)
    except ValueError as e:
        raise ReportError(f"snapshots: strand {code[:16]!r}: not base64 ({e})")
    q = []
    residuals, whole = zigzag_varints(data)
    for r in residuals:
        n = len(q)
        q.append(r + (2 * q[n - 3] - q[n - 6] if n >= 6 else q[n - 3] if n >= 3 else 0))
    if not whole or len(q) % 3 or (ref is not None and len(ref) != len(q)):
        raise ReportError(f"snapshots: strand {code[:16]!r}: truncated, or not as long as the reference's")
    if ref is not None:
        q = [v + round(r / 1e-5) for v, r in zip(q, ref)]
    return [v * 1e-5 for v in q]


def points(flat):
    return [(flat[i], flat[i + 1], flat[i + 2]) for i in range(0, len(flat) - 2, 3)]


def snapshot_strands(snap, ref_flat):
    """Every strand of a snapshot as [(x, y, z), ...] ([] where null); `ref_flat`: the
    reference's strands at that frame, decoded (None when it has none)."""
    codes = snap.get("strands") or []
    refs = [None] * len(codes)
    if snap.get("relative_to_reference"):
        if ref_flat is None or len(ref_flat) != len(codes):
            raise ReportError(f"snapshots: {snap['label']}: relative to a reference snapshot the report lacks")
        refs = ref_flat
    return [points(decode_strand(code, ref)) for code, ref in zip(codes, refs)]


def chart_strands(report, out_dir, stem, written, svg):
    out = []
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
            ref_flat = [decode_strand(c) for c in ref_snap["strands"]] if ref_snap and ref_snap.get("strands") else None
            ref_strands = [points(f) for f in ref_flat or []]
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
                    ax.text(0, 0, "not reached\n(diverged)", ha="center", va="center", fontsize=8, color="tab:red")
                    collections.append(None)
                    continue
                segs, devs = [], []
                for si, pts in enumerate(snapshot_strands(snap, ref_flat)):
                    refp = ref_strands[si] if si < len(ref_strands) else None
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
                # thousands of segments: a raster inside an SVG, not one path each
                lc = LineCollection(segs, cmap="viridis", linewidths=0.7, rasterized=True)
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
        files = save(fig, out_dir, stem, f"strands_{name}", written, svg)
        out.append({"scenario": name, "files": files, "frames": [f["label"] for f in frames],
                    "columns": [c[0] for c in columns], "panels": len(collections),
                    "strands_per_panel": [c[1] if c else 0 for c in collections], "max_deviation": vmax})
    return out


# --- the motion player -----------------------------------------------------------------

def decode_animation(code, sizes):
    """A run's animation data (reports/animation.h) -> its frames, each a flat list of
    integer coordinates in the head's frame (unit_metres each), strand after strand of
    `sizes[s]` vertices: base64, zlib, zigzag LEB128 varints, each predicted from the same
    coordinate one frame back plus the move of the vertex before it (in frame 0, from the
    vertex before it; 0 at a root)."""
    try:
        data = zlib.decompress(base64.b64decode(code, validate=True))
    except (ValueError, zlib.error) as e:
        raise ReportError(f"animation: data {code[:16]!r}: {e}")
    root = [v == 0 for n in sizes for v in range(n) for _ in range(3)]
    per = len(root)
    q = []
    residuals, whole = zigzag_varints(data)
    for r in residuals if per else []:
        at = len(q)
        i = at % per
        if at < per:
            pred = 0 if root[i] else q[at - 3]
        else:
            pred = q[at - per] if root[i] else q[at - per] + q[at - 3] - q[at - per - 3]
        q.append(r + pred)
    if not whole or not per or len(q) % per:
        raise ReportError(f"animation: data {code[:16]!r}: truncated, or not whole frames of its strands")
    return [q[f:f + per] for f in range(0, len(q), per)]


def animation_world(anim, frame_k, flat):
    """One recorded frame's head-frame integers -> world points [(x, y, z), ...]."""
    h, u = anim["head"][frame_k], anim["unit_metres"]
    out = []
    for j in range(0, len(flat), 3):
        x, y, z = flat[j] * u, flat[j + 1] * u, flat[j + 2] * u
        out.append((h[3] * x + h[4] * y + h[5] * z + h[0], h[6] * x + h[7] * y + h[8] * z + h[1],
                    h[9] * x + h[10] * y + h[11] * z + h[2]))
    return out


def began_text(run):
    """A panel's second line: the verdict and the frame where it began (a stretched run's
    first frame over the limit, not its peak)."""
    v = run.get("verdict") or {}
    first = (v.get("stretch") or {}).get("first_above")
    if run["status"] == "stretched" and first is not None:
        return f"stretched from frame {first}", first
    if run["status"] == "ok" and (run.get("verdict") or {}).get("frame") is None:
        return "ok", None
    return verdict_text(run), v.get("frame")


def player_data(report):
    """What report.html's players read (reports/player.js): per scenario with animation
    frames, the recorded frames, the head, the strands and every run's panel, the
    reference's first."""
    out = []
    for si, name in enumerate(scenario_names(report)):
        info = scenario_info(report, name) or {}
        anim = info.get("animation")
        if not anim:
            continue
        # A run without frames (a merged shard's that drew other strands) says so in its panel.
        runs = [r for r in report["runs"] if r["scenario"] == name]
        runs.sort(key=lambda r: not (r.get("animation") or {}).get("same_as_reference", False))
        named = {n["strand"] for n in anim["named"]}
        panels = []
        ref = anim["reference"]
        if not any((r.get("animation") or {}).get("same_as_reference") for r in runs):  # the reference elsewhere
            panels.append({"label": f"reference {ref['model']}", "status": "ok",
                           "verdict": reference_text(runs[0]) if runs else "", "began": None,
                           "frames": ref["frames"], "data": ref["data"]})
        for r in runs:
            a = r.get("animation") or {"frames": 0, "same_as_reference": True}
            text, began = began_text(r)
            panels.append({"label": run_label(r), "status": r["status"], "verdict": text, "began": began,
                           "frames": a["frames"], "data": None if a.get("same_as_reference") else a["data"]})
        out.append({"id": f"hb-player-{si}", "name": name, "dt": info["dt"], "frameCount": info["frames"],
                    "stride": anim["stride"], "frames": anim["frames"], "head": anim["head"],
                    "unit": anim["unit_metres"], "sizes": [len(v) for v in anim["vertices"]],
                    "named": [s in named for s in anim["strands"]], "headRadius": info["head_radius"],
                    "meanStrandLength": info["mean_strand_length"],
                    "reference": {"model": anim["reference"]["model"], "frames": anim["reference"]["frames"],
                                  "data": anim["reference"]["data"]},
                    "phases": [{"start": p["start"], "end": p["end"],
                                "colour": matplotlib.colors.to_hex(PHASE_COLOURS.get(p["kind"], "0.6"))}
                               for p in info.get("phases", [])],
                    "panels": panels, "named_why": anim["named"]})
    return out


def player_html(report):
    """The players' section of report.html: the data as JSON, a block of controls per
    scenario, and reports/player.js inlined (no network, no library)."""
    e = html.escape
    scenarios = player_data(report)
    if not scenarios:
        return []
    lut = [matplotlib.colors.to_hex(plt.get_cmap("viridis")(i / 63)) for i in range(64)]
    out = ["<h2 id='motion'>Motion</h2>",
           "<p>Every run of a scenario side by side, the reference first, at the same frame and camera: a few strands "
           "spread over the groom plus every strand a verdict names (drawn thicker), every "
           f"{scenarios[0]['stride']}th frame or so (docs/report-schema.md#animation). Strands are coloured by their "
           "per-vertex deviation from the reference, on a log scale from 10⁻⁴ L̄ (dark) to 1 L̄ (yellow); the "
           "timeline shades the script's phases and ticks, red, the frame where each run's verdict began.</p>"]
    for sc in scenarios:
        why = "; ".join(f"strand {n['strand']} ({n['model']}: {n['why']})" for n in sc.pop("named_why"))
        out.append(f"<div class='hb-player' id='{sc['id']}'><h3>{e(sc['name'])}</h3>"
                   "<div class='hb-controls'><button class='hb-play'>play</button> <span class='hb-track'>"
                   f"<input class='hb-slider' type='range' min='0' max='{len(sc['frames']) - 1}' value='0'>"
                   "<canvas class='hb-timeline' width='600' height='10'></canvas></span> "
                   "<select class='hb-speed'><option value='0.25'>¼×</option><option value='0.5'>½×</option>"
                   "<option value='1' selected>1×</option><option value='2'>2×</option></select> "
                   "<span class='hb-frame'></span></div><div class='hb-panels'></div>"
                   f"<p class='hb-named'>{e('Strands named: ' + why) if why else ''}</p></div>")
    payload = json.dumps({"scenarios": scenarios, "viridis": lut}, separators=(",", ":")).replace("</", "<\\/")
    out.append(f"<script type='application/json' id='hb-player-data'>{payload}</script>")
    with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "player.js"), encoding="utf-8") as f:
        out.append(f"<script>{f.read()}</script>")
    return out


def panel_frames(sc):
    """Every panel's frames of a player_data() scenario, decoded: [[points per strand]...]."""
    def strands(flat, k):
        pts, out, at = animation_world(anim, k, flat), [], 0
        for n in sc["sizes"]:
            out.append(pts[at:at + n])
            at += n
        return out
    anim = {"head": sc["head"], "unit_metres": sc["unit"]}
    ref = decode_animation(sc["reference"]["data"], sc["sizes"])
    own = [[] if not p["frames"] else ref if p["data"] is None else decode_animation(p["data"], sc["sizes"])
           for p in sc["panels"]]
    return [[strands(f, k) for k, f in enumerate(q)] for q in own], [strands(f, k) for k, f in enumerate(ref)]


def write_animation(report, name, path):
    """The player of scenario `name` as a GIF (matplotlib's Pillow writer): the panels side
    by side, coloured as in the page, at the recorded frames' real rate."""
    sc = next((s for s in player_data(report) if s["name"] == name), None)
    if sc is None:
        have = ", ".join(s["name"] for s in player_data(report)) or "none"
        raise ReportError(f"--animate {name}: the report has no frames of that scenario (it has: {have})")
    from matplotlib.animation import FuncAnimation, PillowWriter
    frames, ref = panel_frames(sc)
    n = len(frames)
    cols = min(n, 4)
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(1.75 * cols, 1.95 * rows), dpi=72, squeeze=False)
    r_head, lbar = sc["headRadius"], sc["meanStrandLength"]
    # The page's view: centred on the head's mean position, the reference's strands and the
    # head in sight, at most 3 L-bar beyond the head (reports/player.js, Player.load).
    centre = [sum(h[a] for h in sc["head"]) / len(sc["head"]) for a in range(3)]
    heads = camera([h[:3] for h in sc["head"]], centre)
    travel = max(math.hypot(x, y) for x, y in heads)
    lim = max(max(abs(x), abs(y)) + r_head for x, y in heads)
    for strands in ref:
        lim = max([lim] + [max(abs(x), abs(y)) for pts in strands for x, y in camera(pts, centre)])
    lim = 1.05 * min(lim, r_head + 3 * lbar + travel)
    cmap = plt.get_cmap("viridis")
    artists = []
    for i, ax in enumerate(a for row in axes for a in row):
        ax.set_axis_off()
        if i >= n:
            continue
        p = sc["panels"][i]
        ax.set_xlim(-lim, lim)
        ax.set_ylim(-lim, lim)
        ax.set_aspect("equal")
        ax.set_title(f"{p['label']}\n{p['verdict']}", fontsize=6)
        head = Circle((0, 0), r_head, color="0.8", zorder=0)
        ax.add_patch(head)
        lc = LineCollection([], linewidths=0.8, cmap=cmap, norm=DEV_NORM)
        ax.add_collection(lc)
        artists.append((head, lc))
    title = fig.suptitle("", fontsize=7)

    def draw(k):
        for (head, lc), panel in zip(artists, frames):
            kk = min(k, len(panel) - 1)
            h = sc["head"][k]
            (hx, hy), = camera([h[:3]], centre)
            head.center = (hx, hy)
            segs, devs = [], []
            for s, pts in enumerate(panel[kk] if panel else []):
                refp = ref[kk][s] if kk < len(ref) else pts
                xy = camera(pts, centre)
                d = [math.dist(a, b) / lbar for a, b in zip(pts, refp)]
                for v in range(len(xy) - 1):
                    segs.append([xy[v], xy[v + 1]])
                    devs.append(max(0.5 * (d[v] + d[v + 1]), 1e-4))
            lc.set_segments(segs)
            lc.set_array(devs)
            lc.set_alpha(1.0 if kk == k else 0.35)
        f = sc["frames"][k]
        title.set_text(f"{name}: frame {f}, t = {(f + 1) * sc['dt']:.2f} s (colour: deviation from the reference)")
        return []

    anim = FuncAnimation(fig, draw, frames=len(sc["frames"]), blit=False)
    fig.subplots_adjust(left=0.01, right=0.99, bottom=0.01, top=0.86, wspace=0.05, hspace=0.3)
    anim.save(path, writer=PillowWriter(fps=1.0 / (sc["stride"] * sc["dt"])))
    plt.close(fig)


# --- tables -----------------------------------------------------------------------------

def table_columns(report):
    return (["model", "knob", "status", "median step ms", "ns/vertex"]
            + [s["label"] for _, s in summary_columns(report)] + ["Pareto", "material card (vs reference)"])


def table_rows(report, name, pareto):
    rows = []
    front = {(p["model"], json.dumps(p["knob"], sort_keys=True)) for p in pareto}
    shown = summary_columns(report)
    for r in report["runs"]:
        if r["scenario"] != name:
            continue
        on_front = (r["model"], json.dumps(r.get("knob"), sort_keys=True)) in front
        rows.append([r["model"], knob_text(r) or "–", verdict_text(r), fmt(r["timing"]["step_ms"]["median"]),
                     fmt(r["timing"]["ns_per_vertex"], ".1f")]
                    + [fmt(summary_value(r, d, s), s["format"].lstrip("%")) for d, s in shown]
                    + ["yes" if on_front else "", card_text(r) or "–"])
    return rows


def scenario_notes(report, name):
    info = scenario_info(report, name)
    notes = []
    runs = [r for r in report["runs"] if r["scenario"] == name]
    notes.append(f"reference: {reference_text(runs[0])}; {runs[0]['groom']['strands']} strands, "
                 f"{runs[0]['groom']['vertices']} vertices, {runs[0]['frames']} frames")
    if not reference_ok(runs[0]):
        dev = runs[0]["metrics"]["deviation_vs_reference"]
        notes.append(f"the reference is {dev['reference_status']} here ({dev.get('reference_reason', '')}): the "
                     "deviations are measured against it, not against a sound solution, and no Pareto front is drawn")
    merge = report.get("merge") or {}
    if len(merge.get("machines", [])) > 1:
        which = machine_of(report)
        by = {}
        for r in runs:
            by.setdefault(which(r), []).append(run_label(r))
        notes.append("timed on " + "; ".join(f"machine {m + 1} ({merge['machines'][m]}): {', '.join(labels)}"
                                            for m, labels in sorted(by.items())))
    if info:
        phases = "; ".join(f"{p['start']:.2f}–{p['end']:.2f} s {p['label']}" for p in info.get("phases", []))
        notes.append("phases: " + (phases or "none (the head holds still)"))
        for f in info.get("snapshots", {}).get("frames", []):
            if f["label"] == "most_violent":
                notes.append(f"most violent frame: {f['frame']} (t = {f['t']:.3f} s), reference kinetic energy "
                             f"relative to the head {fmt(f['violence'])} m²/s²")
    return notes


def device_text(d):
    """A GPU of context.devices: its name (all that versions 1 and 2 give), and its clock
    at the start and end of the run where it was read."""
    if isinstance(d, str):
        return d
    clock = d.get("clock_mhz") or {}
    if clock.get("start") is None and clock.get("end") is None:
        return f"{d.get('name', '?')} (clock not read)"
    return f"{d.get('name', '?')} ({fmt(clock.get('start'), '.0f')} → {fmt(clock.get('end'), '.0f')} MHz)"


def context_line(report):
    c = report.get("context", {})
    line = (f"{c.get('date', '?')} · git {c.get('git_sha', '?')} · {c.get('cpu', '?')} · "
            f"{c.get('threads', '?')} threads · {c.get('build_type', '?')} · {c.get('compiler', '?')}")
    for d in c.get("devices", []):
        line += f" · GPU {device_text(d)}"
    merge = report.get("merge")
    if merge:
        line += (f" · merged from {len(merge['shards'])} shards on {len(merge['machines'])} machine"
                 f"{'s' if len(merge['machines']) != 1 else ''}: "
                 + "; ".join(f"machine {i + 1}: {m}" for i, m in enumerate(merge["machines"]))
                 + (" · times from different machines are compared (--mix-machines)"
                    if merge.get("mix_machines") and len(merge["machines"]) > 1 else ""))
    return line


def write_markdown(report, path, pareto_by_scenario):
    lines = ["# hairbench report", "", context_line(report), ""]
    for name in scenario_names(report):
        lines += [f"## {name}", ""]
        lines += [f"- {n}" for n in scenario_notes(report, name)]
        columns = table_columns(report)
        lines += ["", "| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
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


def overview(report):
    """Rows (run labels: the models of a compare, model and knob value in a sweep) by
    scenarios; each cell the run's verdict, its median step over the reference model's in
    that scenario, its deviation and its jaggedness."""
    names = scenario_names(report)
    rows = list(dict.fromkeys(run_label(r) for r in report["runs"]))
    which = machine_of(report)
    cells = {}
    for name in names:
        runs = [r for r in report["runs"] if r["scenario"] == name]
        ref_model = runs[0]["metrics"]["deviation_vs_reference"]["reference"]
        # the reference model's own run at the scenario's parameters, when it is one of them
        ref_run = next((r for r in runs if r["model"] == ref_model
                        and r["metrics"]["deviation_vs_reference"]["max"] == 0), None)
        ref_t = num(ref_run["timing"]["step_ms"]["median"]) if ref_run else float("nan")
        for r in runs:
            t = num(r["timing"]["step_ms"]["median"])
            # A time over one from another machine is no ratio, unless the merge was
            # told --mix-machines; then the cell says so.
            other = ref_run is not None and which(r) != which(ref_run)
            mix = (report.get("merge") or {}).get("mix_machines", False)
            cells[(run_label(r), name)] = {
                "status": r["status"],
                "verdict": verdict_text(r),
                "asleep": asleep(r),
                "other_machine": other,
                "speed": t / ref_t if ref_t > 0 and math.isfinite(t) and (mix or not other) else float("nan"),
                "deviation": num(r["metrics"]["deviation_vs_reference"]["rms"]),
                "jaggedness": num(r["metrics"]["jaggedness"]["mean"]),
                "card": card_text(r),
            }
    return rows, names, cells


def card_text(run):
    """The run's material card beside the reference's (docs/metrics.md, The material card):
    each number over the reference's ("sag ×0.42 σ ×0.31 ω ×0.79"), or the reference's
    own numbers on its own run; "" for a report without cards."""
    m = run["metrics"].get("material")
    if not m or "skipped" in m:
        return ""
    ratios = m.get("vs_reference")
    own = run["metrics"]["deviation_vs_reference"]["max"] == 0
    if ratios and not own:
        return " ".join(f"{k} ×{fmt(ratios[key], '.2g')}" for k, key in (("sag", "sag"), ("σ", "sigma"), ("ω", "omega")))
    return f"sag {fmt(m['sag'], '.2g')} σ {fmt(m['sigma'], '.2g')}/s ω {fmt(m['omega'], '.2g')}/s"


DEV_NORM = matplotlib.colors.LogNorm(vmin=1e-4, vmax=1.0)
STATUS_COLOURS = {"stretched": "#fbe99a", "deformed": "#dcc3ee", "unstable": "#f9b56b", "diverged": "#ef8a8a"}


def cell_colour(c):
    """A verdict other than ok in its own colour (yellow, lilac, orange, red); an ok run's
    deviation on a log scale, 1e-4 L̄ (white) to 1 L̄ (blue), so that no deviation can be
    mistaken for a verdict; the reference itself pale grey."""
    if c["status"] in STATUS_COLOURS:
        return STATUS_COLOURS[c["status"]]
    d = c["deviation"]
    if not math.isfinite(d):
        return "#eeeeee"
    if d == 0:
        return "#e4e4e4"
    rgb = plt.get_cmap("Blues")(0.05 + 0.5 * float(DEV_NORM(min(max(d, 1e-4), 1.0))))[:3]
    return matplotlib.colors.to_hex(rgb)


def overview_html(report):
    e = html.escape
    rows, names, cells = overview(report)
    out = ["<h2 id='overview'>Overview</h2>",
           "<p>Each cell: verdict; median step time relative to the reference model's run in that scenario "
           "(×, lower is faster); deviation from the reference (RMS over frames, / L̄); jaggedness (mean); the "
           "material card over the reference's: static sag, and the slowest mode's decay rate σ and frequency ω "
           "(docs/metrics.md; on the reference's own run its numbers). "
           "Colour: yellow stretched, lilac deformed, orange unstable, red diverged (docs/verdicts.md); an ok run's "
           "deviation on a "
           "log scale from 10⁻⁴ (white) to 1 (blue); grey: the reference itself.</p>",
           "<table class='overview'><tr><th>model</th>" + "".join(f"<th>{e(n)}</th>" for n in names) + "</tr>"]
    for row in rows:
        tds = [f"<th>{e(row)}</th>"]
        for name in names:
            c = cells.get((row, name))
            if c is None:
                tds.append("<td class='none'>–</td>")
                continue
            verdict = "asleep" if c["status"] == "ok" and c["asleep"] else c["verdict"]
            v = c["speed"]
            speed = "–" if not math.isfinite(v) else f"×{v:.0f}" if v >= 10 else f"×{v:.2g}"
            if c["other_machine"]:
                speed += " (other machines)" if math.isfinite(v) else " (timed on another machine)"
            card = f"<br><small>{e(c['card'])}</small>" if c["card"] else ""
            tds.append(f"<td style='background:{cell_colour(c)}'><b>{e(verdict)}</b><br>{e(speed)}<br>"
                       f"dev {e(fmt(c['deviation'], '.2g'))}<br>jag {e(fmt(c['jaggedness'], '.2g'))}{card}</td>")
        out.append("<tr>" + "".join(tds) + "</tr>")
    out.append("</table>")
    return out


def truth_html(report):
    """The truth scenarios' panel (docs/truth.md): per model and truth scenario, each kicked
    mode's frequency error against the exact chain and its numerical damping (the decay
    rate σ with every damping term off), beside the model's speed there."""
    e = html.escape
    truth_runs = [r for r in report["runs"] if isinstance(r.get("truth"), dict)]
    if not truth_runs:
        return []
    scenarios = list(dict.fromkeys(r["scenario"] for r in truth_runs))
    out = ["<h2 id='truth'>Truth: the hanging chain</h2>",
           "<p>Each model in its chain limit (bending and shape terms, damping and gravity compensation off), "
           "started from strands kicked into the 1st, 2nd and 3rd mode of the chain it simulates, at its default "
           "step and iterations. Per mode: the frequency error ω/ω<sub>exact</sub> − 1 against the chain's exact "
           "answer of the chain it simulates (its nodes and their masses), and the numerical damping σ (1/s; the "
           "exact chain does not decay, &lt; 0 grows); beside them, how far that chain itself is from the "
           "continuous strand (its resolution's error). "
           "docs/truth.md gives the derivation and each model's limit.</p>"]
    for name in scenarios:
        runs = [r for r in truth_runs if r["scenario"] == name]
        modes = sorted({m["mode"] for r in runs for m in r["truth"].get("modes", [])})
        out.append(f"<h3>{e(name)}</h3><table><tr><th>model</th><th>masses</th>"
                   "<th>its chain vs the continuous strand, mode 1</th>"
                   + "".join(f"<th>mode {m} error</th>" for m in modes)
                   + "".join(f"<th>mode {m} σ, 1/s</th>" for m in modes)
                   + "<th>ns/vertex</th></tr>")
        for r in runs:
            t = r["truth"]
            if "skipped" in t:
                out.append(f"<tr><td>{e(r['model'])}</td><td colspan='{2 * len(modes) + 3}'>not kicked: "
                           f"{e(t['skipped'])}</td></tr>")
                continue
            by_mode = {m["mode"]: m for m in t["modes"]}
            masses = ", ".join(sorted({str(m["masses"]) for m in t["modes"]}))
            err = [fmt(num(by_mode[m]["frequency_error"]), "+.2e") if m in by_mode else "–" for m in modes]
            sig = [fmt(num(by_mode[m]["sigma"]), ".3g") if m in by_mode else "–" for m in modes]
            resolution = fmt(num(t["modes"][0].get("resolution_error")), "+.2e")
            out.append(f"<tr><td>{e(r['model'])}</td><td>{e(masses)}</td><td>{e(resolution)}</td>"
                       + "".join(f"<td>{e(c)}</td>" for c in err + sig)
                       + f"<td>{e(fmt(r['timing']['ns_per_vertex'], '.1f'))}</td></tr>")
        out.append("</table>")
    return out


def write_html(report, path, charts, pareto_by_scenario):
    e = html.escape
    parts = ["<!DOCTYPE html><html><head><meta charset='utf-8'><title>hairbench report</title><style>",
             "body{font-family:sans-serif;margin:1.5em;max-width:1800px}table{border-collapse:collapse;"
             "font-size:13px;margin:0.5em 0 1.5em}td,th{border:1px solid #ccc;padding:3px 7px;text-align:right}"
             "td:first-child,td:nth-child(2),td:nth-child(3){text-align:left}th{background:#eee}"
             "img{max-width:100%}figure{margin:1em 0}figcaption{color:#555;font-size:13px}"
             "tr.front td{background:#eef7ee}table.overview td{text-align:center;font-size:12px;line-height:1.3}"
             "table.overview th{text-align:left}.hb-panels{display:flex;flex-wrap:wrap;gap:4px}"
             ".hb-panel{margin:0;border:1px solid #ccc}.hb-panel figcaption{font-size:11px;padding:2px 4px;height:30px}"
             ".hb-stretched figcaption{background:#fbe99a}.hb-deformed figcaption{background:#dcc3ee}"
             ".hb-unstable figcaption{background:#f9b56b}.hb-diverged figcaption{background:#ef8a8a}"
             ".hb-track{display:inline-flex;flex-direction:column;vertical-align:middle}.hb-slider{width:600px;margin:0}.hb-named{font-size:12px;color:#555}",
             "</style></head><body>", "<h1>hairbench report</h1>", f"<p>{e(context_line(report))}</p>"]
    parts += overview_html(report)
    parts += truth_html(report)
    parts += player_html(report)
    parts.append(img_tag(charts["time_vs_error"]["files"][0], "Run time against error (log–log); the Pareto front "
                         "is ringed; runs asleep through a scenario sit on the time axis's floor"))
    parts.append("<h2>Details</h2>")
    for name in scenario_names(report):
        parts.append(f"<h3>{e(name)}</h3><ul>")
        parts += [f"<li>{e(n)}</li>" for n in scenario_notes(report, name)]
        columns = table_columns(report)
        pareto = columns.index("Pareto")
        parts.append("</ul><table><tr>" + "".join(f"<th>{e(c)}</th>" for c in columns) + "</tr>")
        for row in table_rows(report, name, pareto_by_scenario.get(name, [])):
            cls = " class='front'" if row[pareto] else ""
            parts.append(f"<tr{cls}>" + "".join(f"<td>{e(c)}</td>" for c in row) + "</tr>")
        parts.append("</table>")
    parts.append("<h2>Charts</h2>")
    drawn = " and ".join(label for _, label in timeseries_panels(report))
    parts.append(img_tag(charts["timeseries"]["files"][0], f"Over time: {drawn}; script phases shaded, the most "
                         "violent frame dotted"))
    parts.append(img_tag(charts["stages"]["files"][0], "Time per solver stage (mean per step); the legend lists the "
                         "stages each run skipped"))
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
    ap.add_argument("--animate", metavar="SCENARIO",
                    help="write only STEM_SCENARIO.gif, the scenario's motion player as an animation")
    ap.add_argument("--svg", action="store_true",
                    help="also write every chart as SVG (default: HAIRBENCH_SVG=1 in the environment)")
    args = ap.parse_args(argv)
    svg = args.svg or os.environ.get("HAIRBENCH_SVG", "") not in ("", "0")
    try:
        report = load(args.report)
        if not report["runs"]:
            raise ReportError("runs: the report has no runs")
        out_dir = args.out_dir or os.path.dirname(os.path.abspath(args.report))
        os.makedirs(out_dir, exist_ok=True)
        stem = os.path.splitext(os.path.basename(args.report))[0]
        plt.rcParams.update({"font.size": 8, "svg.fonttype": "none"})
        if args.animate:
            gif = os.path.join(out_dir, f"{stem}_{args.animate}.gif")
            write_animation(report, args.animate, gif)
            print(f"charts: wrote {gif}")
            return 0

        written = []
        charts = {
            "time_vs_error": chart_time_vs_error(report, out_dir, stem, written, svg),
            "timeseries": chart_timeseries(report, out_dir, stem, written, svg),
            "stages": chart_stages(report, out_dir, stem, written, svg),
            "strands": chart_strands(report, out_dir, stem, written, svg),
        }
    except ReportError as e:
        print(f"charts.py: {args.report}: {e}", file=sys.stderr)
        return 2
    pareto = {}
    for p in charts["time_vs_error"]["panels"]:
        pareto.setdefault(p["scenario"], []).extend(p["pareto"])
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
