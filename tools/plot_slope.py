#!/usr/bin/python3
"""The slope study's plot (docs/studies/slope.md) from the per-seed table of that page, which
holds what each point's run printed (its study folders are not kept): slip and motor torque
against the slope angle, a steady point filled with its sd, a point that dug in for the whole
drive open (its last second's mean and sd). The torque panel adds the level wheel's torque plus
the slope's own share, m g sin(a) r (3 kg, r = 75 mm).
Usage: /usr/bin/python3 tools/plot_slope.py [docs/studies/slope.md] [out.png]"""
import math
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

page = sys.argv[1] if len(sys.argv) > 1 else "docs/studies/slope.md"
out = sys.argv[2] if len(sys.argv) > 2 else "docs/studies/slope.png"
MASS_KG, RADIUS_M, G = 3.0, 0.075, 9.81

NUMBER = r"(-?[0-9.]+)"


def mean_sd(cell):
    """'0.049 ± 0.069 (se 0.019)' -> (0.049, 0.069); '0.593 (se 0.019)' -> (0.593, None)."""
    m = re.match(NUMBER + r"(?:\s*±\s*" + NUMBER + ")?", cell.strip().replace("−", "-"))
    if not m:
        return None
    return float(m.group(1)), (float(m.group(2)) if m.group(2) else None)


rows = []
in_table = False
for line in open(page):
    if line.startswith("| slope | seed | outcome"):
        in_table = True
        continue
    if in_table and not line.startswith("|"):
        break
    if not in_table or line.startswith("|---"):
        continue
    cells = [c.strip() for c in line.strip().strip("|").split("|")]
    angle = float(re.match(NUMBER, cells[0]).group(1))
    slip, torque = mean_sd(cells[3]), mean_sd(cells[4])
    if slip is None or torque is None:  # failed before driving
        continue
    rows.append({"angle": angle, "seed": cells[1], "steady": cells[2].startswith("steady"),
                 "slip": slip, "torque": torque})
if not rows:
    sys.exit(f"{page}: no per-seed table ('| slope | seed | outcome ...') found")

fig, (a_slip, a_torque) = plt.subplots(1, 2, figsize=(10, 4))
for r in rows:
    style = dict(fmt="o", color="C0", markersize=6, capsize=3,
                 mfc="C0" if r["steady"] else "white", mec="C0")
    a_slip.errorbar(r["angle"], r["slip"][0], yerr=r["slip"][1] or 0.0, **style)
    a_torque.errorbar(r["angle"], r["torque"][0], yerr=r["torque"][1] or 0.0, **style)
level = [r["torque"][0] for r in rows if r["angle"] == 0.0]
if level:
    t0 = sum(level) / len(level)
    angles = [0.0, 5.0, 10.0, 15.0, 20.0, 25.0]
    a_torque.plot(angles, [t0 + MASS_KG * G * math.sin(math.radians(a)) * RADIUS_M
                           for a in angles], "k--", lw=1,
                  label="level torque + m g sin(a) r")
    a_torque.legend(loc="upper left", fontsize=8)
a_slip.plot([], [], "o", color="C0", label="steady (mean ± sd)")
a_slip.plot([], [], "o", color="C0", markerfacecolor="white",
            label="digs in: last second (mean ± sd)")
a_slip.legend(loc="lower right", fontsize=8)
a_slip.set(xlabel="slope [deg]", ylabel="slip [-]", ylim=(-0.15, 1.0),
           title="12-grouser wheel, 3 kg: slip")
a_torque.set(xlabel="slope [deg]", ylabel="motor torque [N m]", title="motor torque")
for a in (a_slip, a_torque):
    a.grid(alpha=0.3)
fig.tight_layout()
fig.savefig(out, dpi=110)
print(f"plot: {out} ({len(rows)} runs from {page})")
