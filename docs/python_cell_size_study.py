# %% [markdown]
# # Cell size of the hash grid, studied from Python
#
# A notebook-style script (cells marked `# %%`, for Jupyter/VS Code or plain `python3`): it runs the cell-size
# sweep of `tethash study cell-size` through the Python module, on two shipped meshes put in contact, and plots
# the detection time and the work of the three stages against the cell size (in mean edge lengths).
#
#     PYTHONPATH=build/python /usr/bin/python3 docs/python_cell_size_study.py [--small] [--out DIR]
#
# `--small` runs a short sweep (a few points, one repeat) for a check that the whole path works.

# %%
import argparse
import pathlib

import matplotlib.pyplot as plt  # without a display matplotlib draws with Agg; the figure is saved to a file
import numpy as np

import tethash

root = pathlib.Path(__file__).resolve().parents[1]
parser = argparse.ArgumentParser(description="cell-size study of the detector, plotted")
parser.add_argument("--small", action="store_true", help="a short sweep (3 points, 1 repeat)")
parser.add_argument("--out", default="python_cell_size_study", help="output folder")
args, _ = parser.parse_known_args()

# %% [markdown]
# The scene: the shipped box and sphere in one scene of two objects (`a+b` joins files). Factors of the mean edge
# length from 1/4 to 8, log-spaced; each point is measured `repeat` times after a warm-up, and every detection is
# compared with the brute-force oracle (columns `missed` and `extra`).

# %%
scene = f"{root / 'meshes' / 'box.vtu'}+{root / 'meshes' / 'sphere.vtu'}"
if args.small:
    sweep = dict(cell_size="x0.5:x2:3", repeat=1, warmup=0)
else:
    sweep = dict(cell_size="x0.25:x8:11", repeat=5, warmup=1)
result = tethash.study("cell-size", out=args.out, meshes=[scene], threads=1, **sweep)
table = result["table"]
print(f"{result['rows']} rows in {result['csv']}")
assert np.all(table["missed"] == 0) and np.all(table["extra"] == 0), "the detector disagreed with the oracle"

# %% [markdown]
# The median time per point, and what each stage did: entries scanned grow with the cell (more vertices per
# cell), cells visited shrink with it; the fastest cell size balances the two.

# %%
factors = np.unique(table["cell_factor"])
median_ms = np.array([np.median(table["ms_total"][table["cell_factor"] == f]) for f in factors])
first = np.array([np.flatnonzero(table["cell_factor"] == f)[0] for f in factors])
best = factors[np.argmin(median_ms)]
print(f"fastest cell size: {best:g} x the mean edge ({median_ms.min():.2f} ms)")

fig, (ax_time, ax_work) = plt.subplots(1, 2, figsize=(10, 4))
ax_time.plot(factors, median_ms, "o-")
ax_time.set(xscale="log", xlabel="cell size / mean edge length", ylabel="detection time (ms, median)",
            title="box + sphere, 1 thread")
ax_time.axvline(best, color="grey", linestyle=":")
for column in ("cells_visited", "entries_scanned", "inside_tests"):
    ax_work.plot(factors, table[column][first], "o-", label=column)
ax_work.set(xscale="log", yscale="log", xlabel="cell size / mean edge length", ylabel="count per detection")
ax_work.legend()
fig.tight_layout()
figure = pathlib.Path(args.out) / "cell_size.png"
fig.savefig(figure, dpi=100)
print(f"figure: {figure}")
