#!/usr/bin/env python3
"""Writes docs/examples/scan.ply and scan.xyz: a synthetic point cloud of a boulder for the README's
`talus rock` commands. Not a measurement: a rough ellipsoid of 0.9 x 0.6 x 0.45 m (its radius
perturbed by a few low-order bumps), sampled where a laser scanner standing beside it would see
it (its visible faces, not the underside), with 2 mm of range noise and 20 stray points (vegetation,
a passer-by) that the point-cloud cleaning should remove. Deterministic (fixed seed).
Usage: scripts/make_example_scan.py [out_dir]"""
import math
import pathlib
import random
import sys

out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).parent.parent / "docs" / "examples")
out.mkdir(parents=True, exist_ok=True)
rng = random.Random(20261126)
a, b, c = 0.45, 0.30, 0.225  # semi-axes, m
bumps = [(rng.uniform(0.03, 0.08), rng.randint(1, 3), rng.randint(1, 3), rng.uniform(0, 2 * math.pi))
         for _ in range(4)]
points = []
while len(points) < 4000:
    # Uniform direction; keep what lies above 15 % of the height (the underside rests on the ground).
    z = rng.uniform(-1, 1)
    phi = rng.uniform(0, 2 * math.pi)
    r = math.sqrt(1 - z * z)
    ux, uy, uz = r * math.cos(phi), r * math.sin(phi), z
    if uz < -0.15:
        continue
    scale = 1 + sum(h * math.cos(m * phi + p) * math.sin(n * math.acos(uz)) for h, m, n, p in bumps)
    noise = rng.gauss(0, 0.002)
    x, y, zz = a * ux * scale, b * uy * scale, c * uz * scale
    norm = math.sqrt(x * x + y * y + zz * zz)
    points.append((x + noise * x / norm, y + noise * y / norm, zz + noise * zz / norm))
for _ in range(20):
    points.append((rng.uniform(-1.2, 1.2), rng.uniform(-1.2, 1.2), rng.uniform(0.0, 1.5)))
with open(out / "scan.ply", "w") as f:
    f.write("ply\nformat ascii 1.0\ncomment synthetic boulder, scripts/make_example_scan.py\n")
    f.write(f"element vertex {len(points)}\nproperty float x\nproperty float y\nproperty float z\nend_header\n")
    for p in points:
        f.write("%.4f %.4f %.4f\n" % p)
with open(out / "scan.xyz", "w") as f:
    for p in points:
        f.write("%.4f %.4f %.4f\n" % p)
print(f"wrote {len(points)} points to {out}/scan.ply and scan.xyz")
