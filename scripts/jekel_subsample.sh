#!/bin/sh
# The public real tests (data/jekel) subsampled to 7 evenly spaced stages over the whole
# range, each run through `bulge run` with default settings; prints the chosen law and
# the TP MSS rms height error. Usage: scripts/jekel_subsample.sh [OUT_DIR]
# (needs `cargo build --release`, or BULGE=path/to/bulge).
set -e
out=${1:-target/jekel_subsample}
bin=${BULGE:-target/release/bulge}
for t in 1 3; do
  src=data/jekel/test$t
  n=$(($(wc -l < $src/heights.csv) - 1))
  k=$(( (n - 1) / 6 ))
  d=$out/test${t}_7
  mkdir -p $d
  (head -1 $src/heights.csv; tail -n +2 $src/heights.csv | awk -v k=$k 'NR%k==1' | head -7) > $d/heights.csv
  cp $src/experiment.toml $d/
  $bin run $d/experiment.toml --out $d/out > $d/log 2>&1
  law=$(grep -o 'chosen [a-z][a-z0-9-]*:' $d/log | head -1)
  awk -F'|' -v t=$t -v law="$law" '/^\| [0-9]/{e=$5+0; s+=e*e; n++} END{printf "test %s, %d stages: %s, TP MSS rms %.2f %%\n", t, n, law, sqrt(s/n)}' $d/out/summary.md
done
