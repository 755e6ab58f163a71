#!/usr/bin/env python3
"""The engine files a user copies (docs/sharding.md): ci/github-sweep.yml is loaded as
YAML and checked for the workflow keys GitHub reads and the ones the sharding relies on,
and its command is planned by the binary; ci/slurm-sweep.sh runs with stub `sbatch` and
`srun` on PATH that run the array's tasks here, so that the script's logic (the array
0..N-1, one shard per task, the merge after every task succeeded) is exercised, not
Slurm.

usage: ci_files_test.py HAIRBENCH_BINARY (the repository is this file's parent's parent)
"""

import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
HAIRBENCH = None  # set from the command line
TINY = os.path.join(ROOT, "tests", "data", "reports", "tiny_shake.json")

# The keys GitHub Actions accepts where this workflow uses them (the workflow syntax's
# top level, a job, a step); anything else is a typo GitHub would reject.
WORKFLOW_KEYS = {"name", "on", "env", "jobs", "permissions", "concurrency", "defaults", "run-name"}
JOB_KEYS = {"name", "needs", "runs-on", "container", "strategy", "steps", "env", "if", "outputs", "permissions",
            "timeout-minutes", "services", "defaults", "environment", "concurrency", "continue-on-error"}
STEP_KEYS = {"name", "id", "if", "uses", "run", "with", "env", "shell", "working-directory", "continue-on-error",
             "timeout-minutes"}


class GithubWorkflow(unittest.TestCase):
    def setUp(self):
        with open(os.path.join(ROOT, "ci", "github-sweep.yml"), encoding="utf-8") as f:
            self.wf = yaml.safe_load(f)
        # YAML 1.1 reads the key `on` as the boolean true.
        self.on = self.wf.get("on", self.wf.get(True))

    def test_workflow_syntax(self):
        keys = {"on" if k is True else k for k in self.wf}
        self.assertLessEqual(keys, WORKFLOW_KEYS)
        self.assertIsNotNone(self.on)
        for name, job in self.wf["jobs"].items():
            self.assertLessEqual(set(job), JOB_KEYS, name)
            self.assertIn("runs-on", job, name)
            for step in job["steps"]:
                self.assertLessEqual(set(step), STEP_KEYS, f"{name}: {step}")
                self.assertEqual(("uses" in step) + ("run" in step), 1, f"{name}: a step needs uses or run: {step}")
                if "uses" in step:
                    self.assertRegex(step["uses"], r"^[\w-]+/[\w-]+@v\d+$")

    def test_matrix_is_the_shard_count(self):
        n = self.wf["env"]["SHARDS"]
        strategy = self.wf["jobs"]["shard"]["strategy"]
        self.assertEqual(strategy["matrix"]["shard"], list(range(1, n + 1)))
        self.assertIs(strategy["fail-fast"], False)

    def step(self, job, pattern):
        for s in self.wf["jobs"][job]["steps"]:
            if re.search(pattern, s.get("run", "") + s.get("uses", "")):
                return s
        self.fail(f"{job}: no step matches {pattern}")

    def test_each_shard_runs_its_part_and_uploads_its_report(self):
        run = self.step("shard", r"hairbench \$SWEEP")["run"]
        self.assertIn('--shard "${{ matrix.shard }}/$SHARDS"', run)
        self.assertIn('--out "out/shard-${{ matrix.shard }}"', run)
        self.assertIn("--no-charts", run)
        up = self.step("shard", r"actions/upload-artifact@v4")["with"]
        self.assertEqual(up["name"], "shard-${{ matrix.shard }}")
        self.assertEqual(up["path"], "out/shard-${{ matrix.shard }}/report.json")

    def test_merge_waits_for_the_shards_and_publishes_the_page(self):
        merge = self.wf["jobs"]["merge"]
        self.assertIn(merge["needs"], ("shard", ["shard"]))
        down = self.step("merge", r"actions/download-artifact@v4")["with"]
        self.assertEqual(down, {"pattern": "shard-*", "path": "shards"})  # one folder per artifact
        run = self.step("merge", r"hairbench merge")["run"]
        self.assertIn("hairbench merge out/merged $MERGE_OPTIONS shards/shard-*/report.json", run)
        up = self.step("merge", r"actions/upload-artifact@v4")["with"]
        self.assertEqual(up, {"name": "report", "path": "out/merged"})

    def test_the_sweep_is_a_valid_command(self):
        env = self.wf["env"]
        args = env["SWEEP"].split() + ["--shard", f"1/{env['SHARDS']}", "--plan"]
        r = subprocess.run([HAIRBENCH] + args, capture_output=True, text=True, cwd=ROOT)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn(f"{env['SHARDS']} shards", r.stdout)


STUB_SBATCH = r"""#!/usr/bin/env bash
# Stub sbatch: records its arguments, then runs the job here at once (an array's tasks in
# order, with SLURM_ARRAY_TASK_ID), from a copy of the script as Slurm's spool would.
set -u
echo "$*" >> "$STUB_DIR/sbatch.log"
array="" dep="" out=""
while [ $# -gt 0 ]; do
  case "$1" in
    --parsable | --job-name=* | --partition=* | --time=*) ;;
    --array=*) array=${1#--array=} ;;
    --dependency=*) dep=${1#--dependency=} ;;
    --output=*) out=${1#--output=} ;;
    -*) echo "stub sbatch: unexpected option $1" >&2; exit 1 ;;
    *) break ;;
  esac
  shift
done
id=$(( $(cat "$STUB_DIR/next_id" 2>/dev/null || echo 100) + 1 ))
echo "$id" > "$STUB_DIR/next_id"
script="$STUB_DIR/spool-$id.sh"
cp "$1" "$script"
shift
status=ok
if [ -n "$dep" ]; then
  case "$dep" in afterok:*) ;; *) echo "stub sbatch: unexpected dependency $dep" >&2; exit 1 ;; esac
  # Slurm never starts a job whose afterok dependency failed.
  if [ "$(cat "$STUB_DIR/job-${dep#afterok:}.status")" != ok ]; then
    echo never > "$STUB_DIR/job-$id.status"; echo "$id"; exit 0
  fi
fi
if [ -n "$array" ]; then
  for ((t = ${array%-*}; t <= ${array#*-}; t++)); do
    SLURM_ARRAY_TASK_ID=$t bash "$script" "$@" > "${out//%a/$t}" 2>&1 || status=failed
  done
else
  bash "$script" "$@" > "$out" 2>&1 || status=failed
fi
echo "$status" > "$STUB_DIR/job-$id.status"
echo "$id"
"""

# Stub srun: runs the step here; STUB_FAIL_TASK makes that array task fail.
STUB_SRUN = """#!/usr/bin/env bash
if [ -n "${STUB_FAIL_TASK:-}" ] && [ "${SLURM_ARRAY_TASK_ID:-}" = "$STUB_FAIL_TASK" ]; then exit 1; fi
exec "$@"
"""

SWEEP = ["sweep", "--scenario", TINY, "--models", "han_m[12]", "--knob", "local_iterations=1,3", "--frames", "20",
         "--threads", "2"]


def runs(report):
    with open(report, encoding="utf-8") as f:
        return [(r["scenario"], r["model"], r["knob"]["value"], r["metrics"]["state_hash"]) for r in json.load(f)["runs"]]


class SlurmScript(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="hairbench-slurm-test-")
        self.stubs = os.path.join(self.tmp, "stubs")
        os.makedirs(self.stubs)
        for name, text in (("sbatch", STUB_SBATCH), ("srun", STUB_SRUN)):
            path = os.path.join(self.stubs, name)
            with open(path, "w", encoding="utf-8") as f:
                f.write(text)
            os.chmod(path, 0o755)
        self.env = dict(os.environ, PATH=self.stubs + os.pathsep + os.environ["PATH"], STUB_DIR=self.tmp,
                        HAIRBENCH=HAIRBENCH)

    def tearDown(self):
        shutil.rmtree(self.tmp)

    def submit(self, out, **env):
        return subprocess.run([os.path.join(ROOT, "ci", "slurm-sweep.sh"), "3", out] + SWEEP, capture_output=True,
                              text=True, env=dict(self.env, **env), cwd=self.tmp)

    def sbatch_calls(self):
        with open(os.path.join(self.tmp, "sbatch.log"), encoding="utf-8") as f:
            return f.read().splitlines()

    def test_array_of_shards_then_merge_equals_the_unsharded_sweep(self):
        out = os.path.join(self.tmp, "out")
        r = self.submit(out)
        self.assertEqual(r.returncode, 0, r.stderr)
        calls = self.sbatch_calls()
        self.assertEqual(len(calls), 2)
        self.assertIn("--array=0-2", calls[0])
        self.assertIn("--dependency=afterok:101", calls[1])  # the array's job id
        self.assertIn("shards: job 101 (array 0-2), merge: job 102 after them", r.stdout)
        for i in (1, 2, 3):
            self.assertTrue(os.path.exists(os.path.join(out, f"shard-{i}", "report.json")), i)
        merged = os.path.join(out, "merged", "report.json")
        self.assertTrue(os.path.exists(merged), open(os.path.join(out, "logs", "merge.out")).read())
        self.assertTrue(os.path.exists(os.path.join(out, "merged", "report.html")))
        full = os.path.join(self.tmp, "full")
        subprocess.run([HAIRBENCH] + SWEEP + ["--no-charts", "--out", full], check=True, capture_output=True)
        self.assertEqual(runs(merged), runs(os.path.join(full, "report.json")))

    def test_a_failed_task_holds_the_merge_back(self):
        out = os.path.join(self.tmp, "out")
        r = self.submit(out, STUB_FAIL_TASK="1")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertFalse(os.path.exists(os.path.join(out, "shard-2", "report.json")))
        self.assertFalse(os.path.exists(os.path.join(out, "merged")))

    def test_bad_arguments_submit_nothing(self):
        for args, message in ((["0", "o", "sweep"], "N must be a whole number >= 1"),
                              (["2", "o", "reproduce", "all"], "'reproduce' has no --shard"),
                              (["2", "o", "sweep", "--scenario", TINY], "sweep: --knob is required")):
            r = subprocess.run([os.path.join(ROOT, "ci", "slurm-sweep.sh")] + args, capture_output=True, text=True,
                               env=self.env, cwd=self.tmp)
            self.assertNotEqual(r.returncode, 0, args)
            self.assertIn(message, r.stderr, args)
            self.assertFalse(os.path.exists(os.path.join(self.tmp, "sbatch.log")), args)


if __name__ == "__main__":
    HAIRBENCH = os.path.abspath(sys.argv.pop(1))
    unittest.main(verbosity=2)
