#!/usr/bin/env bash
# The out-of-tree plugin path end to end (docs/plugins.md): install hairbench into a
# temporary prefix, build examples/plugin against the installed package with
# find_package(hairbench), and run its model beside a built-in one through
# `compare --plugin`. Usage: plugin_install_test.sh BUILD_DIR SOURCE_DIR PYTHON
set -euo pipefail
build="$1" source="$2" python="$3"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

cmake --install "$build" --prefix "$work/prefix" >/dev/null
test -f "$work/prefix/include/hairbench/plugin.h"
test -f "$work/prefix/lib/hairbench/plugins/muller_ftl.so"
cmake -S "$source/examples/plugin" -B "$work/example" -G Ninja -DCMAKE_PREFIX_PATH="$work/prefix" >/dev/null
cmake --build "$work/example" >/dev/null
"$work/prefix/bin/hairbench" compare --plugin "$work/example/example_verlet.so" \
  --models 'example_verlet|muller_ftl|han_m3' --scenario idle --frames 20 --no-charts --out "$work/out" >/dev/null

# Every model ran all its frames; the example's origin is its library, and the installed
# binary found its default plugin in the prefix.
"$python" - "$work" <<'PY'
import json, sys
work = sys.argv[1]
report = json.load(open(f"{work}/out/report.json"))
runs = {r["model"]: r for r in report["runs"]}
assert set(runs) == {"example_verlet", "muller_ftl", "han_m3"}, sorted(runs)
for name, r in runs.items():
    assert r["frames_run"] == 20, (name, r["frames_run"])
    assert r["status"] != "diverged", (name, r["failure"])
assert runs["example_verlet"]["origin"] == f"{work}/example/example_verlet.so", runs["example_verlet"]["origin"]
assert runs["muller_ftl"]["origin"] == f"{work}/prefix/lib/hairbench/plugins/muller_ftl.so", runs["muller_ftl"]["origin"]
assert report["context"]["plugins"]["not_loaded"] == [], report["context"]["plugins"]
print("plugin_install_test: example_verlet", runs["example_verlet"]["status"], "muller_ftl", runs["muller_ftl"]["status"])
PY
