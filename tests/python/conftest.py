"""Shared fixtures of the Python tests: the project's meshes and a tiny brute-force detector in numpy."""

import os
import pathlib

import numpy as np
import pytest

import tethash

SOURCE_DIR = pathlib.Path(os.environ.get("TETHASH_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))


@pytest.fixture(scope="session")
def box():
    return tethash.read_mesh(SOURCE_DIR / "meshes" / "box.vtu")


@pytest.fixture(scope="session")
def two_boxes(box):
    """Two copies of meshes/box.vtu (objects 0 and 1), the second moved so that they overlap by about a third."""
    p, t = box["positions"], box["tets"]
    n = p.shape[0]
    positions = np.vstack([p, p + np.array([0.6137, 0.2171, 0.1234])])
    tets = np.vstack([t, t + n]).astype(np.int32)
    vertex_object = np.repeat(np.array([0, 1], dtype=np.int32), n)
    tet_object = np.repeat(np.array([0, 1], dtype=np.int32), t.shape[0])
    return positions, tets, vertex_object, tet_object


def brute_force(positions, tets, slack):
    """Pairs (vertex, tet), vertex not a corner of tet, whose barycentric coordinates are all >= -slack."""
    a = positions[tets[:, 0]]
    edges = np.stack([positions[tets[:, k]] - a for k in (1, 2, 3)], axis=2)  # m x 3 x 3, columns b-a, c-a, d-a
    volume = np.abs(np.linalg.det(edges))
    keep = volume > 1e-14
    inverse = np.zeros_like(edges)
    inverse[keep] = np.linalg.inv(edges[keep])
    pairs = set()
    for start in range(0, tets.shape[0], 256):
        stop = min(start + 256, tets.shape[0])
        rel = positions[None, :, :] - a[start:stop, None, :]  # chunk x n x 3
        lam = np.einsum("tij,tvj->tvi", inverse[start:stop], rel)  # coordinates of b, c, d
        first = 1.0 - lam.sum(axis=2)
        inside = (lam.min(axis=2) >= -slack) & (first >= -slack) & keep[start:stop, None]
        for t, v in zip(*np.nonzero(inside)):
            tet = start + t
            if v not in tets[tet]:
                pairs.add((int(v), int(tet)))
    return pairs
