#!/usr/bin/env python3
"""Charts of a `hairbench reproduce` report: one small chart per claim that is about a
trend (the claim row's `chart`: series over a shared x axis), written as
OUT_DIR/charts/PAPER_CLAIM.png, which reproduce.md links and reproduce.html inlines.

usage: reproduce_charts.py REPRODUCE_JSON [OUT_DIR]   (needs matplotlib: Debian's
python3-matplotlib, i.e. run it with /usr/bin/python3)
"""

import math
import os
import sys

from chart_support import pyplot, read_report

plt = pyplot("reproduce_charts.py")


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
    papers, out_dir = read_report(argv, "reproduce_charts.py", "papers", "reproduce", __doc__)
    charts = os.path.join(out_dir, "charts")
    os.makedirs(charts, exist_ok=True)
    for p in papers:
        for c in p["claims"]:
            if c.get("chart"):
                draw(c["chart"], c["verdict"], os.path.join(charts, f'{p["id"]}_{c["id"]}.png'))


if __name__ == "__main__":
    main(sys.argv)
