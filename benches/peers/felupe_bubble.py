"""The bubble test in FElupe: an axisymmetric thin solid, clamped at its rim,
inflated by a follower pressure on its lower face.

Usage: python felupe_bubble.py SCENE_TOML OUT_CSV [--radial N] [--through M]

SCENE_TOML is a bulge disc scene with a Mooney-Rivlin (or neo-Hookean)
material: radius_m, thickness_m, pressure_pa and [material] c1_pa (c2_pa).
OUT_CSV gets pressure_pa,height_m,wall_s: the apex height of the mid-surface
and the wall time since the start (imports excluded). The solid is nearly
incompressible: quadratic displacement with constant pressure and volume per
element (FElupe's mixed u/p/J fields), bulk modulus 5000 times the shear
modulus; a free axis, a rim clamped over the whole thickness.
"""

import argparse
import csv
import time
import tomllib

import warnings

import felupe as fem
import numpy as np

# the Job callback's deprecation notice (FElupe 11.3) is not the benchmark's
warnings.filterwarnings("ignore", category=DeprecationWarning)


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("scene", help="bulge disc scene (TOML)")
    ap.add_argument("out", help="output CSV")
    ap.add_argument("--radial", type=int, default=60, help="elements along the radius")
    ap.add_argument("--through", type=int, default=1, help="elements through the thickness")
    ap.add_argument("--substeps", type=int, default=2, help="load steps between pressures")
    ap.add_argument("--ramp-steps", type=int, default=12, help="geometric steps to the first pressure")
    args = ap.parse_args()

    with open(args.scene, "rb") as f:
        scene = tomllib.load(f)
    if scene.get("kind") != "disc":
        raise SystemExit(f"{args.scene}: kind must be \"disc\"")
    material = scene["material"]
    if material.get("model") not in ("mooney-rivlin", "neo-hookean"):
        raise SystemExit(f"{args.scene}: [material] model must be mooney-rivlin or neo-hookean")
    c1, c2 = float(material["c1_pa"]), float(material.get("c2_pa", 0.0))
    pressures = [float(p) for p in scene["pressure_pa"]]
    a, t = float(scene["radius_m"]), float(scene["thickness_m"])
    t0 = time.perf_counter()
    # FElupe's axisymmetric fields take x as the axis and y as the radius
    mesh = fem.Rectangle(a=(0.0, 0.0), b=(t, a), n=(args.through + 1, args.radial + 1))
    mesh = fem.mesh.convert(mesh, order=2)
    region = fem.RegionQuadraticQuad(mesh)
    field = fem.FieldsMixed(region, n=3, axisymmetric=True)
    mu = 2.0 * (c1 + c2)
    umat = fem.NearlyIncompressible(
        fem.Hyperelastic(fem.mooney_rivlin, C10=c1, C01=c2),
        bulk=5000.0 * mu,
    )
    solid = fem.SolidBody(umat, field)

    z, r = mesh.points[:, 0], mesh.points[:, 1]
    boundaries = {
        "axis": fem.Boundary(field[0], fy=0.0, skip=(1, 0)),
        "rim": fem.Boundary(field[0], fy=a),
    }
    region_p = fem.RegionQuadraticQuadBoundary(
        mesh, only_surface=True, mask=np.isclose(z, 0.0), ensure_3d=True
    )
    field_p = fem.FieldContainer([fem.FieldAxisymmetric(region_p, dim=2)])
    pressure = fem.SolidBodyPressure(field_p)

    apex = np.argmin(np.hypot(r, z - t / 2))
    # a flat plate first answers in bending, far outside Newton's reach from
    # rest: the first pressure is approached in geometric steps from 1e-4 of it
    ramp = list(np.geomspace(1e-4 * pressures[0], pressures[0], args.ramp_steps))
    prev = pressures[0]
    for p in pressures[1:]:
        ramp.extend(np.linspace(prev, p, args.substeps + 1)[1:])
        prev = p
    ramp = np.array(ramp)
    targets = set(pressures)
    rows = []
    step = fem.Step(items=[solid, pressure], ramp={pressure: ramp}, boundaries=boundaries)

    def record(i, j, substep):
        if ramp[j] in targets:
            u = field[0].values[apex]
            rows.append((ramp[j], u[0], time.perf_counter() - t0))

    fem.Job(steps=[step], callback=record).evaluate(tol=1e-10, verbose=0)
    with open(args.out, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["pressure_pa", "height_m", "wall_s"])
        for p, h, s in rows:
            w.writerow([f"{p:.6g}", f"{h:.9e}", f"{s:.4f}"])


if __name__ == "__main__":
    main()
