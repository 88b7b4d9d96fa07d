#!/usr/bin/env python3
"""Plots a `pmr bench` CSV: frames per second against view count per method, and stacked per-stage
device times per method (the analogue of the paper's Fig. 14). A triangle sweep (one view count,
several generated scenes: `pmr bench --objects 1000,...,1000000`) is plotted as frame time against
triangle count instead, with the same stacked stages.

usage: scripts/plot_sweep.py SWEEP.csv [OUT_PREFIX]   -> OUT_PREFIX_fps.png (or _ms.png), OUT_PREFIX_stages.png
Uses Debian's python3-matplotlib (run with /usr/bin/python3 if another python3 comes first in PATH).
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def load(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"plot_sweep: {path} has no rows")
    by_method = {}
    for r in rows:
        by_method.setdefault(r["method"], []).append(r)
    sweep = "triangles" if len({r["triangles"] for r in rows}) > 1 else "views"
    for m in by_method.values():
        m.sort(key=lambda r: int(r[sweep]))
    return rows, by_method, sweep


def line_plot(by_method, x_key, y_of, xlabel, ylabel, logy, title, path):
    """One line per method: y_of(row) against row[x_key] on a log x axis."""
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for method, rs in by_method.items():
        ax.plot([int(r[x_key]) for r in rs], [y_of(r) for r in rs], "o-", label=method)
    ax.set_xscale("log", base=2 if x_key == "views" else 10)
    if logy:
        ax.set_yscale("log")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=8)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    path = sys.argv[1]
    prefix = sys.argv[2] if len(sys.argv) > 2 else path.rsplit(".", 1)[0]
    rows, by_method, sweep = load(path)
    r0 = rows[0]
    if sweep == "triangles":
        title = (f"{r0['scene'].rsplit('-', 1)[0]} scenes, {r0['views']} views of {r0['view_w']}x{r0['view_h']} "
                 f"-> display {r0['display_w']}x{r0['display_h']}")
        line_plot(by_method, "triangles", lambda r: float(r["ms_median"]), "triangles",
                  "ms per frame (render + encode)", True, title, prefix + "_ms.png")
    else:
        title = (f"{r0['scene']} ({r0['triangles']} triangles), display {r0['display_w']}x{r0['display_h']}, "
                 f"views of {r0['view_w']}x{r0['view_h']}")
        line_plot(by_method, "views", lambda r: 1000.0 / float(r["ms_median"]), "views N",
                  "frames per second (render + encode)", False, title, prefix + "_fps.png")
    stages_plot(by_method, sweep, title, prefix)


def stages_plot(by_method, sweep, title, prefix):
    stages = [("ms_setup", "vertex + setup"), ("ms_tile", "tile raster"), ("ms_fine", "fine raster (+ encode if fused)"),
              ("ms_encode", "encode")]
    methods = list(by_method)
    fig, axes = plt.subplots(1, len(methods), figsize=(4.2 * len(methods), 4.2), sharey=True, squeeze=False)
    for ax, method in zip(axes[0], methods):
        rs = by_method[method]
        xs = list(range(len(rs)))
        bottom = [0.0] * len(rs)
        for key, label in stages:
            vals = [float(r[key]) for r in rs]
            ax.bar(xs, vals, bottom=bottom, label=label)
            bottom = [b + v for b, v in zip(bottom, vals)]
        ax.set_xticks(xs)
        ax.set_xticklabels([r[sweep] for r in rs], rotation=30 if sweep == "triangles" else 0)
        ax.set_xlabel("views N" if sweep == "views" else "triangles")
        ax.set_title(method)
        ax.grid(True, axis="y", alpha=0.3)
    axes[0][0].set_ylabel("device time per frame (ms)")
    axes[0][-1].legend(fontsize=8)
    fig.suptitle(title, fontsize=8)
    fig.tight_layout()
    fig.savefig(prefix + "_stages.png", dpi=110)


if __name__ == "__main__":
    main()
