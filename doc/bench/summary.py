#!/usr/bin/python3
"""Summaries of doc/performance.sh's timing table, as Markdown sections.

usage: summary.py TIMES.tsv

TIMES.tsv, one measurement a line (tab-separated): DEM label, task,
directions ("-" for none), tool, settings, wall s (or a reason it is not a
number), runs, max RSS MB, speed-up, cells, directions (number), skysweep's
setting tag, skysweep's sweep time s, skysweep's largest kernel build s.

Writes three sections: the speed-ups by DEM size, skysweep's scaling on the
synthetic DEMs (least-squares slope of log wall time against log cells x
directions), and skysweep's peak memory against DEM size.
"""
import math
import sys
from collections import OrderedDict, defaultdict

TAG_NAMES = {
    "curv": "horizon, curvature on (vs r.horizon)",
    "flat": "horizon, curvature off",
    "rad": "svf radiative",
    "geo": "svf geometric (unlimited)",
    "georad": "svf geometric --radius (RVT's)",
    "hs": "hillshade",
    "ins": "insolation, one day",
}
# The products whose cost is one sweep per direction over every cell: their
# time should grow as cells x directions (exponent 1 in the pooled fit).
SWEEPS = ("curv", "flat", "rad", "geo")


def number(text):
    try:
        return float(text)
    except ValueError:
        return None


def read(path):
    rows = []
    with open(path) as f:
        for line in f:
            c = line.rstrip("\n").split("\t")
            c += [""] * (14 - len(c))
            rows.append({
                "dem": c[0], "task": c[1], "dirs": c[2], "tool": c[3], "settings": c[4],
                "wall": number(c[5]), "wall_text": c[5], "rss": number(c[7]),
                "speedup": c[8], "cells": number(c[9]) or 0, "ndirs": number(c[10]) or 1,
                "tag": c[11], "sweep": number(c[12]),
            })
    return rows


def slope(points):
    """Least-squares slope of y on x, and the number of points."""
    n = len(points)
    if n < 2:
        return None
    mx = sum(x for x, _ in points) / n
    my = sum(y for _, y in points) / n
    sxx = sum((x - mx) ** 2 for x, _ in points)
    if sxx == 0:
        return None
    return sum((x - mx) * (y - my) for x, y in points) / sxx


def pooled_slope(groups):
    """One slope, an intercept per group (the groups' own means taken out)."""
    sxy = sxx = 0.0
    for points in groups:
        if len(points) < 2:
            continue
        mx = sum(x for x, _ in points) / len(points)
        my = sum(y for _, y in points) / len(points)
        sxx += sum((x - mx) ** 2 for x, _ in points)
        sxy += sum((x - mx) * (y - my) for x, y in points)
    return sxy / sxx if sxx > 0 else None


def fmt(v, digits=2):
    return "–" if v is None else f"{v:.{digits}f}"


def speedups(rows):
    dems = list(OrderedDict.fromkeys(r["dem"] for r in rows))
    table = OrderedDict()
    for r in rows:
        if r["tool"] == "skysweep":
            continue
        against = "skysweep --radius" if "against skysweep --radius" in r["settings"] else ""
        key = (r["task"], r["dirs"], r["tool"] + (f" vs {against}" if against else ""))
        cell = r["speedup"] if r["wall"] is not None else r["wall_text"].split(" (")[0]
        if cell.startswith("not run: predicted"):
            cell = "not run (predicted > timeout)"
        elif cell.startswith("not run: timed out"):
            cell = "not run (timed out before)"
        table.setdefault(key, {})[r["dem"]] = cell or "–"
    out = ["## Speed-ups at a glance", "",
           "The peer's median wall time over skysweep's (the same DEM, task and directions;",
           "the full rows are in the next table). Above 1: skysweep is faster.", "",
           "| task | directions | peer | " + " | ".join(dems) + " |",
           "|---|---|---|" + "---|" * len(dems)]
    for (task, dirs, tool), cells in table.items():
        out.append(f"| {task} | {dirs} | {tool} | " +
                   " | ".join(cells.get(d, "–") for d in dems) + " |")
    return out


def scaling(rows):
    ours = [r for r in rows if r["tool"] == "skysweep" and r["dem"].startswith("synthetic")
            and r["wall"] is not None and r["cells"] > 0]
    sizes = sorted({r["cells"] for r in ours})
    if len(sizes) < 2:
        return []
    by_setting = OrderedDict()
    for r in ours:
        by_setting.setdefault((r["tag"], r["dirs"]), {})[r["cells"]] = r
    labels = [f"{int(round(math.sqrt(c)))}²" for c in sizes]
    out = ["## How skysweep's time grows", "",
           "On the synthetic DEMs: skysweep's median wall time (whole command: reading, sweeping,",
           "writing) and, in brackets, the sweep alone from its own summary. The exponent is the",
           "least-squares slope of log time against log (cells × directions) over the sizes; 1 is",
           "linear. Small DEMs carry a fixed cost (start-up, OpenCL set-up, GDAL), which pulls",
           "the whole-command exponent below 1; the sweep's exponent shows the algorithm.", "",
           "| product | directions | " + " | ".join(labels) + " | exponent (wall) | exponent (sweep) |",
           "|---|---|" + "---|" * len(labels) + "---|---|"]
    groups_wall, groups_sweep = defaultdict(list), defaultdict(list)
    for (tag, dirs), by_cells in by_setting.items():
        wall_pts, sweep_pts, cells = [], [], []
        for c in sizes:
            r = by_cells.get(c)
            if r is None:
                cells.append("–")
                continue
            x = math.log(c * r["ndirs"])
            wall_pts.append((x, math.log(r["wall"])))
            if r["sweep"]:
                sweep_pts.append((x, math.log(r["sweep"])))
            cells.append(f"{r['wall']:g} s" + (f" ({r['sweep']:g})" if r["sweep"] else ""))
            if tag in SWEEPS:
                groups_wall[tag].append(wall_pts[-1])
                if r["sweep"]:
                    groups_sweep[tag].append(sweep_pts[-1])
        out.append(f"| {TAG_NAMES.get(tag, tag)} | {dirs} | " + " | ".join(cells) +
                   f" | {fmt(slope(wall_pts))} | {fmt(slope(sweep_pts))} |")
    pw = pooled_slope(groups_wall.values())
    ps = pooled_slope(groups_sweep.values())
    out += ["", f"Pooled over the unlimited horizon and SVF products ({', '.join(TAG_NAMES[t] for t in SWEEPS)};"
            " all their direction counts, one intercept per product, so that the directions vary within a"
            f" fit): exponent **{fmt(pw)}** for the whole command, **{fmt(ps)}** for the sweep alone,"
            f" from {labels[0]} to {labels[-1]}."]
    return out


def memory(rows):
    ours = [r for r in rows if r["tool"] == "skysweep" and r["rss"] is not None and r["cells"] > 0]
    if not ours:
        return []
    dems = list(OrderedDict.fromkeys(r["dem"] for r in ours))
    cells_of = {r["dem"]: r["cells"] for r in ours}
    by_setting = OrderedDict()
    for r in ours:
        by_setting.setdefault((r["tag"], r["dirs"]), {})[r["dem"]] = r["rss"]
    out = ["## skysweep's peak memory against DEM size", "",
           "Maximum resident set size (MB, median of the runs) per product; the last column is",
           "the growth over the DEMs, as bytes per added cell (least squares of RSS on cells).", "",
           "| product | directions | " + " | ".join(dems) + " | bytes per cell |",
           "|---|---|" + "---|" * len(dems) + "---|"]
    for (tag, dirs), by_dem in by_setting.items():
        pts = [(cells_of[d], by_dem[d] * 1048576.0) for d in dems if d in by_dem]
        s = slope(pts)
        out.append(f"| {TAG_NAMES.get(tag, tag)} | {dirs} | " +
                   " | ".join(f"{by_dem[d]:.0f}" if d in by_dem else "–" for d in dems) +
                   f" | {fmt(s, 0)} |")
    return out


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    rows = read(sys.argv[1])
    for section in (speedups(rows), scaling(rows), memory(rows)):
        if section:
            print("\n".join(section))
            print()


if __name__ == "__main__":
    main()
