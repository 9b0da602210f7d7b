#!/usr/bin/python3
"""Moment arms of the seed's grain-shape rolling law (docs/physics.md §2.6.1) against the tilt.

A virtual rectangle of half height a (the sphere's contact arm) and half base a tan(gamma)
rests on the contact with a face; tilted by theta it pivots over its corner, where the contact
force acts. In units of a, the pivot lies
    l_N = sin(gamma - t) / cos(gamma)   along T (arm of the normal force),
    l_T = cos(gamma - t) / cos(gamma)   below the centre along -N (arm of the tangential force),
t = theta wrapped into [-gamma, gamma] (the virtual grain lands on its next face every 2 gamma).
Near t = 0 the law replaces l_N by the face regime l_N = a tan^2(gamma) t / (2 delta) where that
is smaller; the figure shows it for delta / a = 2e-3 (dotted). Same formulas as
detail::grainShapeArms in dem/include/grainlink/dem/ContactKernel.hpp.

Usage: tools/plot_grain_shape.py [OUT.png]   (default docs/grain_shape_arms.png)
Runs under Debian's /usr/bin/python3 (python3-matplotlib, python3-numpy).
"""
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np


def arms(theta, gamma, overlap_ratio=None):
    """(l_N, l_T) / a at tilt theta for aspect-ratio angle gamma (radians)."""
    period = 2.0 * gamma
    tilt = theta - period * np.floor(theta / period + 0.5)
    a = np.abs(tilt)
    x = math.tan(gamma) * np.cos(a) - np.sin(a)
    if overlap_ratio is not None:
        x = np.minimum(x, math.tan(gamma) ** 2 / (2.0 * overlap_ratio) * a)
    return np.copysign(x, tilt), np.cos(a) + math.tan(gamma) * np.sin(a)


def main():
    if len(sys.argv) > 2:
        sys.exit(__doc__)
    out = sys.argv[1] if len(sys.argv) == 2 else "docs/grain_shape_arms.png"
    theta = np.linspace(-0.2, math.radians(100.0), 4001)
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    for gamma_deg, colour in ((10, "tab:blue"), (20, "tab:orange"), (30, "tab:green"),
                              (45, "tab:red")):
        gamma = math.radians(gamma_deg)
        l_n, l_t = arms(theta, gamma)
        label = f"γ = {gamma_deg}° (A = {math.tan(gamma):.2f})"
        top.plot(np.degrees(theta), l_n, color=colour, label=label)
        top.plot(np.degrees(theta), arms(theta, gamma, 2e-3)[0], color=colour, linestyle=":")
        bottom.plot(np.degrees(theta), l_t, color=colour, label=label)
        top.axvline(gamma_deg, color=colour, linewidth=0.6, linestyle="--")
        bottom.axvline(gamma_deg, color=colour, linewidth=0.6, linestyle="--")
    top.axhline(0.0, color="black", linewidth=0.6)
    top.set_ylabel("l_N / a  (normal force's arm along T)")
    top.set_title("Grain-shape law: moment arms of a rectangle tilting over its corner\n"
                  "restoring while l_N > 0, sign change at the tipping angle θ = γ (dashed), "
                  "next face at 2γ")
    top.legend(fontsize=8, loc="lower right")
    bottom.axhline(1.0, color="black", linewidth=0.6)
    bottom.set_ylabel("l_T / a  (tangential force's arm along −N)")
    bottom.set_xlabel("tilt θ of the grain relative to the contact [deg]")
    bottom.text(60, 1.02, "sphere: l_T = a, l_N = 0 (γ → 0)", fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
