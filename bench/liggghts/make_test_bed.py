#!/usr/bin/python3
"""Write a LIGGGHTS read_data file (atom_style granular) with 30,000
non-overlapping spheres on a loose lattice at the bottom of the bench box.
Only for testing the LIGGGHTS scripts: settle it with settle_bed.in first.

usage: make_test_bed.py OUT.data [N]
"""
import sys
import numpy as np

LX, LY, LZ = 0.6, 0.1, 0.4          # box [0,LX]x[0,LY]x[0,LZ] (m)
R, RHO = 0.0025, 2400.0             # radius (m), density (kg/m^3)
GAP = 0.0005                        # clearance between lattice neighbours
JIT = 0.2 * GAP                     # jitter (< GAP/2) breaks lattice symmetry

out = sys.argv[1]
n = int(sys.argv[2]) if len(sys.argv) > 2 else 30000
s = 2 * R + GAP
m = R + GAP                         # margin to the walls
nx = int((LX - 2 * m) // s) + 1
ny = int((LY - 2 * m) // s) + 1
nz = -(-n // (nx * ny))
iz, iy, ix = np.unravel_index(np.arange(n), (nz, ny, nx))
pos = m + s * np.stack([ix, iy, iz], axis=1).astype(float)
pos += np.random.default_rng(1).uniform(-JIT, JIT, pos.shape)
assert pos.max(axis=0)[2] + R < LZ

with open(out, "w") as f:
    f.write("LIGGGHTS data file: grainlink bench test lattice\n\n")
    f.write(f"{n} atoms\n1 atom types\n\n")
    f.write(f"0 {LX} xlo xhi\n0 {LY} ylo yhi\n0 {LZ} zlo zhi\n\n")
    f.write("Atoms\n\n")
    for i, (x, y, z) in enumerate(pos, 1):
        # id type diameter density x y z
        f.write(f"{i} 1 {2 * R:.6g} {RHO:.6g} {x:.9g} {y:.9g} {z:.9g}\n")
print(f"{out}: {n} spheres, lattice {nx}x{ny}x{nz}, top z = {pos[:, 2].max() + R:.4f} m")
