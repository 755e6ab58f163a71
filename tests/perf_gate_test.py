"""Unit tests of reports/perf_gate.py: the statistics against known values and the
decisions of the speed, instruction and accuracy gates."""

import json
import os
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "reports"))
import perf_gate  # noqa: E402


class MannWhitneyKnownValues(unittest.TestCase):
    # Reference values from scipy.stats.mannwhitneyu(x, y, alternative="two-sided")
    # (scipy 1.10, method "auto"), checked by hand for the exact small cases:
    # 5 vs 5 fully separated: 2 of C(10,5) = 252 arrangements are as extreme.
    def test_exact_fully_separated(self):
        r = perf_gate.mann_whitney_u([1, 2, 3, 4, 5], [6, 7, 8, 9, 10])
        self.assertEqual(r.method, "exact")
        self.assertEqual(r.u, 0.0)
        self.assertAlmostEqual(r.p, 2 / 252, places=15)

    def test_exact_unequal_sizes(self):
        # U = 1 of 3 x 4: P(U <= 1) = 2 / C(7,3) = 2/35, two-sided 4/35.
        r = perf_gate.mann_whitney_u([1.1, 2.2, 3.3], [2.5, 4.4, 5.5, 6.6])
        self.assertEqual(r.u, 1.0)
        self.assertAlmostEqual(r.p, 4 / 35, places=15)

    def test_asymptotic_with_ties(self):
        a = [10.1, 10.3, 10.2, 10.5, 10.4, 10.2, 10.6, 10.3, 10.1, 10.2]
        b = [10.4, 10.9, 11.0, 10.8, 10.7, 11.2, 10.9, 11.1, 10.8, 10.6]
        r = perf_gate.mann_whitney_u(a, b)
        self.assertEqual(r.method, "asymptotic")
        self.assertEqual(r.u, 3.0)
        self.assertAlmostEqual(r.p, 0.000418144432661332, places=12)
        r = perf_gate.mann_whitney_u([1, 2, 2, 3, 3, 3, 4, 5, 5], [3, 4, 4, 5, 6, 6, 7, 8, 9])
        self.assertEqual(r.u, 10.5)
        self.assertAlmostEqual(r.p, 0.00848290239309508, places=12)

    def test_asymptotic_large_no_ties(self):
        r = perf_gate.mann_whitney_u(list(range(20)), list(range(10, 30)))
        self.assertEqual(r.u, 50.0)
        self.assertAlmostEqual(r.p, 5.2125496206037515e-05, places=15)

    def test_identical_samples_are_not_different(self):
        r = perf_gate.mann_whitney_u(list(range(1, 10)), list(range(1, 10)))
        self.assertEqual(r.p, 1.0)
        self.assertEqual(perf_gate.mann_whitney_u([5, 5, 5], [5, 5, 5]).p, 1.0)

    def test_symmetric(self):
        x, y = [3.1, 2.9, 3.3, 3.0], [3.4, 3.6, 3.2, 3.5, 3.7]
        self.assertAlmostEqual(perf_gate.mann_whitney_u(x, y).p,
                               perf_gate.mann_whitney_u(y, x).p, places=15)


class SpeedDecisions(unittest.TestCase):
    base = {"BM_a": [100.0, 101.0, 99.0, 100.5, 99.5, 100.2, 99.8, 100.1, 99.9, 100.3]}

    def verdict(self, cand, threshold=0.10, alpha=0.01):
        return perf_gate.judge_speed(self.base, cand, threshold, alpha)[0]

    def test_planted_30_percent_slowdown_fails(self):
        v = self.verdict({"BM_a": [t * 1.3 for t in self.base["BM_a"]]})
        self.assertEqual(v.verdict, "REGRESSION")
        self.assertAlmostEqual(v.change, 0.3, places=2)
        self.assertLess(v.p, 0.01)

    def test_unchanged_passes(self):
        self.assertEqual(self.verdict({"BM_a": list(self.base["BM_a"])}).verdict, "ok")

    def test_small_significant_slowdown_passes(self):
        # +5%: significant but under the threshold.
        v = self.verdict({"BM_a": [t * 1.05 for t in self.base["BM_a"]]})
        self.assertLess(v.p, 0.01)
        self.assertEqual(v.verdict, "ok")

    def test_large_but_noisy_slowdown_is_not_significant(self):
        v = perf_gate.judge_speed({"BM_a": [100.0, 60.0, 140.0]},
                                  {"BM_a": [150.0, 70.0, 130.0]}, 0.10, 0.01)[0]
        self.assertGreater(v.change, 0.10)
        self.assertEqual(v.verdict, "not significant")

    def test_missing_benchmark_is_reported_not_failed(self):
        vs = perf_gate.judge_speed(self.base, {"BM_b": [1.0, 2.0]}, 0.1, 0.01)
        self.assertEqual(sorted(v.verdict for v in vs),
                         ["missing in baseline", "missing in candidate"])

    def test_instruction_counts(self):
        vs = perf_gate.judge_counts({"m/s": 1000}, {"m/s": 1150}, 0.10)
        self.assertEqual(vs[0].verdict, "REGRESSION")
        vs = perf_gate.judge_counts({"m/s": 1000}, {"m/s": 1090}, 0.10)
        self.assertEqual(vs[0].verdict, "ok")


def gated(name, key):
    return {"name": name, "summaries": [{"key": key, "gate": {"rel": 0.10, "abs": 1e-4}}]}


# The shape of hairbench's metric_definitions (reports/frame_metrics.h), its gated summaries.
DEFINITIONS = [gated("deviation_vs_reference", "rms"), gated("jaggedness", "mean"),
               gated("length_error", "rms"), gated("rest_shape_error", "")]


def report(runs, definitions=DEFINITIONS):
    return {"schema": "hairbench-report", "schema_version": 1, "runs": runs, "metric_definitions": definitions}


def run(model, status="ok", dev=0.01, jag=0.005, length=0.002, rest=0.02):
    return {"scenario": "shake", "model": model, "status": status,
            "metrics": {"deviation_vs_reference": {"rms": dev},
                        "jaggedness": {"mean": jag}, "length_error": {"rms": length},
                        "rest_shape_error": rest}}


class AccuracyDecisions(unittest.TestCase):
    def verdicts(self, base_runs, cand_runs):
        rows = perf_gate.judge_accuracy("b", report(base_runs), "c", report(cand_runs))
        return [r[4] for r in rows]

    def test_same_metrics_pass(self):
        self.assertTrue(all(v == "ok" for v in self.verdicts([run("m")], [run("m")])))

    def test_worse_deviation_fails(self):
        self.assertIn("REGRESSION", self.verdicts([run("m")], [run("m", dev=0.012)]))
        # within 10%: passes
        self.assertNotIn("REGRESSION", self.verdicts([run("m")], [run("m", dev=0.0105)]))

    def test_newly_unstable_fails(self):
        self.assertEqual(self.verdicts([run("m")], [run("m", status="unstable")]),
                         ["REGRESSION (no longer ok)"])

    def test_the_candidates_table_decides_what_is_gated(self):
        # A metric the table gates is checked; one it does not gate is not.
        base = run("m")
        base["metrics"]["penetration"] = {"max": 0.001}
        cand = run("m")
        cand["metrics"]["penetration"] = {"max": 0.01}
        plain = perf_gate.judge_accuracy("b", report([base]), "c", report([cand]))
        self.assertNotIn("penetration.max", [r[1] for r in plain])
        defs = DEFINITIONS + [gated("penetration", "max")]
        rows = perf_gate.judge_accuracy("b", report([base]), "c", report([cand], defs))
        self.assertIn(("penetration.max", "REGRESSION"), [(r[1], r[4]) for r in rows])

    def test_a_candidate_without_the_table_is_an_input_error(self):
        doc = report([run("m")])
        del doc["metric_definitions"]
        with self.assertRaises(perf_gate.GateError):
            perf_gate.judge_accuracy("b", report([run("m")]), "c", doc)

    def test_not_a_report_is_an_input_error(self):
        with self.assertRaises(perf_gate.GateError):
            perf_gate.judge_accuracy("b", {"runs": []}, "c", report([]))


class TimeSplit(unittest.TestCase):
    def test_sums_each_models_runs_and_reads_reports_before_steps_s(self):
        a, b, old = run("m"), run("m"), run("n")
        a["timing"] = {"steps_s": 2.0, "overhead_s": {"probe": 0.5, "twin": 0.25, "metrics_cpu": 1.0}}
        b["timing"] = {"steps_s": 1.0, "overhead_s": {"animation": 0.25, "metrics_cpu": 0.5}}
        old["series"] = {"step_ms": [1000.0, 500.0, None]}
        split = perf_gate.time_split(report([a, b, old]))
        self.assertEqual(split["m"], [3.0, 1.0, 1.5])
        self.assertEqual(split["n"], [1.5, 0.0, 0.0])
        table = perf_gate.time_split_table(report([old]), report([a, b, old]))
        self.assertIn("| m | nan / 3 | nan / 1 | nan / 1.5 | - / 0.83 |", table)
        self.assertIn("| n | 1.5 / 1.5 |", table)


class CommandLine(unittest.TestCase):
    def write(self, d, name, doc):
        path = os.path.join(d, name)
        with open(path, "w", encoding="utf-8") as f:
            json.dump(doc, f)
        return path

    def bench(self, times):
        return {"benchmarks": [{"name": "BM_a", "run_name": "BM_a", "run_type": "iteration",
                                "real_time": t, "time_unit": "ns"} for t in times]
                + [{"name": "BM_a_median", "run_name": "BM_a", "run_type": "aggregate",
                    "real_time": 1e9}]}

    def test_exit_codes(self):
        with tempfile.TemporaryDirectory() as d:
            base = self.write(d, "b.json", self.bench([100, 101, 99, 100, 102, 98, 100, 101, 99]))
            slow = self.write(d, "s.json", self.bench([130, 131, 129, 130, 132, 128, 130, 131, 129]))
            summary = os.path.join(d, "summary.md")
            self.assertEqual(perf_gate.main(["--baseline", base, "--candidate", base]), 0)
            self.assertEqual(perf_gate.main(["--baseline", base, "--candidate", slow,
                                             "--summary", summary]), 1)
            with open(summary, encoding="utf-8") as f:
                text = f.read()
            self.assertIn("| BM_a |", text)
            self.assertIn("REGRESSION", text)
            self.assertEqual(perf_gate.main(["--baseline", base]), 2)
            self.assertEqual(perf_gate.main(["--baseline", os.path.join(d, "none.json"),
                                             "--candidate", base]), 2)
            self.assertEqual(perf_gate.main([]), 2)


if __name__ == "__main__":
    unittest.main()
