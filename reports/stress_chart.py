#!/usr/bin/env python3
"""Heatmap of a `hairbench stress` report: one row per model x axis, one cell
per value tried in escalation order, green where the model stayed stable and red where
it failed; degenerate grooms as a second panel.

usage: stress_chart.py STRESS_JSON [OUT_DIR]   (needs matplotlib: Debian's
python3-matplotlib, i.e. run it with /usr/bin/python3)
"""

import os
import sys

from chart_support import pyplot, read_report

plt = pyplot("stress_chart.py")
from matplotlib.colors import ListedColormap  # noqa: E402 (after the backend is chosen)


def fmt(v):
    return f"{v:g}" if abs(v) >= 1e-3 or v == 0 else f"{v:.1e}"


def main(argv):
    stress, out_dir = read_report(argv, "stress_chart.py", "stress", "stress", __doc__)

    axes = stress["axes"]
    degenerate = stress["degenerate"]
    width = max([len(a["values"]) for a in axes] + [1])
    grooms = sorted({d["groom"] for d in degenerate})
    models = list(dict.fromkeys(d["model"] for d in degenerate))
    fig_h = 0.28 * (len(axes) + len(models)) + 2.0
    fig, (top, bottom) = plt.subplots(
        2, 1, figsize=(11, fig_h),
        gridspec_kw={"height_ratios": [max(len(axes), 1), max(len(models), 1)]})

    # 1 stable, 0 failed, NaN not tried (shorter axes).
    grid = [[float("nan")] * width for _ in axes]
    for r, a in enumerate(axes):
        for c, (v, ok) in enumerate(zip(a["values"], a["stable"])):
            grid[r][c] = 1.0 if ok else 0.0
            top.text(c, r, fmt(v), ha="center", va="center", fontsize=6)
    cmap = ListedColormap(["#e06666", "#93c47d"])
    cmap.set_bad("#eeeeee")
    top.imshow(grid, cmap=cmap, vmin=0, vmax=1, aspect="auto")
    top.set_yticks(range(len(axes)))
    top.set_yticklabels([f"{a['model']} · {a['axis']}" + (f" [{a['unit']}]" if a["unit"] else "")
                         for a in axes], fontsize=6)
    top.set_xticks([])
    top.set_title(f"Stress from '{stress['base']}' ({stress['groom']['strands']} strands): "
                  "green stable, red failed, values escalate to the right", fontsize=8)

    dgrid = [[float("nan")] * max(len(grooms), 1) for _ in models]
    for d in degenerate:
        r, c = models.index(d["model"]), grooms.index(d["groom"])
        # the verdict classes (docs/verdicts.md) and "refused" at load; stress.json files
        # written before the classes existed call a blow-up "unstable" too
        dgrid[r][c] = {"ok": 1.0, "stretched": 0.8, "deformed": 0.6, "refused": 0.4, "unstable": 0.2,
                       "diverged": 0.0}[d["status"]]
        bottom.text(c, r, d["status"], ha="center", va="center", fontsize=6)
    bottom.imshow(dgrid, cmap=ListedColormap(["#e06666", "#f6b26b", "#ffd966", "#dcc3ee", "#fff2cc", "#93c47d"]),
                  vmin=0, vmax=1, aspect="auto")
    bottom.set_yticks(range(len(models)))
    bottom.set_yticklabels(models, fontsize=6)
    bottom.set_xticks(range(len(grooms)))
    bottom.set_xticklabels(grooms, fontsize=6)
    bottom.set_title("Degenerate grooms: ok (green), stretched (pale yellow), deformed (lilac), refused at load "
                     "(yellow), unstable (orange) or diverged (red)", fontsize=8)
    fig.tight_layout()
    written = []
    for ext in ("png", "svg"):
        out = os.path.join(out_dir, f"stress_heatmap.{ext}")
        fig.savefig(out, dpi=130)
        written.append(out)
    print("wrote " + ", ".join(written))


if __name__ == "__main__":
    main(sys.argv)
