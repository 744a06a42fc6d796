#!/usr/bin/env bash
# The README's first command: installs what is missing, builds, and runs the demo.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bash "$root/scripts/install-deps.sh"
bash "$root/scripts/build.sh" release
out="$root/demo_output"
mkdir -p "$out"
"$root/build/release/bin/rawgment_demo" --out="$out/noise_model.yml" "$@"
