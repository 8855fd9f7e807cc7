"""tethash.detect_edges and tethash.EdgeFaceDetector: edge-face contacts against a numpy evaluation of a crafted
crossing and against the oracle's brute force, the detector kept over steps, the errors."""

import numpy as np
import pytest

import tethash

FIELDS = tethash.EDGE_CONTACT_DTYPE.names


def same(a, b):
    return len(a) == len(b) and all(np.array_equal(a[f], b[f]) for f in FIELDS)


def boundary_edges(tets):
    """The edges of a tet soup where every tet is alone (each face on the boundary): its six edges."""
    edges = set()
    for t in tets:
        for i in range(4):
            for j in range(i + 1, 4):
                edges.add((min(t[i], t[j]), max(t[i], t[j])))
    return edges


def numpy_crossings(positions, tets, objects):
    """(edge, face) vertex-id pairs where an edge of one tet crosses a face of another tet's object (floating
    point, for crafted scenes without touching)."""
    found = set()
    for e in boundary_edges(tets):
        p, q = positions[e[0]], positions[e[1]]
        for t in tets:
            if objects[t[0]] == objects[e[0]]:
                continue
            for skip in range(4):
                f = [t[k] for k in range(4) if k != skip]
                a, b, c = positions[f]
                n = np.cross(b - a, c - a)
                dp, dq = np.dot(p - a, n), np.dot(q - a, n)
                if dp * dq >= 0:
                    continue
                x = p + dp / (dp - dq) * (q - p)  # the edge meets the plane here
                areas = [np.dot(np.cross(v - x, w - x), n) for v, w in ((b, c), (c, a), (a, b))]
                if min(areas) > 0 or max(areas) < 0:
                    found.add((e, tuple(sorted(f))))
    return found


def test_a_thin_tet_through_another_with_no_vertex_inside():
    # Tet A; tet B long and thin, its vertical edge piercing A's base and its slanted face, no vertex of B in A.
    a = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]
    b = [[0.21, 0.23, -1.1], [0.19, 0.22, 2.3], [3.1, 0.27, -1.2], [0.24, 3.3, 2.1]]
    positions = np.array(a + b, dtype=np.float64)
    tets = np.array([[0, 1, 2, 3], [4, 5, 6, 7]], dtype=np.int32)
    vertex_object = np.array([0] * 4 + [1] * 4, dtype=np.int32)
    tet_object = np.array([0, 1], dtype=np.int32)
    assert len(tethash.detect(positions, tets, vertex_object, tet_object)) == 0  # no vertex inside a tet

    r = tethash.detect_edges(positions, tets, vertex_object, tet_object)
    assert r["faces"].shape == (8, 3) and r["edges"].shape == (12, 2)
    c = r["contacts"]
    assert c.dtype == tethash.EDGE_CONTACT_DTYPE
    got = {(tuple(int(v) for v in e), tuple(sorted(int(v) for v in f)))
           for e, f in zip(c["edge_vertices"], c["face_vertices"])}
    expected = numpy_crossings(positions, tets, vertex_object)
    assert len(expected) >= 2
    assert got == expected
    # Rows index the boundary arrays; the crossing point is the same on the edge and on the triangle.
    assert np.array_equal(r["edges"][c["edge"]], c["edge_vertices"])
    assert np.array_equal(r["faces"][c["face"]], c["face_vertices"])
    t = c["edge_t"][:, None]
    on_edge = (1 - t) * positions[c["edge_vertices"][:, 0]] + t * positions[c["edge_vertices"][:, 1]]
    on_face = np.einsum("ki,kij->kj", c["face_bary"], positions[c["face_vertices"]])
    assert np.allclose(on_edge, on_face, atol=1e-12)
    assert np.all((c["edge_t"] > 0) & (c["edge_t"] < 1)) and np.all(c["face_bary"] >= 0)
    # The normal: unit, normal to the face, pointing away from the inner end; objects as given.
    corners = positions[c["face_vertices"]]
    assert np.allclose(np.linalg.norm(c["normal"], axis=1), 1)
    assert np.allclose(np.einsum("kj,kj->k", c["normal"], corners[:, 1] - corners[:, 0]), 0, atol=1e-12)
    inner = positions[c["edge_vertices"][np.arange(len(c)), c["inner_end"]]]
    assert np.all(np.einsum("kj,kj->k", inner - on_face, c["normal"]) < 0)
    assert np.array_equal(c["edge_object"], vertex_object[c["edge_vertices"][:, 0]])
    assert np.array_equal(c["face_object"], vertex_object[c["face_vertices"][:, 0]])
    # Pulled apart: nothing.
    apart = positions.copy()
    apart[4:, 0] += 10
    assert len(tethash.detect_edges(apart, tets, vertex_object, tet_object)["contacts"]) == 0


def test_equal_to_the_oracle_with_object_rules(two_boxes):
    positions, tets, vertex_object, tet_object = two_boxes
    rng = np.random.default_rng(29)
    moved = positions + rng.normal(scale=0.05, size=positions.shape)
    for objects in (None, [{"self_collision": False}, {"self_collision": True}],
                    [{"static": True}, {"static": True}]):
        brute = tethash._tethash._brute_force_edges(moved, tets, vertex_object, tet_object, objects)
        for threads in (1, 2):
            r = tethash.detect_edges(moved, tets, vertex_object, tet_object, objects, threads=threads)
            assert same(r["contacts"], brute["contacts"]), (objects, threads)
            assert np.array_equal(r["faces"], brute["faces"]) and np.array_equal(r["edges"], brute["edges"])
        if objects and objects[0].get("static"):
            assert len(brute["contacts"]) == 0
        else:
            assert len(brute["contacts"]) > 20
    assert r["candidates"] >= len(r["contacts"])


def test_a_kept_detector_over_steps(two_boxes):
    positions, tets, vertex_object, tet_object = two_boxes
    det = tethash.EdgeFaceDetector()
    det.set_topology(tets, len(positions), vertex_object, tet_object)
    counts = set()
    for step in range(4):
        moved = positions.copy()
        moved[vertex_object == 1, 0] += 0.2 * step  # the second box slides out of the first
        found = det.find(moved)
        brute = tethash._tethash._brute_force_edges(moved, tets, vertex_object, tet_object)
        assert same(found["contacts"], brute["contacts"])
        counts.add(len(found["contacts"]))
    assert len(counts) > 1


def test_bad_input_is_refused(two_boxes):
    positions, tets, vertex_object, tet_object = two_boxes
    det = tethash.EdgeFaceDetector()
    with pytest.raises(tethash.Error, match="set_topology"):
        det.find(positions)
    det.set_topology(tets, len(positions))
    with pytest.raises(tethash.Error, match="rows"):
        det.find(positions[:-1])
    bad = positions.copy()
    bad[7, 1] = np.nan
    with pytest.raises(tethash.Error, match="7"):
        det.find(bad)
    with pytest.raises(tethash.Error, match="thread"):
        det.find(positions, threads=-3)
    with pytest.raises(TypeError, match="float64"):
        det.find(positions.astype(np.float32))
    out_of_range = tets.copy()
    out_of_range[3, 2] = len(positions)
    with pytest.raises(tethash.Error, match=str(len(positions))):
        tethash.detect_edges(positions, out_of_range)
    with pytest.raises(ValueError, match="vertex_object"):
        tethash.detect_edges(positions, tets, vertex_object[:-1])
    with pytest.raises(ValueError, match="objects"):
        tethash.detect_edges(positions, tets, vertex_object, tet_object, objects=[{"fixed": True}])
