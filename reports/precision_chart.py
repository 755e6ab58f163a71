#!/usr/bin/env python3
"""Work-precision diagram of a `hairbench precision` report: run time per frame against
error, log-log, one line per model along its cost knobs (every knob scaled together),
the Pareto front over all of them ringed; on a truth scenario a second panel draws the
numerical damping ratio against run time. The legend gives each line's order in the step
and its geometric rate per iteration (docs/precision.md).

usage: precision_chart.py PRECISION_JSON [OUT_DIR]   (needs matplotlib: Debian's
python3-matplotlib, i.e. run it with /usr/bin/python3)
"""

import math
import os
import sys

from chart_support import pyplot, read_report

plt = pyplot("precision_chart.py")


def finite(v):
    return isinstance(v, (int, float)) and math.isfinite(v) and v > 0


def fmt(v):
    return "-" if not isinstance(v, (int, float)) else f"{v:.2g}"


def label(line):
    step = line.get("step")
    it = line.get("iterations")
    parts = []
    if step:
        parts.append(f"order {fmt(step.get('order'))} in {step['knob']}")
    if it:
        parts.append(f"rate {fmt(it.get('rate'))}/iteration")
    return line["model"] + (f" ({', '.join(parts)})" if parts else "")


def draw(ax, lines, key, ylabel):
    for line in lines:
        pts = [p for p in line["work"] if finite(p.get("ms_per_frame")) and finite(p.get(key))]
        if not pts:
            continue
        xs = [p["ms_per_frame"] for p in pts]
        ys = [p[key] for p in pts]
        (handle,) = ax.plot(xs, ys, "o-", label=label(line), markersize=4)
        for p in pts:
            ax.annotate(f"x{p['factor']:g}", (p["ms_per_frame"], p[key]), fontsize=6,
                        xytext=(3, 3), textcoords="offset points")
        if key == "error":
            front = [p for p in pts if p.get("pareto")]
            ax.scatter([p["ms_per_frame"] for p in front], [p[key] for p in front], s=140,
                       facecolors="none", edgecolors=handle.get_color(), linewidths=1.5)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("run time, ms per frame")
    ax.set_ylabel(ylabel)
    ax.grid(True, which="both", alpha=0.3)


def main(argv):
    pr, out_dir = read_report(argv, "precision_chart.py", "precision", "precision", __doc__)
    lines = pr.get("lines")
    if not isinstance(lines, list):
        sys.exit(f"precision_chart.py: {argv[1]}: not a precision report (no lines)")
    exact = pr["reference"] == "exact"
    fig, axes = plt.subplots(1, 2 if exact else 1, figsize=(15 if exact else 9, 6.5), squeeze=False)
    draw(axes[0][0], lines, "error", "error: " + pr["error"].split(",")[0].split(" (")[0])
    axes[0][0].set_title(f"{pr['scenario']}: error against "
                         f"{'the exact chain' if exact else 'the model converged'} "
                         f"({pr['strands']} strands, {pr['frames']} frames); rings: the Pareto front",
                         fontsize=9)
    if exact:
        draw(axes[0][1], lines, "damping_ratio", "numerical damping ratio |sigma| / omega (exact: 0)")
        axes[0][1].set_title("numerical damping of the kicked modes", fontsize=9)
    axes[0][0].legend(fontsize=7, loc="best")
    fig.tight_layout()
    out = os.path.join(out_dir, "precision.png")
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
