#!/usr/bin/python3
"""Write a closed cylinder as an ASCII STL, centred at the origin, axis along y.
Default radius 0.125 m, width 0.1 m, 360 segments -> 720 side + 720 cap = 1440
triangles, normals pointing outwards.

usage: make_cylinder_stl.py OUT.stl [RADIUS WIDTH SEGMENTS]
"""
import sys
import numpy as np

out = sys.argv[1]
r = float(sys.argv[2]) if len(sys.argv) > 2 else 0.125
w = float(sys.argv[3]) if len(sys.argv) > 3 else 0.1
n = int(sys.argv[4]) if len(sys.argv) > 4 else 360

a = 2 * np.pi * np.arange(n + 1) / n
ring = lambda y: [np.array([r * np.cos(t), y, r * np.sin(t)]) for t in a]
lo, hi = ring(-w / 2), ring(w / 2)
c_lo, c_hi = np.array([0, -w / 2, 0.0]), np.array([0, w / 2, 0.0])

tris = []
for i in range(n):
    j = i + 1
    tris += [(lo[i], hi[i], hi[j]), (lo[i], hi[j], lo[j])]   # side quad
    tris += [(c_lo, lo[i], lo[j]), (c_hi, hi[j], hi[i])]     # cap fans

with open(out, "w") as f:
    f.write("solid cylinder\n")
    for p0, p1, p2 in tris:
        nrm = np.cross(p1 - p0, p2 - p0)
        nrm /= np.linalg.norm(nrm)
        f.write(" facet normal %.9g %.9g %.9g\n  outer loop\n" % tuple(nrm))
        for p in (p0, p1, p2):
            f.write("   vertex %.9g %.9g %.9g\n" % tuple(p))
        f.write("  endloop\n endfacet\n")
    f.write("endsolid cylinder\n")
print(f"{out}: {len(tris)} triangles")
