#!/usr/bin/python3
"""Turns the CSV of doc/accuracy_driver (run by doc/accuracy.sh) into
doc/accuracy.md, the plots in doc/img/ and, with --table, the generated part
of src/core/accuracy_table.c. Every number written comes from the CSV."""
import argparse
import collections
import csv
import datetime
import math
import os
import re

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: E402
except ImportError:  # tables still come out; CI need not plot
    plt = None

DEFS = [("svf_geometric", "geometric (1 - mean sin h, Zaksek/RVT)"),
        ("svf_horizontal", "radiative, horizontal surface (mean cos^2 h)"),
        ("svf_tilted", "radiative, tilted cell (Dozier & Frew)")]
DEF_ENUM = {"svf_geometric": "SS_SVF_DEF_GEOMETRIC", "svf_horizontal": "SS_SVF_DEF_HORIZONTAL",
            "svf_tilted": "SS_SVF_DEF_RADIATIVE"}
TARGETS = (0.01, 0.005)


def num(x):
    try:
        return float(x)
    except ValueError:
        return math.nan


def load(path):
    rows = []
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            for k in ("value", "mean", "p95", "max", "seconds"):
                r[k] = num(r[k])
            r["cells"] = int(r["cells"])
            rows.append(r)
    return rows


def ms_per_mcell(r):
    return 1000.0 * r["seconds"] / (r["cells"] / 1e6) if r["cells"] else math.nan


def fmt(x, digits=3):
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "–"
    if x == 0:
        return "0"
    if abs(x) >= 1000 or abs(x) < 1e-3:
        return f"{x:.{digits - 1}e}"
    return f"{x:.{digits}g}"


def table(header, body):
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(str(c) for c in row) + " |" for row in body]
    return "\n".join(out)


class Data:
    def __init__(self, rows):
        self.rows = rows
        self.scenes = []
        self.klass = {}
        self.grid = {}
        for r in rows:
            if r["scene"] not in self.scenes and r["study"] in ("directions", "scene"):
                self.scenes.append(r["scene"])
            self.klass[r["scene"]] = r["class"]
            if r["study"] == "scene":
                self.grid[r["scene"]] = (r["setting"], int(r["mean"]), int(r["p95"]))
        self.dirs = sorted({int(r["value"]) for r in rows if r["study"] == "directions"
                            and r["setting"] == "lines=interpolated"})
        self.ddirs = sorted({int(r["value"]) for r in rows if r["study"] == "directions"
                             and r["setting"] == "lines=digital"})

    def get(self, study, scene, setting, value, quantity):
        for r in self.rows:
            if (r["study"] == study and r["scene"] == scene and r["setting"] == setting
                    and r["quantity"] == quantity
                    and (value is None or int(r["value"]) == int(value))):
                return r
        return None

    def natural(self):
        return [s for s in self.scenes if self.klass[s] != "analytic"]

    def default_scenes(self):
        """Terrain models (DTMs) the default is chosen on; surface models with
        vertical walls (DSMs) are tabulated but have a floor of their own."""
        return [s for s in self.natural() if "DSM" not in self.klass[s]]


def robust(errors):
    """A count's error as ss_directions_for_tolerance takes it: the larger of
    its own and the next larger count's (a dip at one count, such as D = 8
    whose lines all run through cell centres, is not trusted)."""
    out = []
    for i, e in enumerate(errors):
        nxt = errors[i + 1] if i + 1 < len(errors) else None
        out.append(None if e is None else (max(e, nxt) if nxt is not None else e))
    return out


def smallest_meeting(errors, target):
    """Index of the smallest D whose robust error is <= target, or None."""
    for i, e in enumerate(robust(errors)):
        if e is not None and e <= target:
            return i
    return None


def svf_plot(d, path):
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6), sharey=True)
    for ax, (q, title) in zip(axes, DEFS):
        for k, s in enumerate(d.scenes):
            for lines, style in (("lines=interpolated", "-o"), ("lines=digital", "--s")):
                dirs = d.dirs if lines.endswith("interpolated") else d.ddirs
                pts = [d.get("directions", s, lines, D, q) for D in dirs]
                pts = [(ms_per_mcell(r), r["p95"], D) for r, D in zip(pts, dirs) if r]
                pts = [p for p in pts if p[1] > 0]
                if not pts:
                    continue
                ax.plot([p[0] for p in pts], [p[1] for p in pts], style, color=f"C{k}",
                        markersize=4, alpha=1 if style == "-o" else 0.5,
                        label=s if style == "-o" else None)
                if style == "-o":
                    for x, y, D in pts:
                        ax.annotate(str(D), (x, y), fontsize=6, xytext=(2, 2),
                                    textcoords="offset points")
        for t in TARGETS:
            ax.axhline(t, color="grey", lw=0.6, ls=":")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(title, fontsize=9)
        ax.set_xlabel("wall time, ms per Mcell (whole SVF)")
        ax.grid(True, which="both", lw=0.2)
    axes[0].set_ylabel("SVF error, 95th percentile over cells")
    axes[0].legend(fontsize=7)
    fig.suptitle("SVF error against the continuous reference vs time "
                 "(numbers: directions; dashed: digital lines)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def horizon_plot(d, path):
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.4), sharey=True)
    for ax, q, title in ((axes[0], "horizon_deg", "at any azimuth (linear between directions)"),
                         (axes[1], "horizon_at_swept_deg", "at the swept azimuths only")):
        for k, s in enumerate(d.scenes):
            pts = [(D, d.get("directions", s, "lines=interpolated", D, q)) for D in d.dirs]
            pts = [(D, r["p95"], r["mean"]) for D, r in pts if r]
            ax.plot([p[0] for p in pts], [max(p[1], 1e-7) for p in pts], "-o", color=f"C{k}",
                    markersize=4, label=s)
            ax.plot([p[0] for p in pts], [max(p[2], 1e-7) for p in pts], ":", color=f"C{k}")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(title, fontsize=9)
        ax.set_xlabel("directions D")
        ax.grid(True, which="both", lw=0.2)
    axes[0].set_ylabel("horizon error, deg (solid: p95, dotted: mean)")
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def insolation_plot(d, path):
    rows = [r for r in d.rows if r["study"] == "insolation" and r["quantity"] == "global_pct"
            and not r["setting"].startswith("reference")]
    if not rows:
        return False
    fig, ax = plt.subplots(figsize=(6.5, 4.4))
    groups = collections.OrderedDict()
    for r in rows:
        groups.setdefault(r["setting"], []).append(r)
    for k, (setting, rs) in enumerate(groups.items()):
        xs = [ms_per_mcell(r) / 1000 for r in rs]
        ys = [max(r["p95"], 1e-6) for r in rs]
        ax.plot(xs, ys, "-o", color=f"C{k}", markersize=4, label=setting)
        for x, y, r in zip(xs, ys, rs):
            ax.annotate(f"{int(r['value'])}", (x, y), fontsize=7, xytext=(2, 2),
                        textcoords="offset points")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time, s per Mcell for the day")
    ax.set_ylabel("daily global irradiation error, %, 95th percentile")
    ax.set_title("time step (min) and shadow mode (numbers: step or directions)", fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(True, which="both", lw=0.2)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def worst_table(d):
    """For each definition: the worst p95 over the natural terrains at each D."""
    out = {}
    for q, _ in DEFS:
        col = []
        for D in d.dirs:
            vals = [d.get("directions", s, "lines=interpolated", D, q)
                    for s in d.default_scenes()]
            vals = [r["p95"] for r in vals if r]
            col.append(max(vals) if vals else None)
        out[q] = col
    return out


def choose(worst, tol):
    """What ss_directions_for_tolerance returns: (index, robust error, met)."""
    r = robust(worst)
    i = smallest_meeting(worst, tol)
    if i is not None:
        return i, r[i], True
    best = min(e for e in r if e is not None)
    k = next(k for k, e in enumerate(r) if e is not None and e <= 1.05 * best)
    return k, r[k], False


def default_directions(d):
    """The smallest D at which every definition's worst-case error (robust)
    is within 10 % (or 0.0005) of the best it reaches at any D."""
    worst = worst_table(d)
    rob = {q: robust(worst[q]) for q, _ in DEFS}
    for i, D in enumerate(d.dirs):
        ok = True
        for q, _ in DEFS:
            vals = [e for e in rob[q] if e is not None]
            if not vals or rob[q][i] is None or rob[q][i] > max(1.1 * min(vals), min(vals) + 5e-4):
                ok = False
        if ok:
            return i, rob
    return None, rob


def in_short(d):
    """A few sentences, every number taken from the rows."""
    out = []
    if d.dirs and d.default_scenes():
        i, rob = default_directions(d)
        if i is not None:
            out.append(f"Directions: from D = {d.dirs[i]} on no SVF definition gets more than "
                       "10 % (or 0.0005) better on the terrain models (" +
                       ", ".join(d.default_scenes()) + "); their worst p95 error there is " +
                       ", ".join(f"{q.replace('svf_', '')} {fmt(rob[q][i], 2)}" for q, _ in DEFS)
                       + ". When no --directions is given, the planner reads this table (src/core/accuracy_table.c): the fewest directions whose error meets --svf-tolerance, or the cheapest near the floor where none does (doc/planner.md).")
        dmax = d.dirs[-1]
        k = d.dirs.index(32) if 32 in d.dirs else None
        if k is not None:
            parts = []
            for q, _ in DEFS:
                own = [d.get("directions", s, "lines=interpolated", 32, f"{q}_vs_D{dmax}")
                       for s in d.default_scenes()]
                own = [r["p95"] for r in own if r]
                tot = [d.get("directions", s, "lines=interpolated", 32, q)
                       for s in d.default_scenes()]
                tot = [r["p95"] for r in tot if r]
                if own and tot:
                    parts.append(f"{q.replace('svf_', '')} {fmt(max(own), 2)} of {fmt(max(tot), 2)}")
            if parts:
                out.append("What limits SVF accuracy on real DEMs is the sweep's sampling along "
                           "its lines, not the number of directions: at D = 32 the part the "
                           f"directions control (against D = {dmax}) is, worst p95 over the "
                           "terrain models, " + "; ".join(parts) + " of the total error "
                           "against the continuous reference. The rest is the floor the lines "
                           "set where nearby terrain is steep: they sample it only where they "
                           "cross rows or columns, and give a cell the horizons of points up to "
                           "a cell beside it. It shrinks with the cell size "
                           "(tests/test_reference.c checks that the sweep converges to the "
                           "reference as the cells of one surface shrink).")
    ins = [r for r in d.rows if r["study"] == "insolation" and r["quantity"] == "global_pct"
           and r["setting"].startswith("step_min")]
    if ins:
        good = [r for r in ins if r["p95"] <= 1.0]
        if good:
            r = max(good, key=lambda r: r["value"])
            out.append(f"Insolation ({r['scene']}, 21 December): a daily sum within 1 % (p95) "
                       f"of 1-minute steps takes {int(r['value'])}-minute steps "
                       f"({fmt(ms_per_mcell(r) / 1000)} s per Mcell for the day); hourly steps "
                       "err by " + fmt(max(x["p95"] for x in ins if x["value"] == max(
                           y["value"] for y in ins))) + " % (p95).")
    eff = [r for r in d.rows if r["study"] == "effects"]
    if eff:
        def top(setting, quantity):
            rs = [r for r in eff if r["setting"] == setting and r["quantity"] == quantity]
            return max(rs, key=lambda r: r["p95"] if quantity != "shadow_flips_pct"
                       else r["mean"]) if rs else None
        c = top("curvature", "horizon_deg")
        s = top("curvature", "svf_geometric")
        n = top("north", "horizon_deg")
        nf = d.get("effects", n["scene"], "north", None, "shadow_flips_pct") if n else None
        ng = d.get("effects", n["scene"], "north", None, "convergence_deg") if n else None
        g = top("sun_per_cell", "global_pct")
        gs = d.get("effects", g["scene"], "sun_per_cell", None, "sun_spread_deg") if g else None
        if c and s and n and nf and ng and g and gs:
            out.append(f"Effects: earth curvature moves horizons by at most "
                       f"{fmt(c['p95'])} deg p95 ({c['scene']}) and the SVF by {fmt(s['p95'])}; "
                       f"ignoring the meridian convergence ({fmt(ng['mean'])} deg on "
                       f"{n['scene']}) moves horizons by {fmt(n['p95'])} deg p95 and flips "
                       f"{fmt(nf['mean'])} % of shadows under a 5-degree sun; one sun for the "
                       f"scene instead of one per cell changes the daily irradiation by "
                       f"{fmt(g['p95'])} % p95 on {g['scene']} (the sun's spread "
                       f"{fmt(gs['mean'])} deg). The table at the end has each effect on a "
                       "scene where it matters and one where it does not.")
    return out


def write_table_c(d, path):
    """Replaces the generated block of src/core/accuracy_table.c."""
    with open(path) as f:
        text = f.read()
    lines = ["/* BEGIN GENERATED by doc/accuracy.sh: do not edit by hand */",
             "/* clang-format off */",
             "const int ss_accuracy_directions[SS_ACCURACY_N_DIRECTIONS] = {"
             + ", ".join(str(D) for D in d.dirs) + "};", "",
             "const ss_accuracy_row ss_accuracy_rows[] = {"]
    for s in d.natural():
        grid = d.grid.get(s, ("?", 0, 0))[0]
        for q, _ in DEFS:
            rs = [d.get("directions", s, "lines=interpolated", D, q) for D in d.dirs]
            p95 = ", ".join(f"{r['p95']:.3g}" for r in rs)
            ms = ", ".join(f"{ms_per_mcell(r):.4g}" for r in rs)
            for_default = 0 if "DSM" in d.klass[s] else 1
            lines += [f'    {{"{d.klass[s]} ({s}, {grid})",', f"     {DEF_ENUM[q]},",
                      f"     {for_default},", f"     {{{p95}}},", f"     {{{ms}}}}},"]
    lines += ["};", "const int ss_accuracy_n_rows = (int)(sizeof ss_accuracy_rows / "
              "sizeof ss_accuracy_rows[0]);", "/* clang-format on */", "/* END GENERATED */"]
    block = "\n".join(lines)
    new = re.sub(r"/\* BEGIN GENERATED.*?/\* END GENERATED \*/", lambda m: block, text,
                 flags=re.S)
    with open(path, "w") as f:
        f.write(new)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--csv", required=True)
    ap.add_argument("--md", required=True)
    ap.add_argument("--img", required=True)
    ap.add_argument("--command", default="doc/accuracy.sh")
    ap.add_argument("--device", default="?")
    ap.add_argument("--cpu", default="?")
    ap.add_argument("--load", default="?")
    ap.add_argument("--elapsed", default="?")
    ap.add_argument("--timing", default="one run each")
    ap.add_argument("--table")
    a = ap.parse_args()
    d = Data(load(a.csv))
    os.makedirs(a.img, exist_ok=True)
    have_insol = False
    if plt:
        svf_plot(d, os.path.join(a.img, "svf_error_vs_time.png"))
        horizon_plot(d, os.path.join(a.img, "horizon_error_vs_directions.png"))
        have_insol = insolation_plot(d, os.path.join(a.img, "insolation_error_vs_time.png"))
    else:
        print("accuracy_plot.py: matplotlib is absent (apt-get install python3-matplotlib): "
              "no plots")
    if a.table:
        write_table_c(d, a.table)

    md = []
    w = md.append
    w("# Accuracy: what it costs in time\n")
    w(f"Generated by `{a.command}` (then `/usr/bin/python3 doc/accuracy_plot.py`) on "
      f"{datetime.date.today().isoformat()} in {a.elapsed} s. Device: {a.device}; CPU: "
      f"{a.cpu}; load average (1, 5, 15 min) before -> after: {a.load}. Timings are wall "
      f"times of one library call on this machine, kernel build excluded, {a.timing}; other "
      "work on the machine (see the load) slows them. Every number below comes from that run "
      "(`accuracy.csv` beside this file holds the raw rows); do not edit by hand.\n")
    short = in_short(d)
    if short:
        w("## In short\n")
        w("\n".join(f"- {s}" for s in short) + "\n")
    w("## How the error is measured\n")
    w("The reference is independent of the sweep (`tests/reference_march.c`, checked against "
      "closed forms in `tests/test_reference.c`): the DEM is taken as the bilinear surface "
      "between cell centres; from a cell centre a ray runs in the exact azimuth to the grid's "
      "edge, sampled every 1/8 cell and at every crossing of a row or column of centres (where "
      "the surface kinks), plus the limit at the cell itself (the surface's own slope); the "
      "horizon is the largest elevation angle. SVFs integrate those horizons over the "
      "reference azimuths with the formulas of reference/physics.md 2.2 (convention A). At "
      "rows and columns of centres the sweep's samples are exactly the reference's, and the two "
      "agree to 1e-5 degrees (tested); elsewhere the sweep samples the surface only where its "
      "line crosses a row or column, and gives a cell the weighted horizons of two points up "
      "to a cell beside it: that, and the finite number of directions, is the error measured "
      "here.\n")
    w("Cells are drawn at random at least 8 cells inside the grid, among those with terrain "
      "ahead in every azimuth. Horizon errors are over every (cell, reference azimuth) pair, "
      "the sweep's horizons interpolated linearly in azimuth between its directions, as horizon "
      "users (r.sun) do; 'at the swept azimuths' isolates the line sampling. SVF errors are "
      "over cells. mean / p95 (95th percentile) / max of the absolute error.\n")
    body = []
    for s in d.scenes:
        g = d.grid.get(s)
        if g:
            body.append([s, d.klass[s], g[0], g[1], g[2]])
    w(table(["scene", "terrain", "grid swept", "cells sampled", "reference azimuths"], body))
    w("\nShapes (cells of 30 m): `plane30` a 30-degree plane facing south, `vvalley` a "
      "V-valley of 30-degree sides along the columns, `bowl` a hemispherical bowl of radius "
      "0.4 x the grid in a plain. DEMs larger than the grid above are swept on their centre "
      "(the horizons then end at its edge, for the sweep and the reference alike); the cost "
      "table below times the whole DEMs.\n")

    w("## SVF error and time against the number of directions\n")
    w("![SVF error vs time](img/svf_error_vs_time.png)\n")
    for q, title in DEFS:
        w(f"**{title}**: SVF error p95 (and wall time, ms per Mcell), interpolated lines\n")
        body = []
        for s in d.scenes:
            cells = []
            for D in d.dirs:
                r = d.get("directions", s, "lines=interpolated", D, q)
                cells.append(f"{fmt(r['p95'], 2)} ({fmt(ms_per_mcell(r), 2)})" if r else "–")
            body.append([s] + cells)
        w(table(["scene"] + [f"D={D}" for D in d.dirs], body) + "\n")

    w("### Which number of directions meets 0.01 and 0.005\n")
    w("The smallest D whose SVF p95 error, taken as the larger of its own and the next "
      "larger D's (so that a dip at one D, such as D = 8 whose lines all run through cell "
      "centres, is not trusted), meets the target, and what that costs; 'not met' gives the "
      "floor (the smallest p95 measured at any D, and where).\n")
    body = []
    for s in d.scenes:
        for q, _ in DEFS:
            rs = [d.get("directions", s, "lines=interpolated", D, q) for D in d.dirs]
            errs = [r["p95"] if r else None for r in rs]
            row = [s, q.replace("svf_", "")]
            for t in TARGETS:
                i = smallest_meeting(errs, t)
                if i is None:
                    e, k = min((e, k) for k, e in enumerate(errs) if e is not None)
                    row.append(f"not met (floor {fmt(e, 2)}, at D={d.dirs[k]})")
                else:
                    row.append(f"D={d.dirs[i]}: {fmt(ms_per_mcell(rs[i]), 3)} ms/Mcell")
            body.append(row)
    w(table(["scene", "definition"] + [f"SVF within {t}" for t in TARGETS], body) + "\n")

    if d.dirs and any(r["quantity"].endswith(f"_vs_D{d.dirs[-1]}") for r in d.rows):
        dmax = d.dirs[-1]
        w(f"### The part the directions control\n")
        w(f"The SVF error against the sweep's own SVF at D = {dmax} (same cells, same lines): "
          "what adding directions changes, without the line sampling's floor. p95 over cells; "
          "physics.md 6.2 expects O(D^-2) for the geometric definition (kinks where h+ is "
          "clipped) and much faster convergence for the radiative ones.\n")
        for q, title in DEFS:
            body = []
            for s in d.scenes:
                rs = [d.get("directions", s, "lines=interpolated", D, f"{q}_vs_D{dmax}")
                      for D in d.dirs[:-1]]
                body.append([s] + [fmt(r["p95"], 2) if r else "–" for r in rs])
            w(f"**{title}**\n")
            w(table(["scene"] + [f"D={D}" for D in d.dirs[:-1]], body) + "\n")

    w("## Horizon error\n")
    w("![horizon error vs directions](img/horizon_error_vs_directions.png)\n")
    n_ref = max((v[2] for v in d.grid.values()), default=0)
    w(f"Degrees, mean / p95 / max; interpolated lines. 'any' = at the {n_ref} reference "
      "azimuths with the sweep interpolated between its directions; 'swept' = at its own "
      "azimuths.\n")
    body = []
    for s in d.scenes:
        for D in d.dirs:
            r1 = d.get("directions", s, "lines=interpolated", D, "horizon_deg")
            r2 = d.get("directions", s, "lines=interpolated", D, "horizon_at_swept_deg")
            if r1 and r2:
                body.append([s, D, f"{fmt(r1['mean'])} / {fmt(r1['p95'])} / {fmt(r1['max'])}",
                             f"{fmt(r2['mean'])} / {fmt(r2['p95'])} / {fmt(r2['max'])}",
                             fmt(ms_per_mcell(r1))])
    w(table(["scene", "D", "any azimuth", "swept azimuths", "ms/Mcell"], body) + "\n")

    if d.ddirs:
        w("## Sampling along lines: interpolated against digital\n")
        w("`--lines interpolated` (default) samples exact lines and interpolates across them; "
          "`--lines digital` takes the cell nearest the line (doc/model.md). Horizon error at "
          "the swept azimuths (mean / p95, degrees), geometric and tilted SVF p95, and the "
          "geometric SVF's time (ms/Mcell).\n")
        body = []
        for s in d.scenes:
            for D in d.ddirs:
                row = [s, D]
                for lines in ("lines=interpolated", "lines=digital"):
                    h = d.get("directions", s, lines, D, "horizon_at_swept_deg")
                    g = d.get("directions", s, lines, D, "svf_geometric")
                    t = d.get("directions", s, lines, D, "svf_tilted")
                    row.append(f"{fmt(h['mean'])} / {fmt(h['p95'])}; {fmt(g['p95'], 2)}; "
                               f"{fmt(t['p95'], 2)}; {fmt(ms_per_mcell(g), 3)}"
                               if h and g and t else "–")
                body.append(row)
        w(table(["scene", "D", "interpolated: horizon; SVF geom.; SVF tilted; ms/Mcell",
                 "digital: same"], body) + "\n")

    cost = [r for r in d.rows if r["study"] == "cost"]
    if cost:
        w("## Cost on whole DEMs\n")
        w("Wall time of one call on the whole DEM, ms per Mcell, and the sweep rate in "
          "M cell-directions per second.\n")
        body = []
        for s in d.natural():
            for lines in ("lines=interpolated", "lines=digital"):
                rs = {r["quantity"]: r for r in cost if r["scene"] == s and r["setting"] == lines}
                if not rs:
                    continue
                any_r = next(iter(rs.values()))
                D = int(any_r["value"])
                row = [s, lines.split("=")[1], any_r["cells"], D]
                for q in ("horizon_deg", "svf_geometric", "svf_horizontal", "svf_tilted"):
                    r = rs.get(q)
                    row.append(f"{fmt(ms_per_mcell(r), 3)} ({fmt(r['cells'] * D / 1e6 / r['seconds'], 3)})"
                               if r else "–")
                body.append(row)
        w(table(["scene", "lines", "cells", "D", "horizon", "SVF geometric", "SVF horizontal",
                 "SVF tilted"], body) + "\n")

    ins = [r for r in d.rows if r["study"] == "insolation"]
    if ins:
        ref = [r for r in ins if r["setting"].startswith("reference")][0]
        w("## Insolation: time step and shadow mode\n")
        if have_insol:
            w("![insolation error vs time](img/insolation_error_vs_time.png)\n")
        w(f"Scene {ref['scene']} (the {ref['cells']}-cell centre of the DEM), one day (21 December: low sun, long shadows), clear sky, "
          f"per-cell sun, {int(ref['value'])}-minute steps with exact shadows as the reference "
          f"({fmt(ref['seconds'])} s). Errors of the daily global irradiation in % of the "
          "reference per cell (mean / p95 / max) and of the hours of direct sun. Interpolated "
          "shadows store D horizon directions (which also set the sky view); their step is "
          "the middle one.\n")
        body = []
        for r in ins:
            if r["quantity"] != "global_pct" or r["setting"].startswith("reference"):
                continue
            h = d.get("insolation", r["scene"], r["setting"], r["value"], "sun_hours_h")
            body.append([r["setting"], int(r["value"]),
                         f"{fmt(r['mean'])} / {fmt(r['p95'])} / {fmt(r['max'])}",
                         f"{fmt(h['mean'])} / {fmt(h['p95'])}" if h else "–",
                         fmt(r["seconds"]), fmt(ms_per_mcell(r) / 1000)])
        w(table(["setting", "step (min) or D", "global error % mean / p95 / max",
                 "sun hours error (h) mean / p95", "time (s)", "s per Mcell"], body) + "\n")
        w("For a year of weather records, the cumulative sky (`--shadow cumulative`) replaces "
          "the shadow sweeps by the directions' stored horizons; its error against the exact "
          "hourly run and its time, per resolution, are in `doc/cumulative_sky.md` "
          "(`doc/cumulative_sky.sh`).\n\n")

    eff = [r for r in d.rows if r["study"] == "effects"]
    if eff:
        w("## Physical effects: on against off\n")
        w("What switching an effect off changes, over every cell (and direction, for "
          "horizons) at least 8 cells inside the grid: curvature = earth curvature with "
          "refraction k = 0.13 against a flat earth; refraction = k = 0.13 against k = 0 "
          "(curvature on); north = the horizon of a true azimuth read at the grid azimuth "
          "(meridian convergence ignored), and whether a sun 5 degrees high is above it, on the "
          "continuous reference at sampled cells (turning the sweep's lines by a fraction of a "
          "degree would move its samples and measure the line model's noise instead); sun per "
          "cell = the sun's position per cell against one sun for the scene (shadows of a sun "
          "5 degrees high on 21 December, and that day's irradiation at 15-minute steps, "
          "D = 16). "
          "Horizons in degrees, SVF in its units, irradiation in %, shadows in % of cells that "
          "change.\n")
        body = []
        names = {"horizon_deg": "horizon (deg)", "svf_geometric": "geometric SVF",
                 "shadow_flips_pct": "shadow flips (% of cells)",
                 "global_pct": "daily global irradiation (%)",
                 "sun_spread_deg": "the sun's spread over the scene (deg)",
                 "convergence_deg": "meridian convergence at the centre (deg)"}
        for r in eff:
            if r["quantity"] == "seconds_only":
                continue
            single = r["quantity"] in ("shadow_flips_pct", "sun_spread_deg", "convergence_deg")
            vals = (fmt(r["mean"]) if single else
                    f"{fmt(r['mean'])} / {fmt(r['p95'])} / {fmt(r['max'])}")
            how = ""
            if r["setting"] == "north" and r["quantity"] in ("horizon_deg", "shadow_flips_pct"):
                how = f"reference, {int(r['value'])} azimuths"
            elif r["quantity"] in ("horizon_deg", "svf_geometric"):
                how = f"sweep, D={int(r['value'])}"
            off = d.get("effects", r["scene"], r["setting"] + "=off", None, "seconds_only")
            t = fmt(r["seconds"]) if r["seconds"] > 0 else ""
            if off and r["quantity"] == "global_pct":
                t += f" (off: {fmt(off['seconds'])})"
            body.append([r["setting"], r["scene"], names.get(r["quantity"], r["quantity"]),
                         vals, how, t])
        w(table(["effect", "scene", "what changes", "mean / p95 / max", "measured by",
                 "time (s)"], body) + "\n")

    if d.dirs and d.natural():
        worst = worst_table(d)
        w("## The default number of directions and `--tolerance`\n")
        dsm = [s for s in d.natural() if s not in d.default_scenes()]
        floors = []
        for s in dsm:
            for q, _ in DEFS:
                errs = [d.get("directions", s, "lines=interpolated", D, q) for D in d.dirs]
                floors.append(f"{q.replace('svf_', '')} {fmt(min(r['p95'] for r in errs if r), 2)}")
        w("`ss_directions_for_tolerance()` (src/core/accuracy_table.c) reads this table: the "
          "worst SVF p95 error over the measured terrain models (" +
          ", ".join(d.default_scenes()) + "), interpolated lines. It returns the smallest "
          "tabulated D whose error (the larger of its own and the next D's) meets the "
          "tolerance, or, when none does, the cheapest D within 5 % of the smallest error (the "
          "floor), whose error is then above the tolerance. " +
          (("The surface model (" + ", ".join(dsm) + ") is tabulated too but left out of "
            "this choice: next to vertical walls a one-metre DSM is sampled too coarsely for "
            "any number of directions to bring its p95 below " + ", ".join(floors) +
            ", and a tolerance below that is no guide for terrain.") if dsm else "") + "\n")
        body = [[q.replace("svf_", "")] + [fmt(e, 2) for e in worst[q]] for q, _ in DEFS]
        w(table(["definition"] + [f"D={D}" for D in d.dirs], body) + "\n")
        body = []
        for tol in (0.05, 0.02, 0.01, 0.005, 0.002):
            row = [tol]
            for q, _ in DEFS:
                i, e, met = choose(worst[q], tol)
                row.append(f"D={d.dirs[i]} ({fmt(e, 2)}{'' if met else ', not met'})")
            body.append(row)
        w(table(["tolerance"] + [q.replace("svf_", "") for q, _ in DEFS], body) + "\n")
        i_def, rob = default_directions(d)
        def_d = d.dirs[i_def] if i_def is not None else None
        if def_d is not None:
            i = d.dirs.index(def_d)
            w(f"**Default.** The smallest D at which every definition's worst-case error (as "
              f"taken above) is within 10 % (or 0.0005) of the best it reaches at any tabulated "
              f"D is **D = {def_d}** (worst p95: " +
              ", ".join(f"{q.replace('svf_', '')} {fmt(rob[q][i], 2)}" for q, _ in DEFS) +
              "). More directions cost time in proportion and no longer lower the error: what "
              "remains is the line sampling's own error (the floor above).\n")
    with open(a.md, "w") as f:
        f.write("\n".join(md))


if __name__ == "__main__":
    main()
