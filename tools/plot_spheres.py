#!/usr/bin/env python3
"""Figures of `tethash study spheres`: reads DIR/spheres.csv (and spheres.json), writes into DIR (or --out FOLDER)
spheres_time.{png,svg} (collision time per frame: tree build + sphere-sphere tests) and spheres_tests.{png,svg}
(sphere-sphere tests per frame) against the frame number, one line per method and depth, one panel per depth,
as in the figures of the octree / k-d / BSP comparison.

usage: plot_spheres.py DIR [--out FOLDER] [--formats png,svg] [--smooth FRAMES]
"""
import argparse
import csv
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

plt.rcParams.update({"svg.fonttype": "none", "font.size": 9, "axes.grid": True, "grid.alpha": 0.3,
                     "svg.hashsalt": "tethash"})

STYLE = {"brute": ("black", "-"), "octree": ("tab:blue", "-"), "octree-point": ("tab:blue", "--"),
         "kd": ("tab:orange", "-"), "kd-point": ("tab:orange", "--"), "bsp": ("tab:green", "-"),
         "bsp-balanced": ("tab:green", "--")}


def smooth(values, k):
    """Running median over k frames (timings of single frames are noisy on a shared machine)."""
    if k <= 1:
        return values
    out = []
    for i in range(len(values)):
        w = sorted(values[max(0, i - k // 2):i + k // 2 + 1])
        out.append(w[len(w) // 2])
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("dir")
    ap.add_argument("--out", default=None)
    ap.add_argument("--formats", default="png,svg")
    ap.add_argument("--smooth", type=int, default=9, help="running median of the times over this many frames")
    args = ap.parse_args()
    path = os.path.join(args.dir, "spheres.csv")
    if not os.path.exists(path):
        print(f"plot_spheres: {path}: file not found", file=sys.stderr)
        return 2
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    missing = [c for c in ("method", "depth", "frame", "time_ms", "tests") if rows and c not in rows[0]]
    if not rows or missing:
        print(f"plot_spheres: {path}: no rows or missing columns {missing}", file=sys.stderr)
        return 2
    meta = {}
    jp = os.path.join(args.dir, "spheres.json")
    if os.path.exists(jp):
        with open(jp) as f:
            meta = json.load(f)
    series = {}
    for r in rows:
        s = series.setdefault((r["method"], int(r["depth"])), {"frame": [], "time_ms": [], "tests": []})
        s["frame"].append(int(r["frame"]))
        s["time_ms"].append(float(r["time_ms"]))
        s["tests"].append(float(r["tests"]))
    depths = sorted({d for (m, d) in series if m != "brute"}) or [0]
    machine = meta.get("machine", {})
    opts = meta.get("options", {})
    note = (f"{opts.get('spheres', '?')} spheres r={opts.get('radius', '?')}, leaf size {opts.get('leaf_size', '?')}; "
            f"{machine.get('cpu', '')}, {machine.get('date', '')}")
    out = args.out or args.dir
    os.makedirs(out, exist_ok=True)
    for column, label, name, log in (("time_ms", "collision time per frame (ms, build + tests)", "spheres_time", True),
                                     ("tests", "sphere-sphere tests per frame", "spheres_tests", True)):
        fig, axes = plt.subplots(1, len(depths), figsize=(5.2 * len(depths), 3.8), sharey=True, squeeze=False)
        for ax, depth in zip(axes[0], depths):
            for (method, d), s in sorted(series.items()):
                if method != "brute" and d != depth:
                    continue
                color, dash = STYLE.get(method, ("gray", ":"))
                ys = smooth(s[column], args.smooth) if column == "time_ms" else s[column]
                ax.plot(s["frame"], ys, color=color, linestyle=dash, linewidth=1.1, label=method)
            ax.set_title(f"depth {depth}")
            ax.set_xlabel("frame")
            if log:
                ax.set_yscale("log")
            ax.legend(fontsize=7)
        axes[0][0].set_ylabel(label + (f"\nrunning median of {args.smooth}" if column == "time_ms" else ""))
        fig.suptitle("spheres dropped into a box, a new tree per frame", fontsize=10)
        fig.text(0.01, 0.005, note, fontsize=6, color="gray")
        fig.tight_layout(rect=(0, 0.03, 1, 1))
        for fmt in args.formats.split(","):
            p = os.path.join(out, f"{name}.{fmt}")
            fig.savefig(p, dpi=130)
            print(f"figure: {p}")
        plt.close(fig)
    return 0


if __name__ == "__main__":
    sys.exit(main())
