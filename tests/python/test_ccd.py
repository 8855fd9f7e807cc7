"""tethash.ccd_vertex_face, ccd_edge_edge and detect_continuous on numpy arrays: contacts at known times, misses,
the array rules."""

import numpy as np
import pytest

import tethash

TRIANGLE = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]


def test_vertex_through_a_triangle_meets_it_no_later_than_half_way():
    start = np.array([[0.2, 0.2, 1]] + TRIANGLE, dtype=np.float64)
    end = np.array([[0.2, 0.2, -1]] + TRIANGLE, dtype=np.float64)
    hit, toi = tethash.ccd_vertex_face(start, end)
    assert hit and 0.5 - 1e-5 <= toi <= 0.5
    end[0] = [0.2, 0.2, 1e-3]  # stops short
    assert tethash.ccd_vertex_face(start, end) == (False, 1.0)


def test_edges_crossing_and_parallel_edges_meeting():
    start = np.array([[0, 0, 0], [1, 0, 0], [0.5, -1, 1], [0.5, 1, 1]], dtype=np.float64)
    end = start.copy()
    end[2:, 2] -= 2
    hit, toi = tethash.ccd_edge_edge(start, end)
    assert hit and 0.5 - 1e-5 <= toi <= 0.5
    start = np.array([[0, 0, 0], [1, 0, 0], [0.2, 1, 0], [0.8, 1, 0]], dtype=np.float64)
    end = start.copy()
    end[2:, 1] -= 2
    hit, toi = tethash.ccd_edge_edge(start, end)
    assert hit and 0.5 - 1e-5 <= toi <= 0.5


def test_bad_arrays_and_parameters_are_refused():
    start = np.zeros((4, 3))
    with pytest.raises(ValueError, match="shape"):
        tethash.ccd_vertex_face(np.zeros((3, 3)), start)
    with pytest.raises(TypeError, match="float64"):
        tethash.ccd_edge_edge(start.astype(np.float32), start)
    with pytest.raises(tethash.Error, match="tolerance"):
        tethash.ccd_vertex_face(start, start, tolerance=0)


def test_detect_continuous_sees_a_tet_passing_through_another():
    tets = np.array([[0, 1, 2, 3], [4, 5, 6, 7]], dtype=np.int32)
    a = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]
    b = [[0.2, 0.2, 0.2], [1.2, 0.2, 0.2], [0.2, 1.2, 0.2], [0.2, 0.2, 1.2]]
    x0 = np.array(a + [[x - 3, y, z] for x, y, z in b], dtype=np.float64)
    x1 = np.array(a + [[x + 3, y, z] for x, y, z in b], dtype=np.float64)
    r = tethash.detect_continuous(tets, x0, x1)
    assert len(r["toi"]) > 0
    assert set(r["kind"]) == {0, 1}  # vertex-face and edge-edge
    # B's corner (1.2 - 3 + 6 t, 0.2, 0.2) reaches A's face x = 0 at t = 0.3.
    assert 0.3 - 1e-5 <= r["toi"].min() <= 0.3
    assert r["faces"].shape == (8, 3) and r["edges"].shape == (12, 2)
    same = tethash.detect_continuous(tets, x0, x1, threads=2)
    assert all(np.array_equal(r[k], same[k]) for k in r)
