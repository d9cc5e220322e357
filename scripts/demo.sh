#!/usr/bin/env bash
# The demo: the whole pipeline on the bundled synthetic experiment (data/demo),
# as a new user would run it: photos -> heights -> stress/strain -> material ->
# simulated heights (TP MSS, Van Gelder, exact axisymmetric reference) -> report.
set -euo pipefail
BULGE=${1:-target/release/bulge}
OUT=${2:-out}
echo "== bulge run data/demo/experiment.toml --out $OUT"
"$BULGE" run data/demo/experiment.toml --out "$OUT"
echo "== open $OUT/report.html in a browser (self-contained, no network needed)"
