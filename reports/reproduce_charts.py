#!/usr/bin/env python3
"""Charts of a `hairbench reproduce` report: one small chart per claim that is about a
trend (the claim row's `chart`: series over a shared x axis), written as
OUT_DIR/charts/PAPER_CLAIM.png, which reproduce.md links and reproduce.html inlines.

usage: reproduce_charts.py REPRODUCE_JSON [OUT_DIR]   (needs matplotlib: Debian's
python3-matplotlib, i.e. run it with /usr/bin/python3)
"""

import json
import math
import os
import sys

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    # Exit code 3 tells hairbench (harness/charts.cpp) to print how to draw it later.
    print(f"reproduce_charts.py: matplotlib is missing for {sys.executable}: "
          "install python3-matplotlib and run with /usr/bin/python3", file=sys.stderr)
    sys.exit(3)


def draw(chart, verdict, path):
    fig, ax = plt.subplots(figsize=(4.8, 3.2), dpi=100)
    xs = chart["x"]
    for s in chart["series"]:
        pts = [(x, y) for x, y in zip(xs, s["y"]) if x is not None and y is not None and math.isfinite(y)]
        if pts:
            style = "--" if s["label"].startswith("fit") or "a + b" in s["label"] else "-o"
            ax.plot([p[0] for p in pts], [p[1] for p in pts], style, label=s["label"], markersize=4)
    if chart.get("log_x"):
        ax.set_xscale("log")
        # Few x values (iteration counts, strand counts): label each one plainly.
        ticks = [x for x in xs if x is not None]
        ax.set_xticks(ticks)
        ax.set_xticklabels([f"{x:g}" for x in ticks])
        ax.minorticks_off()
    if chart.get("log_y"):
        ax.set_yscale("log")
    ax.set_xlabel(chart["x_label"])
    ax.set_ylabel(chart["y_label"])
    ax.set_title(f'{chart["title"]} ({verdict})', fontsize=9)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def main(argv):
    if len(argv) < 2:
        sys.exit(__doc__)
    path = argv[1]
    out_dir = argv[2] if len(argv) > 2 else os.path.dirname(os.path.abspath(path))
    try:
        with open(path, encoding="utf-8") as f:
            papers = json.load(f)["papers"]
    except (OSError, ValueError, KeyError) as e:
        sys.exit(f"reproduce_charts.py: {path}: not a reproduce report ({e})")
    charts = os.path.join(out_dir, "charts")
    os.makedirs(charts, exist_ok=True)
    for p in papers:
        for c in p["claims"]:
            if c.get("chart"):
                draw(c["chart"], c["verdict"], os.path.join(charts, f'{p["id"]}_{c["id"]}.png'))


if __name__ == "__main__":
    main(sys.argv)
