"""tethash.Detector and tethash.detect on numpy arrays: contacts against a brute force, the array rules."""

import numpy as np
import pytest

import tethash
from conftest import brute_force


def same(a, b):
    """Equal contact arrays (depth is NaN without penetration, and NaN != NaN)."""
    return len(a) == len(b) and all(np.array_equal(a[f], b[f], equal_nan=a[f].dtype.kind == "f")
                                    for f in tethash.CONTACT_DTYPE.names)


def pairs_of(contacts):
    return {(int(c["vertex"]), int(c["tet"])) for c in contacts}


def test_contacts_equal_brute_force(two_boxes):
    positions, tets, vertex_object, tet_object = two_boxes
    contacts = tethash.detect(positions, tets, vertex_object, tet_object)
    assert contacts.dtype == tethash.CONTACT_DTYPE
    found = pairs_of(contacts)
    strict = brute_force(positions, tets, -1e-12)  # clearly inside
    loose = brute_force(positions, tets, 1e-12)  # inside or within rounding of a face
    assert len(strict) > 100
    assert strict <= found <= loose
    # Sorted by (vertex, tet), objects as given, barycentric coordinates that rebuild the vertex.
    order = list(zip(contacts["vertex"], contacts["tet"]))
    assert order == sorted(order)
    assert np.array_equal(contacts["vertex_object"], vertex_object[contacts["vertex"]])
    assert np.array_equal(contacts["tet_object"], tet_object[contacts["tet"]])
    corners = positions[tets[contacts["tet"]]]  # k x 4 x 3
    rebuilt = np.einsum("ki,kij->kj", contacts["bary"], corners)
    assert np.allclose(rebuilt, positions[contacts["vertex"]], atol=1e-12)
    assert np.all(np.isnan(contacts["depth"]))


def test_parameters_do_not_change_the_answer(two_boxes):
    positions, tets, vertex_object, tet_object = two_boxes
    reference = tethash.detect(positions, tets, vertex_object, tet_object)
    for params in ({"cell_size": "x0.5", "hash": "teschner"}, {"cell_size": 0.3, "table_size": 97},
                   {"table_size": "x2", "threads": 2}):
        other = tethash.detect(positions, tets, vertex_object, tet_object, **params)
        assert same(other, reference), params


def test_objects_and_penetration(two_boxes):
    positions, tets, vertex_object, tet_object = two_boxes
    det = tethash.Detector(penetration=True)
    det.set_topology(tets, positions.shape[0], vertex_object, tet_object,
                     objects=[{"self_collision": False}, {"self_collision": False}])
    contacts = det.detect(positions)
    assert len(contacts) > 0
    assert np.all(contacts["vertex_object"] != contacts["tet_object"])
    assert np.all(np.isfinite(contacts["depth"])) and np.all(contacts["depth"] >= 0)
    assert np.allclose(np.linalg.norm(contacts["direction"], axis=1), 1.0)
    # The overlap is at most 0.6137 deep along x (box of side 1 moved by 0.6137, 0.2171, 0.1234).
    assert contacts["depth"].max() < 0.7
    assert det.stats["contacts"] == len(contacts)


def test_zero_copy_on_c_contiguous_float64(two_boxes):
    positions, tets, _, _ = two_boxes
    positions = np.ascontiguousarray(positions)
    det = tethash.Detector()
    det.set_topology(tets, positions.shape[0])
    first = det.detect(positions)
    assert det.positions_address == positions.ctypes.data
    assert not det.positions_copied
    # The detector reads the caller's buffer: moving it in place changes the next answer.
    positions[positions.shape[0] // 2:, 0] += 5.0
    assert len(det.detect(positions)) < len(first)
    assert det.positions_address == positions.ctypes.data
    positions[positions.shape[0] // 2:, 0] -= 5.0


def test_one_copy_for_strided_or_fortran_arrays(two_boxes):
    positions, tets, _, _ = two_boxes
    det = tethash.Detector()
    det.set_topology(tets, positions.shape[0])
    reference = det.detect(np.ascontiguousarray(positions))
    fortran = np.asfortranarray(positions)
    assert same(det.detect(fortran), reference)
    assert det.positions_copied and det.positions_address != fortran.ctypes.data
    wide = np.zeros((positions.shape[0], 6))
    wide[:, ::2] = positions
    assert same(det.detect(wide[:, ::2]), reference)
    assert det.positions_copied


def test_bad_arrays_name_the_argument(two_boxes):
    positions, tets, _, _ = two_boxes
    det = tethash.Detector()
    det.set_topology(tets, positions.shape[0])
    with pytest.raises(TypeError, match="positions.*float64.*float32"):
        det.detect(positions.astype(np.float32))
    with pytest.raises(ValueError, match=r"positions: expected shape \(n, 3\), found \(\d+, 2\)"):
        det.detect(np.ascontiguousarray(positions[:, :2]))
    with pytest.raises(ValueError, match="positions: expected shape"):
        det.detect(positions.ravel())
    with pytest.raises(TypeError, match="positions: expected a numpy array"):
        det.detect(positions.tolist())
    with pytest.raises(ValueError, match="positions: expected %d rows" % positions.shape[0]):
        det.detect(positions[:-1])
    with pytest.raises(TypeError, match="tets: expected dtype int32, found int64"):
        det.set_topology(tets.astype(np.int64), positions.shape[0])
    with pytest.raises(ValueError, match="vertex_object: expected %d ids" % positions.shape[0]):
        det.set_topology(tets, positions.shape[0], vertex_object=np.zeros(3, dtype=np.int32))
    with pytest.raises(tethash.Error):  # index out of range, named by the core
        det.set_topology(tets, 10)
    with pytest.raises(TypeError, match="unknown detector parameter 'cellsize'"):
        tethash.Detector(cellsize=1.0)
    with pytest.raises(ValueError, match="cell_size"):
        tethash.Detector(cell_size="x-1")
    fresh = tethash.Detector()
    with pytest.raises(ValueError, match="set_topology"):
        fresh.detect(positions)
