"""bulge beside FElupe on one bubble, in one run.

Usage: python compare.py BULGE SCENE_TOML [--nodes N ...] [--radial M ...]

Runs, each as a whole process timed from start to exit:
  * `BULGE simulate SCENE --model axisym`: the exact heights (the reference);
  * `BULGE simulate SCENE --model membrane --nodes N` and `--model tp`, for
    each N;
  * `python felupe_bubble.py SCENE` (an axisymmetric thin solid in FElupe),
    for each number M of elements along the radius;
and prints one Markdown table: wall time, the largest relative height error
against the exact heights over the scene's pressures, and the ratio of
FElupe's wall time to each bulge run's.
"""

import argparse
import csv
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))


def run(cmd):
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - t0


def heights(path):
    with open(path) as f:
        return {round(float(r["pressure_pa"]), 1): float(r["height_m"]) for r in csv.DictReader(f)}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("bulge", help="the bulge binary (release build)")
    ap.add_argument("scene", help="a disc scene with a Mooney-Rivlin or neo-Hookean material")
    ap.add_argument("--nodes", type=int, nargs="+", default=[406], help="bulge mesh sizes (nodes of the 60-degree sector)")
    ap.add_argument("--radial", type=int, nargs="+", default=[60, 120, 240], help="FElupe elements along the radius")
    ap.add_argument("--repeat", type=int, default=3, help="runs of each; the median wall time is reported")
    args = ap.parse_args()

    tmp = tempfile.mkdtemp(prefix="bulge-peers-")
    exact_csv = os.path.join(tmp, "exact.csv")
    run([args.bulge, "simulate", args.scene, "--model", "axisym", "-o", exact_csv])
    exact = heights(exact_csv)

    rows = []

    def measure(label, mesh, cmd, out):
        walls = sorted(run(cmd) for _ in range(args.repeat))
        h = heights(out)
        missing = set(exact) - set(h)
        if missing:
            sys.exit(f"{label}: no height at {sorted(missing)} Pa")
        err = max(abs(h[p] / exact[p] - 1.0) for p in exact)
        rows.append((label, mesh, walls[len(walls) // 2], err))

    for n in args.nodes:
        for model in ["membrane", "tp"]:
            out = os.path.join(tmp, f"{model}-{n}.csv")
            measure(f"bulge {model}", f"{n} nodes", [args.bulge, "simulate", args.scene, "--model", model, "--nodes", str(n), "-o", out], out)
    for m in args.radial:
        out = os.path.join(tmp, f"felupe-{m}.csv")
        cmd = [sys.executable, os.path.join(HERE, "felupe_bubble.py"), args.scene, out, "--radial", str(m)]
        measure("FElupe (axisymmetric solid)", f"{m} x 1 quadratic", cmd, out)

    fastest_felupe = min(r[2] for r in rows if r[0].startswith("FElupe"))
    print(f"{len(exact)} pressures; errors against the exact axisymmetric membrane; median of {args.repeat} runs, whole process")
    print()
    print("| program | mesh | wall s | largest height error % | FElupe's fastest / this |")
    print("|---|---|---:|---:|---:|")
    for label, mesh, wall, err in rows:
        print(f"| {label} | {mesh} | {wall:.3f} | {err * 100:.3f} | {fastest_felupe / wall:.1f} |")


if __name__ == "__main__":
    main()
