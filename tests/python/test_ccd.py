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


def _vertex_through_a_face():
    """Tet 0 the unit corner tet; tet 1's apex, vertex 7, rises from z = -0.1 to 0.1 through tet 0's base, 0.3 from
    its corner 0 at the end (the rest state)."""
    tets = np.array([[0, 1, 2, 3], [4, 5, 6, 7]], dtype=np.int32)
    rest = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [0, 0, -1], [1, 0, -1], [0, 1, -1], [0.2, 0.2, 0.1]],
                    dtype=np.float64)
    x0 = rest.copy()
    x0[7, 2] = -0.1
    return tets, rest, x0, rest.copy()


def test_continuous_detector_locality_refuses_a_local_pair_and_accepts_a_far_one():
    tets, rest, x0, x1 = _vertex_through_a_face()
    det = tethash.ContinuousDetector()
    det.set_topology(tets, 8)
    free = det.detect(x0, x1)
    assert list(free["kind"]) == [0] and list(free["a"]) == [7] and free["broad_phase_pairs"] >= 1
    one_group = np.zeros(8, dtype=np.int32)
    det.set_locality(rest, one_group, [0.25])  # reach 0.5: vertex 7 and corner 0 are 0.3 apart, local
    local = det.detect(x0, x1)
    assert len(local["toi"]) == 0 and local["broad_phase_pairs"] >= 1  # met by the grid, refused by the rule
    det.set_locality(rest, one_group, [0.05 ** 2])  # reach 0.05: far
    assert list(det.detect(x0, x1)["a"]) == [7]
    by_object = np.array([0, 0, 0, 0, 1, 1, 1, 1], dtype=np.int32)
    det.set_locality(rest, by_object, [0.25, 0.25])  # two groups: never local
    assert list(det.detect(x0, x1)["a"]) == [7]


def test_continuous_detector_bad_input_is_named():
    tets, rest, x0, x1 = _vertex_through_a_face()
    det = tethash.ContinuousDetector()
    with pytest.raises(tethash.Error, match="set_topology"):
        det.detect(x0, x1)
    det.set_topology(tets, 8)
    one_group = np.zeros(8, dtype=np.int32)
    with pytest.raises(tethash.Error, match="vertex 4 is in group 1"):
        det.set_locality(rest, np.array([0, 0, 0, 0, 1, 1, 1, 1], dtype=np.int32), [0.25])
    with pytest.raises(tethash.Error, match="squared reach of group 0"):
        det.set_locality(rest, one_group, [-1.0])
    with pytest.raises(tethash.Error, match="rest has 7 rows"):
        det.set_locality(rest[:7], one_group, [0.25])
    with pytest.raises(ValueError, match="vertex_group: expected 8 ids"):
        det.set_locality(rest, one_group[:7], [0.25])
    with pytest.raises(tethash.Error, match="x0 and x1 have 8 and 7 rows"):
        det.detect(x0, x1[:7])
