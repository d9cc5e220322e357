#!/usr/bin/env python3
"""Compares `bulge track` output with the synthetic truth (independent of bulge).

Usage: python3 data/demo/check_heights.py data/demo/truth.csv out/heights.csv
Prints per-photo errors and the RMS apex errors (px) and height error (m).
"""
import csv
import math
import sys

truth = {r["file"]: r for r in csv.DictReader(open(sys.argv[1]))}
rows = list(csv.DictReader(open(sys.argv[2])))
ex, ey, eh, z = [], [], [], []
print("file            score   dx_px   dy_px   dheight_m  dheight/std")
for r in rows:
    t = truth[r["file"]]
    dx = float(r["apex_x_px"]) - float(t["apex_x_px"])
    dy = float(r["apex_y_px"]) - float(t["apex_y_px"])
    dh = float(r["height_m"]) - float(t["height_m"])
    ex.append(dx)
    ey.append(dy)
    eh.append(dh)
    z.append(dh / float(r["height_std_m"]))
    print(f"{r['file']:<15} {r['score']:>6} {dx:+7.3f} {dy:+7.3f} {dh:+11.3e} {z[-1]:+8.2f}")


def rms(v):
    return math.sqrt(sum(x * x for x in v) / len(v))


print(
    f"{len(rows)} photos: RMS apex error x {rms(ex):.3f} px, y {rms(ey):.3f} px "
    f"(max |y| {max(abs(v) for v in ey):.3f} px); RMS height error {rms(eh):.3e} m; "
    f"RMS(error/height_std_m) {rms(z):.2f}"
)
