#!/usr/bin/env bash
# The README's first command: installs what is missing, builds, and runs the demo into a fresh folder
# demo_output/<date-time>/ (outputs are never overwritten), whose report.md links every plot.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bash "$root/scripts/install-deps.sh"
bash "$root/scripts/build.sh" release
out="$root/demo_output/$(date +%Y%m%d-%H%M%S)"
mkdir -p "$root/demo_output"
"$root/build/release/bin/rawgment_demo" --out="$out" "$@"
