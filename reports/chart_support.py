"""What the one-report chart scripts (stress_chart.py, reproduce_charts.py,
precision_chart.py) share: matplotlib on its file backend, the command line
SCRIPT REPORT_JSON [OUT_DIR], and one object of the report read, each failure one line.
"""

import json
import os
import sys


def pyplot(script):
    """matplotlib.pyplot on the Agg backend; without matplotlib, one line and exit code 3,
    which tells hairbench (harness/charts.cpp) to print how to draw the chart later."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print(f"{script}: matplotlib is missing for {sys.executable}: "
              "install python3-matplotlib and run with /usr/bin/python3", file=sys.stderr)
        sys.exit(3)
    return plt


def read_report(argv, script, key, what, usage):
    """(report[key], out_dir) from the command line; exits with one line when the file
    cannot be read or has no `key`."""
    if len(argv) < 2:
        sys.exit(usage)
    path = argv[1]
    out_dir = argv[2] if len(argv) > 2 else os.path.dirname(os.path.abspath(path))
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)[key], out_dir
    except (OSError, ValueError, KeyError) as e:
        sys.exit(f"{script}: {path}: not a {what} report ({e})")
