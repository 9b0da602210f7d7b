"""tools/plot_wheel.py's count of grousers in the soil against the closed form: a wheel turning
at a steady rate with its lowest tip a depth d below the surface has a tip within the arc
|theta| < acos(1 - d / (r + h)) of straight down, so N grousers put on average
N acos(1 - d / (r + h)) / pi in the soil, and at any moment the floor or the ceiling of that.
Run under /usr/bin/python3 (the tool imports matplotlib)."""
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "tools"))
from plot_wheel import grousers_in_soil  # noqa: E402


def check(count, radius, height, depth):
    omega, dt, revolutions = 3.0, 1e-4, 40
    steps = int(revolutions * 2 * math.pi / omega / dt)
    rig = [{"time_s": str(i * dt), "omega_rad_s": str(omega)} for i in range(steps)]
    soil = [{"time_s": str(i * dt), "body": "wheel", "sinkage_m": str(depth)}
            for i in range(0, steps, 5)]
    counts = grousers_in_soil(rig, soil, "wheel", count, radius, height)
    expected = count * math.acos(1.0 - depth / (radius + height)) / math.pi
    mean = sum(counts) / len(counts)
    print(f"{count} grousers, {1000 * depth:.1f} mm deep: mean {mean:.4f}, closed form {expected:.4f}")
    assert abs(mean - expected) < 0.01 * expected, "mean count off by more than 1 %"
    assert set(counts) <= {math.floor(expected), math.ceil(expected)}, sorted(set(counts))


check(28, 0.075, 0.008, 0.019)  # the seed's 28 grousers at this wheel's sinkage: 6 or 7
check(12, 0.075, 0.008, 0.0185)
check(4, 0.075, 0.008, 0.030)
print("grouser count matches the closed form")
