#!/usr/bin/python3
"""The ParaView snapshots of a run (tiny.yaml: grains and a plate), read back with Debian's VTK
(python3-vtk9), the library ParaView is built on:
- every file of particles.pvd and body_plate.pvd exists, at increasing times;
- each particle snapshot holds one vertex cell per grain (the count summary.json gives) with the
  radius, velocity and force
  arrays, and vtkGeometryFilter — what ParaView's default Surface view runs — turns it into one
  vertex per grain (a snapshot without cells shows nothing there);
- every file is binary, appended and zlib-compressed (vtkZLibDataCompressor), and its numbers
  decode to what the scenario allows: every radius within tiny.yaml's 3.5-4.5 mm, every grain
  centre inside its 60 x 60 mm bin, ids 0 to n - 1 each once;
- each plate snapshot holds the plate's triangles (24 facets: 96 triangles) and their loads;
- with `output.contact_network`, each contacts snapshot holds a line per touching grain pair, as
  many as series.csv counts at that time, and each line's normal_force_N is Hertz's
  4/3 E* sqrt(R*) delta^(3/2) recomputed here from the particle snapshot's centres and radii
  (E* = E / (2 (1 - nu^2)) for tiny.yaml's one material).
Usage: read_vtk.py GRAINLINK SCENARIO WORK"""
import os
import shutil
import subprocess
import sys
import csv
import json
import xml.etree.ElementTree as ET

import vtk

grainlink, scenario, work = map(os.path.abspath, sys.argv[1:4])
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
# tiny.yaml with the force chains written beside every particle snapshot.
text = open(scenario).read()
assert "snapshot_interval_s: 0.05}" in text
with open(os.path.join(work, "tiny.yaml"), "w") as f:
    f.write(text.replace("snapshot_interval_s: 0.05}", "snapshot_interval_s: 0.05, contact_network: true}"))
done = subprocess.run([grainlink, "dem", os.path.join(work, "tiny.yaml"), "--out",
                       os.path.join(work, "out")], cwd=work, capture_output=True, text=True)
if done.returncode != 0:
    sys.exit("FAILED: the run failed:\n" + done.stderr[-2000:])
folder = os.path.join(work, "out")
failures = []


def collection(name):
    entries = ET.parse(os.path.join(folder, name)).getroot().iter("DataSet")
    files = [(float(e.get("timestep")), os.path.join(folder, e.get("file"))) for e in entries]
    times = [t for t, _ in files]
    if not files or times != sorted(times) or len(set(times)) != len(times):
        failures.append(f"{name}: times {times}")
    for _, f in files:
        if not os.path.exists(f):
            failures.append(f"{name} names {f}, which does not exist")
    return [f for _, f in files]


def read(path):
    with open(path, "rb") as f:
        head = f.read(400)
    if b'compressor="vtkZLibDataCompressor"' not in head or b'format="appended"' not in head:
        failures.append(f"{path}: not appended and zlib-compressed: {head[:300]!r}")
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    return reader.GetOutput()


grains = json.load(open(os.path.join(folder, "summary.json")))["particles"]
particles = collection("particles.pvd")
for path in particles:
    grid = read(path)
    n = grid.GetNumberOfPoints()
    types = {grid.GetCellType(k) for k in range(grid.GetNumberOfCells())}
    surface = vtk.vtkGeometryFilter()
    surface.SetInputData(grid)
    surface.Update()
    shown = surface.GetOutput().GetNumberOfVerts()
    arrays = {grid.GetPointData().GetArrayName(k) for k in range(grid.GetPointData().GetNumberOfArrays())}
    if n != grains or grid.GetNumberOfCells() != n or types != {vtk.VTK_VERTEX} or shown != n:
        failures.append(f"{path}: {n} points, {grid.GetNumberOfCells()} cells of types {types}, "
                        f"{shown} shown by the geometry filter")
    if not {"radius_m", "velocity_m_s", "force_N", "id"} <= arrays:
        failures.append(f"{path}: point arrays {arrays}")
        continue
    ids = grid.GetPointData().GetArray("id")
    if sorted(int(ids.GetValue(k)) for k in range(n)) != list(range(n)):
        failures.append(f"{path}: ids are not 0 to {n - 1} each once")
    radius = grid.GetPointData().GetArray("radius_m").GetRange()
    bounds = grid.GetBounds()
    if not (0.0035 <= radius[0] <= radius[1] <= 0.0045):
        failures.append(f"{path}: radii {radius} outside 3.5-4.5 mm")
    if not (0.0 < bounds[0] and bounds[1] < 0.06 and 0.0 < bounds[2] and bounds[3] < 0.06):
        failures.append(f"{path}: grain centres {bounds} outside the bin")
print(f"{len(particles)} particle snapshots: {grains} vertex cells each, all shown by "
      "vtkGeometryFilter")
plates = collection("body_plate.pvd")
for path in plates:
    grid = read(path)
    types = {grid.GetCellType(k) for k in range(grid.GetNumberOfCells())}
    if grid.GetNumberOfCells() != 96 or types != {vtk.VTK_TRIANGLE} or \
            grid.GetCellData().GetArray("force_N") is None:
        failures.append(f"{path}: {grid.GetNumberOfCells()} cells of types {types}")
print(f"{len(plates)} plate snapshots: 96 triangles each")

E, NU = 3.0e6, 0.2
E_STAR = E / (2.0 * (1.0 - NU * NU))
with open(os.path.join(folder, "series.csv")) as f:
    counted = {round(float(r["run_time_s"]), 6): int(r["contacts"]) for r in csv.DictReader(f)}
times = [float(e.get("timestep")) for e in ET.parse(os.path.join(folder, "contacts.pvd")).getroot().iter("DataSet")]
networks = collection("contacts.pvd")
worst, compared = 0.0, 0
for time, path, grains_path in zip(times, networks, particles):
    grid, grains = read(path), read(grains_path)
    lines = grid.GetNumberOfCells()
    types = {grid.GetCellType(k) for k in range(lines)}
    force = grid.GetCellData().GetArray("normal_force_N")
    radius = grains.GetPointData().GetArray("radius_m")
    if types - {vtk.VTK_LINE} or force is None or lines == 0:
        failures.append(f"{path}: {lines} cells of types {types}")
        continue
    expected = counted.get(round(time, 6))
    compared += expected is not None
    if expected is not None and expected != lines:
        failures.append(f"{path}: {lines} lines, series.csv counts {expected} contacts at t = {time}")
    for k in range(lines):
        i, j = (grid.GetCell(k).GetPointId(n) for n in (0, 1))
        xi, xj = grains.GetPoint(i), grains.GetPoint(j)
        ri, rj = radius.GetValue(i), radius.GetValue(j)
        delta = ri + rj - sum((a - b) ** 2 for a, b in zip(xi, xj)) ** 0.5
        hertz = 4.0 / 3.0 * E_STAR * (ri * rj / (ri + rj)) ** 0.5 * max(delta, 0.0) ** 1.5
        worst = max(worst, abs(force.GetValue(k) - hertz) / hertz if hertz > 0 else 1.0)
if compared == 0:
    failures.append(f"no contacts snapshot at a time of series.csv (times {times})")
if worst > 1e-9:
    failures.append(f"a contact's normal_force_N differs from Hertz by {worst:.3g} (relative)")
print(f"{len(networks)} contact networks ({compared} at a series.csv time, as many lines as it counts "
      f"contacts), forces Hertz's within {worst:.2g}")
if failures:
    sys.exit("FAILED:\n" + "\n".join(failures))
