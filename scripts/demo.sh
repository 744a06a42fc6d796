#!/usr/bin/env bash
# The README's first command: installs what is missing, builds, and runs the demo into a fresh folder
# demo_output/<date-time>/ (outputs are never overwritten), whose report.md links every plot.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bash "$root/scripts/install-deps.sh"
# Only the demo and the library it links: the tests, benchmarks, fuzzers, other apps and the Python module
# are the test command's to build (on host H3 this cut a fresh clone's time to the report from 173 s).
bash "$root/scripts/build.sh" release rawgment_demo
out="$root/demo_output/$(date +%Y%m%d-%H%M%S)"
mkdir -p "$root/demo_output"
"$root/build/release/bin/rawgment_demo" --out="$out" "$@"
