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
- each plate snapshot holds the plate's triangles (24 facets: 96 triangles) and their loads.
Usage: read_vtk.py GRAINLINK SCENARIO WORK"""
import os
import shutil
import subprocess
import sys
import json
import xml.etree.ElementTree as ET

import vtk

grainlink, scenario, work = map(os.path.abspath, sys.argv[1:4])
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
done = subprocess.run([grainlink, "dem", scenario, "--out", os.path.join(work, "out")], cwd=work,
                      capture_output=True, text=True)
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
if failures:
    sys.exit("FAILED:\n" + "\n".join(failures))
