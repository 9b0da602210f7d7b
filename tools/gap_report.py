#!/usr/bin/python3
"""The sim-to-real diagnosis as one self-contained HTML page (docs/gap.md, "Outputs").

Reads DIR/diagnosis.json and DIR/features.csv (written by `grainlink gap diagnose`) and writes
DIR/report.html: the result in words, measured against simulated with their bands, the map of
standardised residuals, the signature overlap of the candidate effects, and the held-out gap
before and after. Every plot is embedded (base64 PNG), so the page travels alone.

usage: /usr/bin/python3 tools/gap_report.py DIR
"""
import base64
import csv
import html
import io
import json
import math
import os
import sys
from collections import OrderedDict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def number(text):
    try:
        return float(text)
    except (TypeError, ValueError):
        return math.nan


def png(fig):
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
    plt.close(fig)
    return base64.b64encode(buf.getvalue()).decode("ascii")


def axis_of(kind):
    if kind.startswith("plate_sinkage"):
        return "sinkage [mm]", 1000.0
    if "shear" in kind:
        return "shear displacement [mm]", 1000.0
    if kind.startswith("wheel"):
        return "slip [-]", 1.0
    if kind.startswith("mole"):
        return "stroke", 1.0
    return "", 1.0


def is_scalar(rows):
    """A scalar observable (an angle of repose): every feature at one x."""
    return all(number(r["x_lo"]) == number(r["x_hi"]) for r in rows)


def quantity_of(observable):
    """pressure_Pa -> 'pressure [Pa]': the SI name's unit as an axis label."""
    for unit in ("Pa", "N_m", "N", "m", "deg"):
        if observable.endswith("_" + unit):
            return f"{observable[:-len(unit) - 1].replace('_', ' ')} [{unit.replace('_', ' ')}]"
    return observable


def curves_plot(rows, diag):
    """One panel per experiment and observable: measured +- 2 u_D, simulated +- 2 u_val, the
    best model and (held out) the null model."""
    panels = OrderedDict()
    for r in rows:
        panels.setdefault((r["experiment"], r["observable"]), []).append(r)
    n = len(panels)
    if n == 0:
        return None
    cols = min(3, n)
    nrows = math.ceil(n / cols)
    fig, axes = plt.subplots(nrows, cols, figsize=(4.2 * cols, 3.2 * nrows), squeeze=False)
    held = set(diag.get("held_out_experiments", []))
    for ax, ((exp, obs), rs) in zip(axes.flat, panels.items()):
        label, scale = axis_of(rs[0]["kind"])
        x = [0.5 * (number(r["x_lo"]) + number(r["x_hi"])) * scale for r in rs]
        if is_scalar(rs):
            x = list(range(len(rs)))
        m = [number(r["measured"]) for r in rs]
        ud = [2 * number(r["u_D"]) for r in rs]
        s = [number(r["simulated"]) for r in rs]
        uv = [2 * number(r["u_val"]) for r in rs]
        ax.errorbar(x, m, yerr=ud, fmt="o", color="k", ms=4, label="measured ±2u_D")
        # A marker on every line: a scalar (an angle of repose) is one point.
        ax.plot(x, s, "-", marker=".", color="tab:blue", label="base model")
        ax.fill_between(x, [a - b for a, b in zip(s, uv)], [a + b for a, b in zip(s, uv)],
                        color="tab:blue", alpha=0.2, label="±2u_val")
        best = [number(r["best_model_mean"]) for r in rs]
        if any(math.isfinite(b) for b in best):
            ax.plot(x, best, "--", marker=".", color="tab:red",
                    label=rs[0]["best_model"] or "best model")
        nm = [number(r["null_mean"]) for r in rs]
        if any(math.isfinite(v) for v in nm):
            ax.plot(x, nm, ":", marker=".", color="tab:green", label="null model")
        ax.set_title(exp + (" (held out)" if exp in held else " (calibration)") + "\n" + obs,
                     fontsize=9)
        ax.set_xlabel(label, fontsize=8)
        ax.set_ylabel(quantity_of(obs), fontsize=8)
        ax.tick_params(labelsize=7)
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    axes.flat[0].legend(fontsize=6)
    fig.tight_layout()
    return png(fig)


def residual_map(rows, diag):
    """One panel per kind of observable, one row per experiment, each bin drawn over its own x
    range in the kind's unit: z = (measured - simulated) / u_val."""
    kinds = OrderedDict()
    for r in rows:
        kinds.setdefault(r["kind"], OrderedDict()).setdefault(r["experiment"], []).append(r)
    if not kinds:
        return None
    held = set(diag.get("held_out_experiments", []))
    cmap, norm = plt.get_cmap("RdBu"), plt.Normalize(vmin=-6, vmax=6)
    heights = [max(1, len(exps)) for exps in kinds.values()]
    fig, axes = plt.subplots(len(kinds), 1, squeeze=False, layout="constrained",
                             figsize=(8.0, 1.0 + 0.3 * sum(heights) + 0.6 * len(kinds)),
                             gridspec_kw={"height_ratios": heights})
    for ax, (kind, exps) in zip(axes[:, 0], kinds.items()):
        label, scale = axis_of(kind)
        scalar = is_scalar([r for rs in exps.values() for r in rs])
        for i, rs in enumerate(exps.values()):
            for j, r in enumerate(rs):
                lo, hi = (j, j + 1) if scalar else (number(r["x_lo"]) * scale,
                                                    number(r["x_hi"]) * scale)
                z = number(r["z"])
                ax.barh(i, hi - lo, left=lo, height=0.9,
                        color=cmap(norm(z)) if math.isfinite(z) else "lightgrey",
                        edgecolor="k" if math.isfinite(z) and abs(z) > 2 else "none",
                        linewidth=0.6)
        ax.set_yticks(range(len(exps)))
        ax.set_yticklabels([e + (" (held out)" if e in held else "") for e in exps], fontsize=7)
        ax.invert_yaxis()
        ax.set_title(kind, fontsize=8)
        ax.set_xlabel("(one value)" if scalar else label, fontsize=8)
        if scalar:
            ax.set_xticks([])
        ax.tick_params(labelsize=7)
    fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap=cmap), ax=list(axes[:, 0]),
                 label="z = (meas. - sim.) / u_val")
    axes[0, 0].set_title("standardised residuals (outlined: |z| > 2, outside the validation "
                         "uncertainty)\n" + axes[0, 0].get_title(), fontsize=9)
    return png(fig)


def overlap_plot(diag):
    names = diag["signature_overlap"]["effects"]
    f = diag["signature_overlap"]["fraction"]
    if not names:
        return None
    fig, ax = plt.subplots(figsize=(1.5 + 0.45 * len(names), 1.2 + 0.45 * len(names)))
    im = ax.imshow(f, cmap="viridis", vmin=0, vmax=1)
    ax.set_xticks(range(len(names)))
    ax.set_xticklabels(names, rotation=60, ha="right", fontsize=7)
    ax.set_yticks(range(len(names)))
    ax.set_yticklabels(names, fontsize=7)
    ax.set_xlabel("reproduced by", fontsize=8)
    fig.colorbar(im, ax=ax, label="share of the row's signature")
    ax.set_title("signature overlap on this design", fontsize=9)
    return png(fig)


def before_after(diag):
    labels, values = ["base", "null model"], [diag["held_out"]["base"]["gap_beyond_uncertainty"],
                                              diag["held_out"]["null"]["gap_beyond_uncertainty"]]
    for c in diag["candidates"]:
        if c.get("confirmed"):
            labels.append(c["effect"])
            values.append(c["held_out"]["gap_beyond_uncertainty"])
    for p in diag["pairs"]:
        if p.get("confirmed"):
            labels.append(" + ".join(p["effects"]))
            values.append(p["held_out"]["gap_beyond_uncertainty"])
    values = [100 * (v if v is not None else math.nan) for v in values]
    # The claimed model red, every other candidate blue: a short bar is no claim by itself.
    claimed = diag["verdict"]["model"] if diag["verdict"]["model_is"] == "claimed" else None
    colors = ["0.5", "tab:green"] + ["tab:red" if name == claimed else "tab:blue"
                                     for name in labels[2:]]
    fig, ax = plt.subplots(figsize=(1.5 + 0.8 * len(labels), 3))
    ax.bar(range(len(labels)), values, color=colors)
    for i, v in enumerate(values):
        if math.isfinite(v):
            ax.annotate(f"{v:.0f} %", (i, v), ha="center", va="bottom", fontsize=7)
    ax.set_xticks(range(len(labels)))
    ax.set_xticklabels(labels, rotation=30, ha="right", fontsize=7)
    ax.set_ylabel("held-out gap beyond u_val [%]", fontsize=8)
    ax.set_title("held-out gap before and after", fontsize=9)
    return png(fig)


def main(directory):
    with open(f"{directory}/diagnosis.json") as f:
        diag = json.load(f)
    if "verdict" not in diag:
        sys.exit(f"{directory}/diagnosis.json has no 'verdict': it was written by an older "
                 "grainlink; run `grainlink gap diagnose` again with its --sims cache (no "
                 "simulation is repeated)")
    with open(f"{directory}/features.csv") as f:
        rows = list(csv.DictReader(f))
    with open(f"{directory}/report.txt") as f:
        text = f.read()
    figures = [("Measured against simulated", curves_plot(rows, diag),
                "Each panel is one experiment: the measured mean with twice its measurement "
                "uncertainty (points), the base model with twice the validation uncertainty u_val "
                "(blue band), the model the verdict names (red dashes) and, on held-out "
                "experiments, the null model: the base plus a generic correction fitted on the "
                "calibration experiments (green dots)."),
               ("Where the gap lies", residual_map(rows, diag),
                "One panel per kind of observable, one row per experiment, each cell one bin "
                "drawn over its own range of x (sinkage, shear displacement, slip) in the axis's "
                "unit; red: the simulation is too high there, blue: too low; outlined cells lie "
                "more than 2 u_val off the measurement."),
               ("Held-out gap", before_after(diag),
                "How far the held-out experiments lie beyond their validation uncertainty with "
                "the base, the null model and each re-simulated candidate. A shorter bar than the "
                "null model's is not a claim by itself: the claim also needs the held-out "
                "prediction to beat the null model's at the level (see the verdict)."),
               ("Which effects this design can tell apart", overlap_plot(diag),
                "The share of each row effect's signature that the column effect reproduces at "
                "its best strength: near 1, these experiments cannot tell the two apart.")]
    parts = ["<!DOCTYPE html><html><head><meta charset='utf-8'><title>grainlink gap: "
             f"{html.escape(diag['measurements'])}</title><style>body{{font-family:sans-serif;"
             "max-width:1100px;margin:auto}} pre{{background:#f4f4f4;padding:8px;white-space:"
             "pre-wrap}} img{{max-width:100%}}</style></head><body>",
             f"<h1>Sim-to-real diagnosis: {html.escape(diag['measurements'])}</h1>",
             f"<p style='font-size:120%'><b>{html.escape(diag['verdict']['text'])}</b></p>",
             f"<p>{html.escape(diag['claim'])}</p>",
             (f"<p style='color:#a00'><b>Warning</b>: {html.escape(diag['numerical_warning'])}</p>"
              if diag.get("numerical_warning") else ""),
             "<h3>Where the base model differs from the measurements</h3>",
             "<ul>" + "".join(f"<li>{html.escape(w['text'])}</li>" for w in diag["where"]) + "</ul>"]
    for title, fig, caption in figures:
        if fig:
            parts.append(f"<h2>{title}</h2><img src='data:image/png;base64,{fig}' "
                         f"alt='{html.escape(title)}'><p><i>{html.escape(caption)}</i></p>")
    parts.append(f"<h2>Report</h2><pre>{html.escape(text)}</pre></body></html>")
    with open(f"{directory}/report.html.tmp", "w") as f:
        f.write("\n".join(parts))
    os.replace(f"{directory}/report.html.tmp", f"{directory}/report.html")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
