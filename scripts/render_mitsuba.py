#!/usr/bin/env python3
"""Path-traced photos of a bubble test, for checking bulge on photos it did not draw.

A development tool, outside bulge's dependencies: it needs Mitsuba 3 (Jakob et al.,
"Mitsuba 3 renderer", 2022, https://mitsuba-renderer.org), numpy and pillow, e.g.

    python3 -m venv /tmp/mi && /tmp/mi/bin/pip install mitsuba numpy pillow
    /tmp/mi/bin/python scripts/render_mitsuba.py out/mitsuba --bulge target/release/bulge

The scene is a clamped disc inflated to the exact axisymmetric neo-Hookean shape (from
`bulge simulate --model axisym --profile`, one solve per photo), revolved into a mesh, on a
clamp ring with a top face and a side, a table below, a wall behind, lit by an area lamp
above the camera and a dim sky (and, with `--back-lamp-deg`, a small lamp behind the bubble
whose mirror image a glossy dome shows under its top). A perspective camera `--distance-m` from the axis, aimed at
the mid-height of the largest bubble from `--camera-above-m` above that point, renders
linear light; the lens blur is applied in linear light, then shot and read noise, the sRGB
tone curve, 8-bit rounding and JPEG. The folder gets photos/, pressure.csv (file,pressure_pa),
truth.csv (file,pressure_pa,height_m: the pole's height above the clamp plane) and
camera.toml (the pinhole's focal length and principal point, as `bulge calibrate` writes
them, without distortion).

Image coordinates: the centre of the top-left pixel is (0, 0), as in bulge and OpenCV; the
renderer's film puts pixel centres at half-integers, so the principal point is (W-1)/2, (H-1)/2.
"""

import argparse
import csv
import math
import os
import subprocess
import tempfile

import numpy as np
from PIL import Image


def back_lamp(theta_deg, a, h_max, origin):
    """A small square lamp behind and above the largest dome, 20 degrees to the left of the
    camera's plane, placed where the mirror direction of the camera's ray off the sphere
    through the largest dome's rim and pole at theta_deg from the pole towards the camera
    points, 0.09 m from that point: a glossy coat shows its highlight under the top."""
    import mitsuba as mi

    r = (a * a + h_max * h_max) / (2 * h_max)
    t, phi = math.radians(theta_deg), math.radians(-20.0)
    centre = np.array([0.0, h_max - r, 0.0])
    n = np.array([math.sin(t) * math.sin(phi), math.cos(t), math.sin(t) * math.cos(phi)])
    point = centre + r * n
    v = origin - point
    v = v / np.linalg.norm(v)
    l = 2 * np.dot(n, v) * n - v
    pos = point + 0.09 * l
    return {"type": "rectangle",
            "emitter": {"type": "area", "radiance": {"type": "rgb", "value": [300, 300, 300]}},
            "to_world": mi.ScalarTransform4f.look_at(
                origin=pos.tolist(), target=point.tolist(), up=[0, 1, 0])
            @ mi.ScalarTransform4f.scale(0.006)}


def profile(bulge, material, radius_m, thickness_m, pressures, i):
    """The meridian (rho_m, z_m) at pressures[i], continued from the pressures before."""
    with tempfile.TemporaryDirectory() as tmp:
        scene = os.path.join(tmp, "disc.toml")
        with open(scene, "w") as f:
            f.write(
                f"kind = \"disc\"\nradius_m = {radius_m}\nthickness_m = {thickness_m}\n"
                f"pressure_pa = [1.0]\nmaterial = \"{os.path.abspath(material)}\"\n"
            )
        prof = os.path.join(tmp, "profile.csv")
        ps = ",".join(str(p) for p in pressures[: i + 1])
        subprocess.run(
            [bulge, "simulate", scene, "--pressures", ps, "--model", "axisym", "-o", os.path.join(tmp, "s.csv"),
             "--profile", prof],
            check=True, capture_output=True)
        rows = list(csv.DictReader(open(prof)))
    rho = np.array([float(r["rho_m"]) for r in rows])
    z = np.array([float(r["z_m"]) for r in rows])
    return rho, z


def write_ply(path, vertices, faces):
    with open(path, "w") as f:
        f.write("ply\nformat ascii 1.0\n")
        f.write(f"element vertex {len(vertices)}\nproperty float x\nproperty float y\nproperty float z\n")
        f.write(f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n")
        for v in vertices:
            f.write(f"{v[0]:.9g} {v[1]:.9g} {v[2]:.9g}\n")
        for t in faces:
            f.write(f"3 {t[0]} {t[1]} {t[2]}\n")


def revolve(rho, y, segments):
    """A surface of revolution about the y axis through the points (rho_k, y_k)."""
    verts, faces = [], []
    phis = np.linspace(0.0, 2.0 * math.pi, segments, endpoint=False)
    index = []
    for r, yy in zip(rho, y):
        if r == 0.0:
            index.append([len(verts)] * segments)
            verts.append((0.0, yy, 0.0))
        else:
            row = []
            for ph in phis:
                row.append(len(verts))
                verts.append((r * math.cos(ph), yy, r * math.sin(ph)))
            index.append(row)
    for k in range(len(rho) - 1):
        a, b = index[k], index[k + 1]
        for j in range(segments):
            j2 = (j + 1) % segments
            if a[j] == a[j2]:
                faces.append((a[j], b[j2], b[j]))
            else:
                faces.append((a[j], b[j2], b[j]))
                faces.append((a[j], a[j2], b[j2]))
    return verts, faces


def gaussian_blur(img, sigma):
    if sigma <= 0:
        return img
    r = int(math.ceil(4 * sigma))
    x = np.arange(-r, r + 1)
    k = np.exp(-0.5 * (x / sigma) ** 2)
    k /= k.sum()
    pad = np.pad(img, r, mode="edge")
    tmp = np.apply_along_axis(lambda m: np.convolve(m, k, mode="valid"), 1, pad)
    return np.apply_along_axis(lambda m: np.convolve(m, k, mode="valid"), 0, tmp)


def srgb(x):
    x = np.clip(x, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out")
    ap.add_argument("--bulge", default="target/release/bulge")
    ap.add_argument("--radius-m", type=float, default=0.0375)
    ap.add_argument("--thickness-m", type=float, default=0.00035)
    ap.add_argument("--c1-pa", type=float, default=0.2e6, help="neo-Hookean C1")
    ap.add_argument("--pressure-max-pa", type=float, default=6350.0,
                    help="default: 0.9 of the limit pressure of the default disc")
    ap.add_argument("--photos", type=int, default=8)
    ap.add_argument("--width", type=int, default=1280)
    ap.add_argument("--height", type=int, default=960)
    ap.add_argument("--distance-m", type=float, default=0.45,
                    help="horizontal distance from the bubble's axis to the camera")
    ap.add_argument("--camera-above-m", type=float, default=0.005,
                    help="the camera's height above the largest bubble's mid-height")
    ap.add_argument("--focal-px", type=float, default=0.0,
                    help="default: the opening spans half the width at the axis")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--blur-px", type=float, default=0.8, help="lens blur sigma, linear light")
    ap.add_argument("--ring-face", type=float, default=0.45, help="ring top face reflectance")
    ap.add_argument("--ring-side", type=float, default=0.12)
    ap.add_argument("--dome", type=float, default=0.06, help="dome diffuse reflectance")
    ap.add_argument("--gloss", type=float, default=0.0,
                    help="rough-plastic roughness of the dome (0: matte)")
    ap.add_argument("--wall", type=float, default=0.55)
    ap.add_argument("--quality", type=int, default=92, help="JPEG quality (0: PNG)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--back-lamp-deg", type=float, default=0.0,
                    help="add a small lamp behind the bubble whose mirror image on the largest "
                         "dome lies this many degrees from its pole towards the camera "
                         "(0: none); a glossy dome then shows a highlight under its top")
    args = ap.parse_args()

    import mitsuba as mi
    mi.set_variant("scalar_rgb")

    a = args.radius_m
    n = args.photos
    pressures = [args.pressure_max_pa * (k + 1) / n for k in range(n)]
    os.makedirs(os.path.join(args.out, "photos"), exist_ok=True)
    mesh_dir = os.path.join(args.out, "meshes")
    os.makedirs(mesh_dir, exist_ok=True)
    material = os.path.join(mesh_dir, "material.toml")
    with open(material, "w") as f:
        f.write(f"model = \"neo-hookean\"\nc1_pa = {args.c1_pa}\npoisson = 0.45\n")
    domes = [profile(args.bulge, material, a, args.thickness_m, pressures, i) for i in range(n)]
    h_max = domes[-1][1][0]

    ring_outer, ring_depth = 1.35 * a, 0.012
    seg = 720
    v, f = revolve(np.array([a, ring_outer]), np.array([0.0, 0.0]), seg)
    write_ply(os.path.join(mesh_dir, "ring_face.ply"), v, f)
    v, f = revolve(np.array([ring_outer, ring_outer]), np.array([0.0, -ring_depth]), seg)
    write_ply(os.path.join(mesh_dir, "ring_side.ply"), v, f)

    W, H = args.width, args.height
    D = args.distance_m
    target = np.array([0.0, h_max / 2, 0.0])
    origin = np.array([0.0, h_max / 2 + args.camera_above_m, D])
    dist = np.linalg.norm(origin - target)
    focal = args.focal_px or dist * (W / 2) / (2 * a)
    fov = 2 * math.degrees(math.atan((W / 2) / focal))

    def grey(r):
        return {"type": "diffuse", "reflectance": {"type": "rgb", "value": [r, r, r]}}

    exposure = None
    rng = np.random.default_rng(args.seed)
    rows = []
    for i, (p, (rho, z)) in enumerate(zip(pressures, domes)):
        v, fa = revolve(rho, z, seg)
        dome_path = os.path.join(mesh_dir, f"dome_{i:02d}.ply")
        write_ply(dome_path, v, fa)
        dome_bsdf = grey(args.dome)
        if args.gloss > 0:
            dome_bsdf = {"type": "roughplastic", "alpha": args.gloss,
                         "diffuse_reflectance": {"type": "rgb", "value": [args.dome] * 3}}
        scene = {
            "type": "scene",
            "integrator": {"type": "path", "max_depth": 6},
            "sensor": {
                "type": "perspective", "fov": fov, "fov_axis": "x",
                "to_world": mi.ScalarTransform4f.look_at(
                    origin=origin.tolist(), target=target.tolist(), up=[0, 1, 0]),
                "film": {"type": "hdrfilm", "width": W, "height": H,
                         "rfilter": {"type": "gaussian"}},
                "sampler": {"type": "independent", "sample_count": args.spp,
                            "seed": args.seed * 1000 + i},
            },
            "dome": {"type": "ply", "filename": dome_path, "bsdf": dome_bsdf},
            "face": {"type": "ply", "filename": os.path.join(mesh_dir, "ring_face.ply"),
                     "bsdf": grey(args.ring_face)},
            "side": {"type": "ply", "filename": os.path.join(mesh_dir, "ring_side.ply"),
                     "bsdf": grey(args.ring_side)},
            "table": {"type": "rectangle", "bsdf": grey(0.3),
                      "to_world": mi.ScalarTransform4f.translate([0, -ring_depth, 0])
                      @ mi.ScalarTransform4f.rotate([1, 0, 0], -90)
                      @ mi.ScalarTransform4f.scale(0.6)},
            "wall": {"type": "rectangle", "bsdf": grey(args.wall),
                     "to_world": mi.ScalarTransform4f.translate([0, 0, -0.12])
                     @ mi.ScalarTransform4f.scale(0.6)},
            "lamp": {"type": "rectangle",
                     "emitter": {"type": "area", "radiance": {"type": "rgb", "value": [8, 8, 8]}},
                     "to_world": mi.ScalarTransform4f.look_at(
                         origin=[0.05, 0.3, 0.3], target=[0, 0.02, 0], up=[0, 1, 0])
                     @ mi.ScalarTransform4f.scale(0.06)},
            "sky": {"type": "constant", "radiance": {"type": "rgb", "value": [0.25, 0.25, 0.25]}},
        }
        if args.back_lamp_deg > 0:
            scene["back_lamp"] = back_lamp(args.back_lamp_deg, a, h_max, origin)
        scene = mi.load_dict(scene)
        img = np.array(mi.render(scene))
        lum = 0.2126 * img[..., 0] + 0.7152 * img[..., 1] + 0.0722 * img[..., 2]
        if exposure is None:
            exposure = 0.8 / np.percentile(lum, 99.0)
        light = gaussian_blur(lum * exposure, args.blur_px)
        light = light + rng.normal(0.0, 1.0, light.shape) * np.sqrt(2e-6 + 4e-5 * np.clip(light, 0, None))
        grey8 = np.clip(np.round(srgb(light) * 255.0), 0, 255).astype(np.uint8)
        name = f"photo_{i + 1:02d}." + ("jpg" if args.quality else "png")
        out = Image.fromarray(grey8).convert("RGB")
        if args.quality:
            out.save(os.path.join(args.out, "photos", name), quality=args.quality)
        else:
            out.save(os.path.join(args.out, "photos", name))
        rows.append((name, p, float(z[0])))
        print(f"{name}: pressure {p:.0f} Pa, apex {z[0] * 1e3:.3f} mm", flush=True)

    with open(os.path.join(args.out, "pressure.csv"), "w") as f:
        f.write("file,pressure_pa\n")
        for name, p, _ in rows:
            f.write(f"{name},{p}\n")
    with open(os.path.join(args.out, "truth.csv"), "w") as f:
        f.write("file,pressure_pa,height_m\n")
        for name, p, h in rows:
            f.write(f"{name},{p},{h}\n")
    with open(os.path.join(args.out, "camera.toml"), "w") as f:
        f.write(f"[camera]\nresponse = \"srgb\"\nfocal_px = [{focal}, {focal}]\n"
                f"principal_point_px = [{(W - 1) / 2}, {(H - 1) / 2}]\n"
                "distortion = [0.0, 0.0, 0.0, 0.0, 0.0]\n"
                f"image_size_px = [{W}, {H}]\n")
    print(f"camera {D} m from the axis, {math.degrees(math.atan2(origin[1], D)):.2f} deg above "
          f"the ring's centre, focal {focal:.1f} px")
    # Where the pinhole camera projects the ring's centre and the opening's
    # near and far edges on the axis (image rows, the top-left pixel's
    # centre at 0): the clamp row a user gives init for this scene.
    forward = (target - origin) / np.linalg.norm(target - origin)
    right = np.cross(forward, [0.0, 1.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)

    def row(point):
        v = np.asarray(point) - origin
        return (H - 1) / 2 - focal * (v @ up) / (v @ forward)

    print(f"ring centre at row {row([0, 0, 0]):.2f}; the opening's near edge on the axis at row "
          f"{row([0, 0, a]):.2f}, its far edge at {row([0, 0, -a]):.2f}")


if __name__ == "__main__":
    main()
