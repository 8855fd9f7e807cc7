"""tethash: spatial-hash collision detection for deformable tetrahedral meshes (Teschner et al. 2003).

Arrays: positions are float64 with shape (n, 3), tets int32 with shape (m, 4), both row-major. A C-contiguous
array of that dtype is read in place, without a copy (``Detector.positions_address`` is the address the detector
read); a strided or Fortran-ordered array is copied once per call (``Detector.positions_copied``). Any other
dtype or shape is a TypeError or ValueError naming the argument.

    det = tethash.Detector(cell_size="x1", penetration=True)
    det.set_topology(tets, len(positions))
    for step in range(steps):
        contacts = det.detect(positions)   # numpy structured array, dtype CONTACT_DTYPE

Contacts are sorted by (vertex, tet); fields: vertex, tet, vertex_object, tet_object, bary (4), depth and
direction (3; NaN and 0 unless the detector was made with penetration=True).
"""

import math
import os
import sys


def _load_failure(error):
    """The ImportError to raise when the compiled module does not load: which interpreter it was built for, which
    one this is, and what to do."""
    from ._build_info import PYTHON, PYTHON_VERSION

    built = f"Python {PYTHON_VERSION[0]}.{PYTHON_VERSION[1]} ({PYTHON})"
    here = f"Python {sys.version_info[0]}.{sys.version_info[1]} ({sys.executable})"
    if tuple(sys.version_info[:2]) != tuple(PYTHON_VERSION):
        return ImportError(f"tethash: this build of the module is for {built}, this interpreter is {here}: run "
                           f"{PYTHON}, or build tethash for this interpreter (cmake -DPython3_EXECUTABLE="
                           f"{sys.executable}; it needs numpy and pybind11)")
    try:
        import numpy  # noqa: F401  (the compiled module needs it)
    except ImportError:
        return ImportError(f"tethash: numpy is not installed for {here} (the module was built for {built} with its "
                           f"numpy): install numpy for this interpreter, or run {PYTHON}")
    return ImportError(f"tethash: the compiled module does not load in {here} (built for {built}): {error}")


try:
    from ._tethash import (CONTACT_DTYPE, EDGE_CONTACT_DTYPE, ContinuousDetector, Detector, EdgeFaceDetector, Error,
                           RunFailure, ccd_edge_edge, ccd_vertex_face, detect_continuous)
    from . import _tethash
except ImportError as _error:
    raise _load_failure(_error) from _error

__all__ = ["CONTACT_DTYPE", "Detector", "Error", "RunFailure", "detect", "read_mesh", "write_mesh", "simulate",
           "study", "scene_toml", "default_scene_text", "ccd_vertex_face", "ccd_edge_edge", "detect_continuous",
           "ContinuousDetector", "EDGE_CONTACT_DTYPE", "EdgeFaceDetector", "detect_edges"]


def detect(positions, tets, vertex_object=None, tet_object=None, objects=None, **params):
    """Contacts of one configuration: a structured array (see CONTACT_DTYPE) sorted by (vertex, tet).

    params: cell_size ("auto", a length, or "xF" times the mean edge), table_size, hash ("column", "teschner"),
    threads (0 = every core), skin, penetration (True: fill depth and direction).
    objects: a list of {"self_collision": bool, "static": bool}, one per object id.
    """
    det = Detector(**params)
    det.set_topology(tets, _tethash._check_positions(positions), vertex_object, tet_object, objects)
    return det.detect(positions)


def detect_edges(positions, tets, vertex_object=None, tet_object=None, objects=None, threads=1):
    """Edge-face contacts of one configuration: boundary edges crossing a boundary triangle of another object, or of
    a distant part of their own (docs/ccd.md). A dict: faces (F, 3) and edges (E, 2) int32 (the boundary), contacts
    (a structured array, EDGE_CONTACT_DTYPE, sorted by (edge, face)) and candidates (the pairs tested).

    Contact fields: edge, face (rows of edges and faces), edge_vertices (2), face_vertices (3, outward order),
    edge_object, face_object, edge_t (the crossing point is (1 - t) x[e0] + t x[e1]), face_bary (3), inner_end (0
    or 1: the end of the edge on the triangle's inner side), normal (3: the triangle's unit normal, inner to outer
    side). objects and threads as for detect; EdgeFaceDetector keeps the topology between calls."""
    det = EdgeFaceDetector()
    det.set_topology(tets, _tethash._check_positions(positions), vertex_object, tet_object, objects)
    return det.find(positions, threads)


def read_mesh(path, linearize=False):
    """Reads a tet mesh (.vtk .vtu .msh .node/.ele .mesh .veg) into a dict of numpy arrays: positions (n, 3)
    float64, tets (m, 4) int32, vertex_object, tet_object (int32, zeros for one object), vertex_label and
    tet_label (int32, empty when the file has none)."""
    return _tethash._read_mesh(os.fspath(path), linearize)


def write_mesh(path, positions, tets=None, vertex_object=None, tet_object=None):
    """Writes a tet mesh by extension (.vtu .vtk .msh .mesh .node/.ele), atomically. `positions` may also be a
    dict as read_mesh returns it."""
    if isinstance(positions, dict):
        mesh = positions
        positions, tets = mesh["positions"], mesh["tets"]
        vertex_object = mesh.get("vertex_object") if vertex_object is None else vertex_object
        tet_object = mesh.get("tet_object") if tet_object is None else tet_object
    if tets is None:
        raise TypeError("write_mesh: tets missing (give positions and tets, or a mesh dict)")
    _tethash._write_mesh(os.fspath(path), positions, tets, vertex_object, tet_object)


def _toml_value(value, where):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            raise ValueError(f"scene: {where}: not a finite number: {value}")
        return repr(value)
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{k} = {_toml_value(v, f'{where}.{k}')}" for k, v in value.items()) + " }"
    if hasattr(value, "tolist"):  # numpy arrays and scalars
        return _toml_value(value.tolist(), where)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(v, f"{where}[{i}]") for i, v in enumerate(value)) + "]"
    raise TypeError(f"scene: {where}: cannot write a {type(value).__name__} to a scene")


def scene_toml(scene):
    """The TOML text of a scene given as a dict (the keys of a scene file, docs/simulator.md): top-level values,
    tables (dicts) and arrays of tables (lists of dicts, e.g. "object")."""
    lines, tables = [], []
    for key, value in scene.items():
        if isinstance(value, dict):
            tables.append(f"\n[{key}]")
            tables += [f"{k} = {_toml_value(v, f'{key}.{k}')}" for k, v in value.items()]
        elif isinstance(value, (list, tuple)) and value and all(isinstance(v, dict) for v in value):
            for i, item in enumerate(value):
                tables.append(f"\n[[{key}]]")
                tables += [f"{k} = {_toml_value(v, f'{key}[{i}].{k}')}" for k, v in item.items()]
        else:
            lines.append(f"{key} = {_toml_value(value, key)}")
    return "\n".join(lines + tables) + "\n"


def default_scene_text():
    """The TOML of the built-in default scene (what `tethash simulate` runs without a file)."""
    return _tethash._default_scene_text()


def simulate(scene=None, steps=None, dt=None, substeps=None, integrator=None, record_every=0, base_dir="."):
    """Runs a scene as `tethash simulate` does, without writing frames: `scene` is a TOML file path, a dict
    (scene_toml) or None (the built-in default scene). steps, dt, substeps and integrator override the scene's.

    Returns a dict: steps, time, energy, contacts, max_depth, ms_detect, ms_step (numpy arrays, one value per
    step), energy_start, mesh (as read_mesh returns it, positions at the end), velocities, warnings, and with
    record_every = k > 0 the positions every k steps in frames (and frame_times). Raises RunFailure when the run
    blows up or crumples, Error on a bad scene."""
    if scene is None:
        return _tethash._simulate_text(default_scene_text(), "<default scene>", ".", steps, dt, substeps, integrator,
                                       record_every)
    if isinstance(scene, dict):
        return _tethash._simulate_text(scene_toml(scene), "<dict scene>", os.fspath(base_dir), steps, dt, substeps,
                                       integrator, record_every)
    return _tethash._simulate_file(os.fspath(scene), steps, dt, substeps, integrator, record_every)


def study(sweep, out="study", **options):
    """Runs a parameter study as `tethash study SWEEP` does (same value-list grammar, docs/studies.md) and
    returns a dict: csv and json (paths), rows, points_done, points_total, notes, and table (the CSV as a numpy
    structured array, one row per point and repeat).

    options: meshes (paths; "a.vtu+b.vtu" joins files), teschner_scenarios, scenarios, cell_size, table_size,
    hash, threads, grid, integrator, dt, substeps, duration, repeat, warmup, oracle, penetration,
    shard ("I/N"), quiet. Values may be lists or comma-separated text ("x0.5:x4:8")."""
    import numpy as np

    result = _tethash._study(sweep, dict(options, out=os.fspath(out)))
    table = np.genfromtxt(result["csv"], delimiter=",", names=True, dtype=None, encoding="utf-8")
    result["table"] = np.atleast_1d(table)
    return result
