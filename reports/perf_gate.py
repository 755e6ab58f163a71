#!/usr/bin/env python3
"""Performance and accuracy gate: candidate against baseline.

Speed: per benchmark, the samples are the repetitions of Google Benchmark's own JSON
(run_type "iteration"; real_time, which is the manual time of hairbench_bench). A
benchmark regresses only when its median slowed down by more than the threshold AND a
two-sided Mann-Whitney U test says the two sample sets differ (p < alpha), the rule
Google Benchmark's tools/compare.py applies: a large change on two noisy samples or a
significant but tiny change both pass.

Instructions: the same decision on callgrind instruction counts (one sample each:
deterministic, so only the threshold applies).

Accuracy: per model x scenario of two hairbench reports, the metrics must not worsen by
more than their stated tolerance, and no run that was ok may get another verdict.

Exit codes: 0 pass, 1 regression, 2 could not run. Standard library only, so it runs
with any Python 3.
"""

import argparse
import json
import math
import statistics
import sys
from dataclasses import dataclass


class GateError(Exception):
    """Input the gate cannot judge (missing file, wrong schema): exit code 2."""


# --- Mann-Whitney U -------------------------------------------------------------


def _ranks(values):
    """Average ranks (1-based) of values, ties sharing the mean of their positions."""
    order = sorted(range(len(values)), key=lambda i: values[i])
    ranks = [0.0] * len(values)
    i = 0
    while i < len(order):
        j = i
        while j + 1 < len(order) and values[order[j + 1]] == values[order[i]]:
            j += 1
        for k in range(i, j + 1):
            ranks[order[k]] = (i + j) / 2.0 + 1.0
        i = j + 1
    return ranks


def _tie_sizes(values):
    counts = {}
    for v in values:
        counts[v] = counts.get(v, 0) + 1
    return [t for t in counts.values() if t > 1]


def _exact_cdf(u, n1, n2):
    """P(U <= u) under H0, by counting the arrangements of n1 x's among n1+n2 ranks
    with the recurrence f(n1, n2, u) = f(n1-1, n2, u-n2) + f(n1, n2-1, u)."""
    u = int(math.floor(u))
    if u < 0:
        return 0.0
    # counts[m][k]: arrangements with m y's placed so far and statistic k; built row by
    # row over x's to keep memory at O(n2 * n1 n2).
    max_u = n1 * n2
    prev = [[1] + [0] * max_u for _ in range(n2 + 1)]  # zero x's: U = 0 for every m
    for a in range(1, n1 + 1):
        cur = [[0] * (max_u + 1) for _ in range(n2 + 1)]
        cur[0][0] = 1  # no y's: every x precedes nothing, U = 0
        for b in range(1, n2 + 1):
            for k in range(max_u + 1):
                # the largest element is an x (it beats all b y's) or a y
                v = cur[b - 1][k]
                if k >= b:
                    v += prev[b][k - b]
                cur[b][k] = v
        prev = cur
    dist = prev[n2]
    total = math.comb(n1 + n2, n1)
    return sum(dist[: min(u, max_u) + 1]) / total


@dataclass
class UTest:
    u: float  # U of the first sample (scipy's `statistic`)
    p: float  # two-sided
    method: str  # "exact" or "asymptotic"


def mann_whitney_u(x, y):
    """Two-sided Mann-Whitney U test. Exact distribution when a sample has at most 8
    values and there are no ties; otherwise the normal approximation with the tie
    correction of the variance and a continuity correction of 0.5 (the conventions of
    scipy.stats.mannwhitneyu's 'auto', so results can be checked against it)."""
    n1, n2 = len(x), len(y)
    if n1 == 0 or n2 == 0:
        raise GateError("Mann-Whitney U needs at least one sample on each side")
    combined = list(x) + list(y)
    ranks = _ranks(combined)
    r1 = sum(ranks[:n1])
    u1 = r1 - n1 * (n1 + 1) / 2.0
    u2 = n1 * n2 - u1
    ties = _tie_sizes(combined)
    if min(n1, n2) <= 8 and not ties:
        p = 2.0 * min(_exact_cdf(u1, n1, n2), _exact_cdf(u2, n1, n2))
        return UTest(u1, min(p, 1.0), "exact")
    n = n1 + n2
    mu = n1 * n2 / 2.0
    tie_term = sum(t ** 3 - t for t in ties) / (n * (n - 1))
    var = n1 * n2 / 12.0 * ((n + 1) - tie_term)
    if var <= 0.0:  # every value equal: no evidence of a difference
        return UTest(u1, 1.0, "asymptotic")
    z = (max(u1, u2) - mu - 0.5) / math.sqrt(var)
    p = math.erfc(z / math.sqrt(2.0))  # 2 * (1 - Phi(z))
    return UTest(u1, min(max(p, 0.0), 1.0), "asymptotic")


# --- Google Benchmark JSON --------------------------------------------------------


def load_json(path):
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except OSError as e:
        raise GateError(f"{path}: cannot read: {e.strerror}") from None
    except json.JSONDecodeError as e:
        raise GateError(f"{path}: not JSON: line {e.lineno}: {e.msg}") from None


_NS_PER = {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}


def benchmark_samples(docs):
    """{benchmark name: [real_time, ...]} from one or more Google Benchmark JSON
    documents (the rounds of an interleaved run), in the order they appear."""
    samples = {}
    for path, doc in docs:
        if not isinstance(doc, dict) or not isinstance(doc.get("benchmarks"), list):
            raise GateError(f"{path}: benchmarks: missing (not Google Benchmark JSON)")
        for b in doc["benchmarks"]:
            if b.get("run_type", "iteration") != "iteration" or "error_occurred" in b:
                continue
            name = b.get("run_name", b.get("name"))
            t = b.get("real_time")
            if not isinstance(name, str) or not isinstance(t, (int, float)):
                raise GateError(f"{path}: benchmarks: entry without name or real_time")
            # Benchmarks report in their own unit (hairbench_bench's BM_step in ms): the
            # summary table is in ns.
            unit = b.get("time_unit", "ns")
            if unit not in _NS_PER:
                raise GateError(f"{path}: benchmarks: {name}: unknown time_unit '{unit}'")
            samples.setdefault(name, []).append(float(t) * _NS_PER[unit])
    return samples


@dataclass
class Verdict:
    name: str
    baseline: float
    candidate: float
    change: float  # candidate / baseline - 1
    p: float  # None in instruction mode
    verdict: str  # "ok", "faster", "slower (noise)", "REGRESSION", "missing"


def judge_speed(base, cand, threshold, alpha):
    verdicts = []
    for name in sorted(set(base) | set(cand)):
        if name not in base or name not in cand:
            side = "baseline" if name not in base else "candidate"
            verdicts.append(Verdict(name, math.nan, math.nan, math.nan, None,
                                    f"missing in {side}"))
            continue
        mb, mc = statistics.median(base[name]), statistics.median(cand[name])
        change = mc / mb - 1.0 if mb > 0 else math.inf
        p = mann_whitney_u(base[name], cand[name]).p
        if change > threshold and p < alpha:
            v = "REGRESSION"
        elif change < -threshold and p < alpha:
            v = "faster"
        elif abs(change) > threshold:
            v = "not significant"
        else:
            v = "ok"
        verdicts.append(Verdict(name, mb, mc, change, p, v))
    return verdicts


def judge_counts(base, cand, threshold):
    """Instruction counts: deterministic, one value per benchmark."""
    verdicts = []
    for name in sorted(set(base) | set(cand)):
        if name not in base or name not in cand:
            side = "baseline" if name not in base else "candidate"
            verdicts.append(Verdict(name, math.nan, math.nan, math.nan, None,
                                    f"missing in {side}"))
            continue
        b, c = base[name], cand[name]
        change = c / b - 1.0 if b > 0 else math.inf
        v = "REGRESSION" if change > threshold else (
            "faster" if change < -threshold else "ok")
        verdicts.append(Verdict(name, b, c, change, None, v))
    return verdicts


# --- Accuracy from hairbench reports -----------------------------------------------

def accuracy_tolerances(path, doc):
    """metric path in a run -> (relative tolerance, absolute floor), from the report's
    metric_definitions (hairbench's metric table, reports/frame_metrics.h): each summary
    with a gate. A candidate value may exceed the baseline by max(rel * baseline, abs)."""
    defs = doc.get("metric_definitions") if isinstance(doc, dict) else None
    if not isinstance(defs, list):
        raise GateError(f"{path}: metric_definitions: missing (a report from a hairbench before the metric "
                        "table: run the candidate's hairbench again)")
    out = {}
    for d in defs:
        for s in d.get("summaries", []):
            gate = s.get("gate")
            if isinstance(gate, dict):
                key = (d["name"], s["key"]) if s.get("key") else (d["name"],)
                out[key] = (float(gate["rel"]), float(gate["abs"]))
    return out


def _metric(run, path):
    v = run.get("metrics", {})
    for key in path:
        if not isinstance(v, dict):
            return None
        v = v.get(key)
    return v if isinstance(v, (int, float)) else None


def _runs_by_key(path, doc):
    if not isinstance(doc, dict) or doc.get("schema") != "hairbench-report":
        raise GateError(f"{path}: schema: not a hairbench-report")
    runs = {}
    for r in doc.get("runs", []):
        knob = r.get("knob")
        key = (r.get("scenario"), r.get("model"),
               json.dumps(knob, sort_keys=True) if knob else "")
        runs[key] = r
    return runs


def judge_accuracy(base_path, base_doc, cand_path, cand_doc):
    """Rows (run, metric, baseline, candidate, verdict) for every gated metric of the
    candidate's table."""
    base, cand = _runs_by_key(base_path, base_doc), _runs_by_key(cand_path, cand_doc)
    tolerances = accuracy_tolerances(cand_path, cand_doc)
    rows = []
    for key in sorted(set(base) & set(cand)):
        b, c = base[key], cand[key]
        label = f"{key[1]} / {key[0]}" + (f" [{key[2]}]" if key[2] else "")
        if b.get("status") == "ok" and c.get("status") != "ok":
            rows.append((label, "status", "ok", c.get("status"), "REGRESSION (no longer ok)"))
            continue
        for path, (rel, floor) in tolerances.items():
            vb, vc = _metric(b, path), _metric(c, path)
            if vb is None or vc is None:
                continue
            limit = vb + max(rel * abs(vb), floor)
            verdict = "REGRESSION" if vc > limit else "ok"
            rows.append((label, ".".join(path), f"{vb:.4g}", f"{vc:.4g}", verdict))
    return rows


def time_split(doc):
    """Per model, summed over its runs: the timed steps, its own work outside them (probe,
    rest twin, setup, steps past the end, the player's frames; wall s) and its metrics'
    CPU s, from runs[].timing (docs/report-schema.md). A report from before timing.steps_s
    sums series.step_ms; one without overhead_s counts none."""
    out = {}
    for r in doc.get("runs", []):
        t = r.get("timing", {})
        steps = t.get("steps_s")
        if not isinstance(steps, (int, float)):
            steps = sum(v for v in r.get("series", {}).get("step_ms", []) if isinstance(v, (int, float))) / 1e3
        over = t.get("overhead_s", {})
        own = sum(v for k, v in over.items() if k != "metrics_cpu" and isinstance(v, (int, float)))
        m = out.setdefault(r.get("model"), [0.0, 0.0, 0.0])
        m[0] += steps
        m[1] += own
        m[2] += over.get("metrics_cpu", 0.0) if isinstance(over.get("metrics_cpu"), (int, float)) else 0.0
    return out


def time_split_table(base_doc, cand_doc):
    """Baseline and candidate side by side, per model: where each run's time went. Not a
    gate: the speed gate is the benchmarks'; this says where a change moved the time."""
    base, cand = time_split(base_doc), time_split(cand_doc)
    lines = ["| model | steps s (base / cand) | own overhead s | metrics CPU s | overhead / steps |",
             "|---|---:|---:|---:|---:|"]
    for model in sorted(set(base) | set(cand), key=str):
        b, c = base.get(model, [math.nan] * 3), cand.get(model, [math.nan] * 3)
        share = ["-" if not x[0] > 0 else f"{(x[1] + x[2]) / x[0]:.2f}" for x in (b, c)]
        lines.append(f"| {model} | {b[0]:.3g} / {c[0]:.3g} | {b[1]:.3g} / {c[1]:.3g} | {b[2]:.3g} / {c[2]:.3g} "
                     f"| {share[0]} / {share[1]} |")
    return "\n".join(lines)


# --- Output ------------------------------------------------------------------------


def speed_table(verdicts, unit):
    lines = [f"| benchmark | baseline ({unit}) | candidate ({unit}) | change | p-value | verdict |",
             "|---|---:|---:|---:|---:|---|"]
    for v in verdicts:
        p = "-" if v.p is None else f"{v.p:.2g}"
        change = "-" if math.isnan(v.change) else f"{v.change * 100:+.1f}%"
        base = "-" if math.isnan(v.baseline) else f"{v.baseline:.4g}"
        cand = "-" if math.isnan(v.candidate) else f"{v.candidate:.4g}"
        lines.append(f"| {v.name} | {base} | {cand} | {change} | {p} | {v.verdict} |")
    return "\n".join(lines)


def accuracy_table(rows):
    lines = ["| run | metric | baseline | candidate | verdict |", "|---|---|---:|---:|---|"]
    lines += [f"| {r[0]} | {r[1]} | {r[2]} | {r[3]} | {r[4]} |" for r in rows]
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--baseline", nargs="+", default=[],
                    help="Google Benchmark JSON files of the baseline (one per round)")
    ap.add_argument("--candidate", nargs="+", default=[],
                    help="Google Benchmark JSON files of the candidate (one per round)")
    ap.add_argument("--baseline-counts", help="JSON {name: instructions} of the baseline")
    ap.add_argument("--candidate-counts", help="JSON {name: instructions} of the candidate")
    ap.add_argument("--baseline-report", help="hairbench report.json of the baseline")
    ap.add_argument("--candidate-report", help="hairbench report.json of the candidate")
    ap.add_argument("--threshold", type=float, default=0.10,
                    help="slowdown that fails, as a fraction (default 0.10)")
    ap.add_argument("--alpha", type=float, default=0.01,
                    help="significance level of the U test (default 0.01)")
    ap.add_argument("--summary", help="also write the Markdown summary to this file")
    args = ap.parse_args(argv)

    try:
        sections, failed = [], False
        if args.baseline or args.candidate:
            if not (args.baseline and args.candidate):
                raise GateError("--baseline and --candidate go together")
            base = benchmark_samples([(p, load_json(p)) for p in args.baseline])
            cand = benchmark_samples([(p, load_json(p)) for p in args.candidate])
            if not base or not cand:
                raise GateError("no benchmark samples to compare (empty filter?)")
            verdicts = judge_speed(base, cand, args.threshold, args.alpha)
            failed |= any(v.verdict == "REGRESSION" for v in verdicts)
            reps = min(len(s) for s in list(base.values()) + list(cand.values()))
            sections.append(
                f"### Speed (median real time; fails above +{args.threshold:.0%} with "
                f"p < {args.alpha}; {reps}+ samples per side)\n\n"
                + speed_table(verdicts, "ns"))
        if args.baseline_counts or args.candidate_counts:
            if not (args.baseline_counts and args.candidate_counts):
                raise GateError("--baseline-counts and --candidate-counts go together")
            verdicts = judge_counts(load_json(args.baseline_counts),
                                    load_json(args.candidate_counts), args.threshold)
            failed |= any(v.verdict == "REGRESSION" for v in verdicts)
            sections.append(f"### Instructions (callgrind; fails above "
                            f"+{args.threshold:.0%})\n\n" + speed_table(verdicts, "Ir"))
        if args.baseline_report or args.candidate_report:
            if not (args.baseline_report and args.candidate_report):
                raise GateError("--baseline-report and --candidate-report go together")
            cand_doc = load_json(args.candidate_report)
            rows = judge_accuracy(args.baseline_report, load_json(args.baseline_report),
                                  args.candidate_report, cand_doc)
            failed |= any(r[4].startswith("REGRESSION") for r in rows)
            tol = ", ".join(f"{'.'.join(k)} +max({r:.0%}, {a:g})"
                            for k, (r, a) in accuracy_tolerances(args.candidate_report, cand_doc).items())
            sections.append(f"### Accuracy (tolerances: {tol}; a run no longer ok "
                            "fails)\n\n" + accuracy_table(rows))
            sections.append("### Where the time went (per model, summed over scenarios; not gated)\n\n"
                            + time_split_table(load_json(args.baseline_report), cand_doc))
        if not sections:
            raise GateError("nothing to compare: give benchmark, count or report files")
    except GateError as e:
        print(f"perf-gate: {e}", file=sys.stderr)
        return 2

    summary = (f"## Performance gate: {'FAIL' if failed else 'pass'}\n\n"
               + "\n\n".join(sections) + "\n")
    print(summary)
    if args.summary:
        with open(args.summary, "w", encoding="utf-8") as f:
            f.write(summary)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
