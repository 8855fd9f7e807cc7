#!/usr/bin/env python3
"""Figures of a tethash study: reads DIR/study.csv and DIR/study.json, writes PNG and SVG into DIR
(or --out FOLDER), and report.html, one page with the figures, the table, the command and the machine. Which
figures depend on the sweep and on the columns that vary.

usage: plot_study.py DIR [--out FOLDER] [--formats png,svg] [--prefix NAME] [--no-report]
"""
import argparse
import csv
import json
import html
import math
import os
import re
import statistics
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

plt.rcParams.update({"svg.fonttype": "none", "font.size": 9, "axes.grid": True, "grid.alpha": 0.3,
                     "svg.hashsalt": "tethash"})

STAGES = [("ms_total", "total"), ("ms_vertices", "stage 1: hash vertices"),
          ("ms_tets", "stage 2: hash tet boxes"), ("ms_inside", "stage 3: inside tests"),
          ("ms_sort", "sort/merge")]


def num(v):
    try:
        return float(v)
    except (TypeError, ValueError):
        return float("nan")


def load(folder):
    with open(os.path.join(folder, "study.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    meta = {}
    jp = os.path.join(folder, "study.json")
    if os.path.exists(jp):
        with open(jp) as f:
            meta = json.load(f)
    return rows, meta


def points(rows):
    """One dict per point: deterministic columns from the first repeat, timing columns as medians."""
    groups = {}
    for r in rows:
        groups.setdefault(int(r["point"]), []).append(r)
    out = []
    for p in sorted(groups):
        g = groups[p]
        d = dict(g[0])
        for k in g[0]:
            if k.startswith("ms_") or "wall" in k:
                vals = [num(r[k]) for r in g if r[k] != ""]
                d[k] = statistics.median(vals) if vals else float("nan")
                d[k + "_min"] = min(vals) if vals else float("nan")
                d[k + "_max"] = max(vals) if vals else float("nan")
        out.append(d)
    return out


def machine_text(meta):
    m = meta.get("machine")
    if m is None and meta.get("shards"):
        m = meta["shards"][0].get("machine")
    if not m:
        return "machine: unknown"
    return "machine: %s, %s cores, %s" % (m.get("cpu", "?"), m.get("cores", "?"), m.get("compiler", "?"))


ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def portable_path(token):
    """An absolute path as a reader elsewhere can use it: relative to the repository when inside it, else its last
    component (the folders of the machine that ran the study say nothing to a reader)."""
    if not token.startswith("/"):
        return token
    real = os.path.normpath(token)
    if real == ROOT or real.startswith(ROOT + os.sep):
        return os.path.relpath(real, ROOT)
    return os.path.basename(real) or token


def command_text(meta):
    c = meta.get("command")
    if meta.get("shards"):
        c = meta["shards"][0].get("command", c)
    if not c:
        return "?"
    # Every absolute path in it, also inside a token (a.vtu+b.vtu, --out=DIR, lists).
    return re.sub(r"(?<![\w.~-])/[^\s'\"+,=:;]+", lambda m: portable_path(m.group(0)), c)


FIGURES = []  # (name, files written), in order, for the report


def finish(fig, meta, scene, name, args):
    footer = "scene: %s | %s\ncommand: %s" % (scene, machine_text(meta), command_text(meta))
    fig.text(0.01, 0.005, footer, fontsize=6.5, va="bottom", ha="left", wrap=True, color="0.3")
    # Room for the footer's two lines (about 0.45 inch) and, on tall figures, for the title above the panels.
    height = fig.get_size_inches()[1]
    fig.tight_layout(rect=(0, min(0.07, 0.45 / height), 1, 1 if height < 8 else 1 - 0.25 / height))
    written = []
    for ext in args.formats:
        path = os.path.join(args.out, "%s%s.%s" % (args.prefix, name, ext))
        fig.savefig(path, dpi=120)
        written.append(path)
    plt.close(fig)
    FIGURES.append((name, written))
    for p in written:
        print("figure:", p)


def spans_decades(values, ratio=20):
    v = [x for x in values if x > 0 and math.isfinite(x)]
    return len(v) > 1 and max(v) / min(v) > ratio


def plain_ticks(ax, axis="x"):
    """Log axis with plain numbers (0.25, 0.5, 1, 2) instead of powers of ten."""
    from matplotlib.ticker import FuncFormatter, LogLocator
    fmt = FuncFormatter(lambda v, _: "%g" % v)
    a = ax.xaxis if axis == "x" else ax.yaxis
    a.set_major_locator(LogLocator(base=2))
    a.set_major_formatter(fmt)
    a.set_minor_formatter(FuncFormatter(lambda v, _: ""))


def log_axis(ax, axis="x"):
    """A log axis labelled at 1, 2 and 5 times the powers of ten, as plain numbers, without minor labels: the
    default labels every minor tick on a narrow range, and they overlap."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter
    a = ax.xaxis if axis == "x" else ax.yaxis
    (ax.set_xscale if axis == "x" else ax.set_yscale)("log")
    lo, hi = ax.get_xlim() if axis == "x" else ax.get_ylim()
    decades = math.log10(hi / lo) if lo > 0 and hi > lo else 1
    # 1, 2, 5 per decade on a narrow range; every decade, or every few, on a wide one.
    subs = (1.0, 2.0, 5.0) if decades <= 2.5 else (1.0,)
    a.set_major_locator(LogLocator(base=10, subs=subs, numticks=12 if decades <= 2.5 else 8))
    a.set_major_formatter(FuncFormatter(lambda v, _: "%g" % v))
    a.set_minor_formatter(NullFormatter())


def positive(values):
    """Zeros and negatives as NaN, so that log axes leave a gap instead of a line to the bottom."""
    return [v if v > 0 else float("nan") for v in values]


def set_scales(ax, xs, ys):
    if spans_decades(xs, 7):
        ax.set_xscale("log")
        plain_ticks(ax)
    if spans_decades(ys):
        ax.set_yscale("log")


def by(pts, key):
    out = {}
    for p in pts:
        out.setdefault(p[key], []).append(p)
    return out


def table_label(p):
    if p["table_kind"] == "auto":
        return "table auto (%s)" % p["table_size"]
    return "table %s (%s)" % (p["table_size"], p["table_kind"])


def series_key(p, keys):
    return tuple(p[k] for k in keys)


def plot_detection(pts, meta, args, sweep):
    pts = [p for p in pts if not p.get("error")]  # a method that could not run has no statistics
    scenes = by(pts, "scene")
    for scene, sp in scenes.items():
        tag = "" if len(scenes) == 1 else "_" + scene
        cells = sorted({num(p["cell_factor"]) for p in sp})
        tables = sorted({int(p["table_size"]) for p in sp})
        hashes = sorted({p["hash"] for p in sp})
        threads = sorted({int(p["threads"]) for p in sp})
        other = lambda p, skip: ", ".join(  # noqa: E731
            s for k, s in (("table", table_label(p)), ("hash", "hash " + p["hash"]), ("threads", p["threads"] + " thr"))
            if k not in skip and {"table": len(tables), "hash": len(hashes), "threads": len(threads)}[k] > 1)

        if len(cells) > 1:
            # Teschner's figure: time per stage against cell size, one curve per table size.
            fig, axes = plt.subplots(1, len(STAGES), figsize=(3.0 * len(STAGES), 3.4), sharex=True)
            groups = {}
            order = {}
            for p in sp:
                groups.setdefault(other(p, ()), []).append(p)
                order[other(p, ())] = (int(p["table_size"]), p["table_kind"], p["hash"], int(p["threads"]))
            for ax, (col, title) in zip(axes, STAGES):
                allx, ally = [], []
                for label, g in sorted(groups.items(), key=lambda kv: order[kv[0]]):
                    g = sorted(g, key=lambda p: num(p["cell_factor"]))
                    x = [num(p["cell_factor"]) for p in g]
                    y = [num(p[col]) for p in g]
                    ax.plot(x, y, marker="o", ms=3, label=label or "median")
                    allx += x
                    ally += y
                ax.set_title(title)
                ax.set_xlabel("cell size / mean edge length")
                ax.set_ylabel("time (ms, median)")
                set_scales(ax, allx, ally)
            axes[0].legend(fontsize=6)
            fig.suptitle("Detection time per stage vs cell size (%s)" % scene)
            finish(fig, meta, scene, "stages_vs_cell" + tag, args)

            # Candidates and contacts against cell size.
            fig, ax = plt.subplots(figsize=(6, 4))
            g0 = sorted(min(groups.items(), key=lambda kv: order[kv[0]])[1], key=lambda p: num(p["cell_factor"]))
            x = [num(p["cell_factor"]) for p in g0]
            ys = []
            for col, lab in (("cells_visited", "cells visited"), ("entries_scanned", "bucket entries scanned"),
                             ("hash_collisions", "entries from other cells (collisions)"),
                             ("inside_tests", "inside tests (candidates)"), ("contacts", "contacts"),
                             ("oracle_contacts", "oracle contacts")):
                y = positive([num(p[col]) for p in g0])
                if all(math.isnan(v) for v in y):
                    continue
                ax.plot(x, y, marker="o", ms=3, label=lab, ls="--" if col == "oracle_contacts" else "-")
                ys += y
            ax.set_xlabel("cell size / mean edge length")
            ax.set_ylabel("count per detection")
            ax.set_xscale("log")
            plain_ticks(ax)
            if spans_decades(ys):
                ax.set_yscale("log")
            ax.legend(fontsize=7)
            ax.set_title("Candidates and contacts vs cell size (%s%s)" % (scene, (", " + other(g0[0], ())) if other(g0[0], ()) else ""))
            finish(fig, meta, scene, "candidates_vs_cell" + tag, args)

        # Exactness: missed and extra against the swept parameter (zero line).
        xcol, xlab = ("cell_factor", "cell size / mean edge length") if len(cells) > 1 else \
            ("table_size", "table size (buckets)") if len(tables) > 1 else \
            ("threads", "threads") if len(threads) > 1 else ("point", "point")
        if any(p["missed"] != "" for p in sp):
            fig, ax = plt.subplots(figsize=(6, 3.2))
            x = [num(p[xcol]) for p in sp]
            ax.axhline(0, color="k", lw=0.8)
            ax.plot(x, [num(p["missed"]) for p in sp], "o", ms=4, label="missed (oracle contacts not found)")
            ax.plot(x, [num(p["extra"]) for p in sp], "x", ms=5, label="extra (found, not in oracle)")
            ax.set_xlabel(xlab)
            ax.set_ylabel("contacts")
            # The x axis of the sweep's other figures: cell sizes on a log axis in plain numbers (as the stages and
            # candidates), table sizes on a log axis (as the table figure), threads and points linear.
            if xcol == "cell_factor" and len(set(x)) > 1:
                ax.set_xscale("log")
                plain_ticks(ax)
            elif xcol == "table_size" and len(set(x)) > 1:
                log_axis(ax)
            ax.legend(fontsize=7)
            ax.set_title("Exactness vs the brute-force oracle, every point (%s)" % scene)
            finish(fig, meta, scene, "exactness" + tag, args)

        if len(tables) > 1:
            fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
            ax = axes[0]
            groups = {}
            for p in sp:
                if p["table_kind"] == "auto":
                    continue
                groups.setdefault((p["table_kind"], p["cell_factor"], p["hash"], p["threads"]), []).append(p)
            allx, ally = [], []
            for (kind, cf, h, th), g in sorted(groups.items()):
                g = sorted(g, key=lambda p: int(p["table_size"]))
                x = [int(p["table_size"]) for p in g]
                y = [num(p["ms_total"]) for p in g]
                ax.plot(x, y, marker="o", ms=3, label="%s, cell %.3g×, %s, %s thr" % (kind, num(cf), h, th))
                allx += x
                ally += y
            nv = int(sp[0]["vertices"])
            ax.axvline(nv, color="0.5", ls=":", lw=1)
            ax.text(nv, ax.get_ylim()[1] if ally else 1, " vertices", fontsize=7, va="top", color="0.4")
            ax.set_xscale("log")
            if spans_decades(ally):
                ax.set_yscale("log")
            ax.set_xlabel("table size (buckets)")
            ax.set_ylabel("detection time (ms, median)")
            ax.set_title("Time vs table size")
            ax.legend(fontsize=6)
            ax = axes[1]
            for (kind, cf, h, th), g in sorted(groups.items()):
                g = sorted(g, key=lambda p: num(p["table_load"]))
                ax.plot([num(p["table_load"]) for p in g], [num(p["collision_rate"]) for p in g], marker="o", ms=3,
                        label="%s, cell %.3g×, %s" % (kind, num(cf), h))
            ax.set_xscale("log")
            ax.set_xlabel("table load (vertices / buckets)")
            ax.set_ylabel("hash collisions / entries scanned")
            ax.set_title("Hash-collision rate vs table load")
            ax.legend(fontsize=6)
            fig.suptitle("Table size (%s)" % scene)
            finish(fig, meta, scene, "table_size" + tag, args)

        if len(hashes) > 1 and len(cells) == 1 and len(tables) <= 2:
            fig, ax = plt.subplots(figsize=(5, 3.5))
            labels = [p["hash"] + "\n" + (table_label(p) if len(tables) > 1 else "") for p in sp]
            y = [num(p["ms_total"]) for p in sp]
            lo = [num(p["ms_total"]) - num(p["ms_total_min"]) for p in sp]
            hi = [num(p["ms_total_max"]) - num(p["ms_total"]) for p in sp]
            ax.bar(range(len(sp)), y, yerr=[lo, hi], capsize=3)
            ax.set_xticks(range(len(sp)), labels, fontsize=7)
            ax.set_ylabel("detection time (ms, median, bars: min-max)")
            ax.set_title("Hash functions (%s)" % scene)
            finish(fig, meta, scene, "hash" + tag, args)

        if len(threads) > 1:
            fig, axes = plt.subplots(1, 2, figsize=(9, 3.5))
            groups = {}
            for p in sp:
                groups.setdefault(other(p, ("threads",)), []).append(p)
            for label, g in sorted(groups.items()):
                g = sorted(g, key=lambda p: int(p["threads"]))
                x = [int(p["threads"]) for p in g]
                y = [num(p["ms_total"]) for p in g]
                axes[0].plot(x, y, marker="o", label=label or "median")
                axes[1].plot(x, [y[0] / v for v in y], marker="o", label=label or "speed-up")
            axes[1].plot(threads, threads, "k:", lw=0.8, label="ideal")
            axes[0].set_xlabel("threads")
            axes[0].set_ylabel("detection time (ms, median)")
            axes[1].set_xlabel("threads")
            axes[1].set_ylabel("speed-up over 1 thread")
            axes[1].legend(fontsize=7)
            fig.suptitle("Threads (%s)" % scene)
            finish(fig, meta, scene, "threads" + tag, args)

        # Grid: a heat map of the median time over the two parameters that vary.
        varying = [(k, v) for k, v in (("cell_factor", cells), ("table_size", tables), ("hash", hashes),
                                       ("threads", threads)) if len(v) > 1]
        if sweep == "grid" and len(varying) == 2:
            (kx, vx), (ky, vy) = varying
            import numpy as np
            z = np.full((len(vy), len(vx)), np.nan)
            for p in sp:
                xv = num(p[kx]) if kx != "hash" else p[kx]
                yv = num(p[ky]) if ky != "hash" else p[ky]
                xi = [num(v) if kx != "hash" else v for v in vx].index(xv)
                yi = [num(v) if ky != "hash" else v for v in vy].index(yv)
                z[yi, xi] = num(p["ms_total"])
            fig, ax = plt.subplots(figsize=(6, 4))
            im = ax.imshow(z, origin="lower", aspect="auto", cmap="viridis")
            ax.set_xticks(range(len(vx)), ["%g" % v if kx != "hash" else v for v in vx], fontsize=7, rotation=45)
            ax.set_yticks(range(len(vy)), ["%g" % v if ky != "hash" else v for v in vy], fontsize=7)
            ax.set_xlabel(kx.replace("_", " "))
            ax.set_ylabel(ky.replace("_", " "))
            fig.colorbar(im, ax=ax, label="detection time (ms, median)")
            ax.set_title("Grid: %s × %s (%s)" % (kx, ky, scene))
            finish(fig, meta, scene, "grid" + tag, args)

        # Penetration depth error against detection time.
        if any(p.get("depth_err_rms", "") != "" for p in sp):
            fig, ax = plt.subplots(figsize=(6, 3.8))
            x = [num(p["ms_total"]) for p in sp if p["depth_err_rms"] != ""]
            ax.plot(x, [num(p["depth_err_rms"]) for p in sp if p["depth_err_rms"] != ""], "o", label="RMS")
            ax.plot(x, [num(p["depth_err_max"]) for p in sp if p["depth_err_rms"] != ""], "^", label="max")
            ax.set_xlabel("detection time (ms, median)")
            ax.set_ylabel("|depth − exact distance| (length units)")
            ax.set_title("Penetration-depth error (Heidelberger 2004) vs detection time (%s)" % scene, fontsize=8)
            ax.legend(fontsize=7)
            finish(fig, meta, scene, "depth_error" + tag, args)


def plot_stability(pts, meta, args):
    """One panel per integrator: young (rows) × dt and mass ratio (columns), each cell coloured by its verdict."""
    colours = {"ok": "#4caf50", "stopped": "#ff9800", "crumpled": "#d32f2f"}
    for scene in sorted({p["scene"] for p in pts}):
        sp = [p for p in pts if p["scene"] == scene]
        integs = sorted({p["integrator"] for p in sp})
        youngs = sorted({num(p["young"]) for p in sp})
        cols = sorted({(num(p["dt"]), num(p["mass_ratio"])) for p in sp})
        fig, axes = plt.subplots(1, len(integs), figsize=(4.5 * len(integs), 0.5 * len(youngs) + 2.2), squeeze=False)
        for ax, integ in zip(axes[0], integs):
            for p in sp:
                if p["integrator"] != integ:
                    continue
                x = cols.index((num(p["dt"]), num(p["mass_ratio"])))
                y = youngs.index(num(p["young"]))
                ax.add_patch(plt.Rectangle((x, y), 1, 1, color=colours.get(p["verdict"], "#9e9e9e")))
                ax.text(x + 0.5, y + 0.5, p["verdict"][:4], ha="center", va="center", fontsize=6)
            ax.set_xlim(0, len(cols))
            ax.set_ylim(0, len(youngs))
            ax.set_xticks([i + 0.5 for i in range(len(cols))])
            ax.set_xticklabels(["dt %.3g\nratio %g" % c for c in cols], fontsize=5)
            ax.set_yticks([i + 0.5 for i in range(len(youngs))])
            ax.set_yticklabels(["%g" % y for y in youngs], fontsize=6)
            ax.set_ylabel("young (Pa)")
            ax.set_title("%s: %s" % (scene, integ), fontsize=8)
        finish(fig, meta, scene, "stability", args)


def plot_integrator(pts, meta, args):
    scene = pts[0]["scene"] if pts else "?"
    ok = [p for p in pts if p["status"] == "ok" and p["err_rms"] != ""]
    fig, axes = plt.subplots(1, 3, figsize=(13, 4))
    groups = {}
    for p in ok:
        groups.setdefault((p["integrator"], p["substeps"]), []).append(p)
    markers = "osD^v<>"
    for i, ((integ, sub), g) in enumerate(sorted(groups.items())):
        g = sorted(g, key=lambda p: num(p["wall_s_per_sim_s"]))
        x = [num(p["wall_s_per_sim_s"]) for p in g]
        lab = integ + ("" if sub == "1" else " ×%s substeps" % sub)
        line = axes[0].plot(x, [num(p["err_rms"]) for p in g], marker=markers[i % 7], label=lab + " (RMS)")[0]
        axes[0].plot(x, [num(p["err_max"]) for p in g], marker=markers[i % 7], ls="--", color=line.get_color(),
                     alpha=0.6, label=lab + " (max)")
        for p in g:
            axes[0].annotate("dt=%g" % num(p["dt"]), (num(p["wall_s_per_sim_s"]), num(p["err_rms"])), fontsize=5,
                             xytext=(2, 2), textcoords="offset points")
        axes[1].plot(x, [num(p["max_penetration"]) for p in g], marker=markers[i % 7], color=line.get_color(), label=lab)
        axes[2].plot(x, [abs(num(p["energy_drift"])) for p in g], marker=markers[i % 7], color=line.get_color(), label=lab)
    if ok:
        axes[1].axhline(num(ok[0]["ref_max_penetration"]), color="k", ls=":", lw=0.8, label="reference")
        axes[2].axhline(abs(num(ok[0]["ref_energy_drift"])), color="k", ls=":", lw=0.8, label="reference")
    for ax in axes:
        log_axis(ax)
        ax.set_xlabel("wall time per simulated second (s/s)")
    log_axis(axes[0], "y")
    axes[0].set_ylabel("vertex position error (length units)")
    axes[0].set_title("Work-precision: error vs reference run")
    axes[1].set_ylabel("final max penetration depth (length units)")
    axes[1].set_title("Penetration at the end")
    log_axis(axes[2], "y")
    axes[2].set_ylabel("|E(T) − E(0)| (energy units)")
    axes[2].set_title("Energy drift")
    axes[0].legend(fontsize=6)
    axes[1].legend(fontsize=6)
    failed = [p for p in pts if p["status"] != "ok"]
    if failed:
        fig.text(0.5, 0.09, "diverged (not plotted): " + ", ".join("%s dt=%s" % (p["integrator"], p["dt"]) for p in failed),
                 ha="center", fontsize=6, color="darkred")
    ref = ok[0] if ok else None
    fig.suptitle("Work-precision diagrams (%s; reference: %s, dt = %s s)" %
                 (scene, ref["ref_integrator"] if ref else "?", ref["ref_dt"] if ref else "?"))
    finish(fig, meta, scene, "work_precision", args)


def method_label(p):
    """The method and the partition parameters it was given ("octree depth 8")."""
    parts = [p["method"]]
    for col, short in (("max_depth", "depth"), ("leaf_size", "leaf"), ("looseness", "loose"), ("levels", "levels")):
        v = p.get(col, "")
        if v not in ("", "default"):
            parts.append("%s %s" % (short, v))
    return " ".join(parts)


def plot_methods(pts, meta, args):
    """The method sweep as three tables in colour, one row per method (and parameters), one column per scene: the
    median time per detection, the pairs the exact test checked and the working memory, each cell coloured by its
    ratio to the best method of its scene (log scale) and labelled with its value. Methods that could not run are
    left out (their error is in the CSV). Its size does not grow with the methods and scenes beyond what the labels
    need: a bar chart of 15 methods on 9 scenes was 3,333 pixels wide with a legend nobody could match to bars."""
    ran = [p for p in pts if not p.get("error")]
    if not ran:
        print("figures: no method ran (see the error column)")
        return
    import numpy as np
    from matplotlib.colors import LogNorm
    scenes = list(dict.fromkeys(p["scene"] for p in ran))
    labels = list(dict.fromkeys(method_label(p) for p in ran))
    def short(v):
        """At most 4 or 5 characters: 0.237, 14.6, 1460, 45k, 1.5M."""
        if v >= 1e6:
            return "%.3gM" % (v / 1e6)
        if v >= 1e4:
            return "%.3gk" % (v / 1e3)
        return "%.0f" % v if v >= 100 else "%.3g" % v

    panels = (("ms_total", "time per detection (ms, median)"), ("inside_tests", "pairs tested (inside tests)"),
              ("memory_bytes", "working memory (MB)"))
    # One panel under the other, a column of 0.8 inch per scene (room for five characters in bold).
    width = min(13.0, 2.4 + 0.8 * len(scenes))
    height = min(18.0, 1.2 + len(panels) * (0.9 + 0.22 * len(labels)))
    fig, axes = plt.subplots(len(panels), 1, figsize=(width, height), sharex=True, squeeze=False)
    for ax, (col, title) in zip(axes[:, 0], panels):
        z = np.full((len(labels), len(scenes)), np.nan)
        for p in ran:
            v = num(p[col])
            if col == "memory_bytes":
                v /= 1e6
            z[labels.index(method_label(p)), scenes.index(p["scene"])] = v
        best = np.nanmin(np.where(z > 0, z, np.nan), axis=0)
        ratio = z / best
        ratio[~(ratio > 0)] = np.nan
        top = np.nanmax(ratio) if np.isfinite(ratio).any() else 2
        ax.imshow(ratio, aspect="auto", cmap="RdYlGn_r", norm=LogNorm(vmin=1, vmax=max(2.0, top)))
        for r in range(len(labels)):
            for c in range(len(scenes)):
                if np.isfinite(z[r, c]):
                    ax.text(c, r, short(z[r, c]), ha="center", va="center", fontsize=6.5,
                            fontweight="bold" if ratio[r, c] <= 1.0 else "normal")
        ax.set_xticks(range(len(scenes)))
        ax.set_xticklabels(scenes, rotation=30, ha="right", fontsize=7)
        ax.set_yticks(range(len(labels)))
        ax.set_yticklabels(labels, fontsize=7)
        ax.set_title(title + "; colour: ratio to the best of the scene (bold)", fontsize=8)
        ax.grid(False)
    fig.suptitle("Broad-phase methods side by side (threads %s)" % ",".join(sorted({p["threads"] for p in ran})))
    finish(fig, meta, ", ".join(scenes), "methods", args)


def write_report(rows, meta, args, sweep):
    """report.html beside the figures: one page with the command, the machine, every figure drawn and the table of
    points (medians over the repeats), well-formed (it parses as XML) and with relative links only."""
    e = html.escape
    title = "tethash study: %s" % (sweep or "?")
    out = []
    out.append("<!DOCTYPE html>")
    out.append('<html lang="en"><head><meta charset="utf-8"/><title>%s</title>' % e(title))
    out.append("<style>body{font-family:sans-serif;margin:1.5em;max-width:1200px}img{max-width:100%;"
               "border:1px solid #ddd}figure{margin:1em 0}table{border-collapse:collapse;font-size:12px}"
               "td,th{border:1px solid #ccc;padding:2px 6px;text-align:right}th{background:#eee}"
               "div.table{overflow-x:auto}code{background:#f4f4f4;padding:2px 4px}</style></head><body>")
    out.append("<h1>%s</h1>" % e(title))
    out.append("<p>command: <code>%s</code></p>" % e(command_text(meta)))
    out.append("<p>%s</p>" % e(machine_text(meta)))
    out.append("<h2>Figures</h2>")
    if not FIGURES:
        out.append("<p>none for this sweep (see the table)</p>")
    for name, files in FIGURES:
        pick = [f for f in files if f.endswith(".png")] or [f for f in files if f.endswith(".svg")]
        if not pick:
            continue
        src = os.path.relpath(pick[0], args.out)
        out.append('<figure><img src="%s" alt="%s"/><figcaption>%s</figcaption></figure>' % (e(src), e(name), e(name)))
    cols = list(rows[0].keys())
    pts = points(rows)
    limit = 500
    csv_link = os.path.relpath(os.path.join(args.dir, "study.csv"), args.out)
    out.append("<h2>Table</h2>")
    out.append('<p>%d points (timings: medians over the repeats)%s; every row: <a href="%s">study.csv</a></p>' %
               (len(pts), ", the first %d shown" % limit if len(pts) > limit else "", e(csv_link)))
    out.append('<div class="table"><table><thead><tr>%s</tr></thead><tbody>' %
               "".join("<th>%s</th>" % e(c) for c in cols))
    for p in pts[:limit]:
        cells = []
        for c in cols:
            v = p.get(c, "")
            cells.append("<td>%s</td>" % e("%.4g" % v if isinstance(v, float) else str(v)))
        out.append("<tr>%s</tr>" % "".join(cells))
    out.append("</tbody></table></div></body></html>")
    path = os.path.join(args.out, "%sreport.html" % args.prefix)
    tmp = path + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write("\n".join(out) + "\n")
    os.replace(tmp, path)
    print("report:", path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dir")
    ap.add_argument("--out", default=None)
    ap.add_argument("--formats", default="png,svg")
    ap.add_argument("--prefix", default="")
    ap.add_argument("--no-report", action="store_true", help="figures only, no report.html")
    args = ap.parse_args()
    args.out = args.out or args.dir
    args.formats = [f for f in args.formats.split(",") if f]
    csv_path = os.path.join(args.dir, "study.csv")
    # Bad input (a missing folder, a file that is not a study) is one line and status 2, not a traceback.
    try:
        rows, meta = load(args.dir)
        if not rows:
            print("figures: no rows in %s" % csv_path)
            return 0
        missing = [c for c in ("point", "sweep") if c not in rows[0]]
        if missing:
            raise ValueError("missing column(s) %s: not a tethash study" % ", ".join(missing))
        pts = points(rows)
    except FileNotFoundError:
        print("plot_study.py: error: %s: no such file (give the folder of a tethash study)" % csv_path, file=sys.stderr)
        return 2
    except (OSError, csv.Error, ValueError, KeyError, TypeError) as e:  # json.JSONDecodeError is a ValueError
        print("plot_study.py: error: %s: %s" % (csv_path, e), file=sys.stderr)
        return 2
    try:
        os.makedirs(args.out, exist_ok=True)
        sweep = rows[0].get("sweep", meta.get("sweep", ""))
        if sweep == "integrator":
            plot_integrator(pts, meta, args)
        elif sweep == "stability":
            plot_stability(pts, meta, args)
        elif sweep == "method":
            plot_methods(pts, meta, args)
        else:
            plot_detection(pts, meta, args, sweep)
        if not args.no_report:
            write_report(rows, meta, args, sweep)
    except OSError as e:
        print("plot_study.py: error: cannot write figures to %s: %s" % (args.out, e), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
