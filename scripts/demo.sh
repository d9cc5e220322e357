#!/usr/bin/env bash
# The demo: the pipeline, as far as it exists, on the bundled experiment.
set -euo pipefail
BULGE=${1:-target/release/bulge}
OUT=${2:-out}
mkdir -p "$OUT"
echo "== bulge stress: data/demo/heights.csv -> $OUT/stress_strain.csv"
"$BULGE" stress data/demo/heights.csv --experiment data/demo/experiment.toml -o "$OUT/stress_strain.csv"
if command -v column >/dev/null; then column -s, -t < "$OUT/stress_strain.csv"; else cat "$OUT/stress_strain.csv"; fi
