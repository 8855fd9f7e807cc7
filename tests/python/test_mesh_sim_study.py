"""Mesh reading and writing, simulate and study from Python."""

import json

import numpy as np
import pytest

import tethash
from conftest import SOURCE_DIR


@pytest.mark.parametrize("ext", [".vtu", ".vtk", ".msh", ".mesh"])
def test_write_read_round_trip(tmp_path, two_boxes, ext):
    positions, tets, vertex_object, tet_object = two_boxes
    path = tmp_path / ("two_boxes" + ext)
    tethash.write_mesh(path, positions, tets, vertex_object, tet_object)
    back = tethash.read_mesh(path)
    assert back["tets"].dtype == np.int32 and back["positions"].dtype == np.float64
    assert np.array_equal(back["tets"], tets)
    assert np.allclose(back["positions"], positions, rtol=0, atol=1e-12 * np.abs(positions).max())
    # Contacts of what was read back equal those of what was written.
    before = tethash.detect(positions, tets, vertex_object, tet_object)
    after = tethash.detect(back["positions"], back["tets"])
    assert np.array_equal(before[["vertex", "tet"]], after[["vertex", "tet"]])


def test_write_read_dict_and_errors(tmp_path, box):
    path = tmp_path / "box.vtu"
    tethash.write_mesh(path, box)
    assert np.array_equal(tethash.read_mesh(path)["tets"], box["tets"])
    with pytest.raises(tethash.Error, match="nothing.xyz"):
        tethash.read_mesh(tmp_path / "nothing.xyz")
    with pytest.raises(tethash.Error, match="missing.vtu"):
        tethash.read_mesh(tmp_path / "missing.vtu")
    with pytest.raises(TypeError, match="tets: expected dtype int32"):
        tethash.write_mesh(tmp_path / "x.vtu", box["positions"], box["tets"].astype(np.int64))
    assert not (tmp_path / "x.vtu").exists()


def test_simulate_dict_scene_falls_and_lands():
    scene = {
        "dt": 1 / 240,
        "steps": 60,
        "gravity": [0, 0, -9.81],
        "ground": {"height": 0.0},
        "output": {"every": 0},
        "object": [{"name": "cube", "generate": {"shape": "box", "resolution": 3, "size": [0.4, 0.4, 0.4]},
                    "translate": [0, 0, 0.3], "material": {"density": 500, "young": 1e5}}],
    }
    run = tethash.simulate(scene, record_every=20)
    assert run["steps"] == 60 and run["time"].shape == (60,)
    assert run["time"][-1] == pytest.approx(60 / 240)
    z = run["mesh"]["positions"][:, 2]
    # Dropped from a bottom at 0.1 for 0.25 s: it reached the ground and rests on it (no falling through).
    assert z.min() > -0.02 and z.min() < 0.02
    assert len(run["frames"]) == 4 and np.array_equal(run["frames"][-1], run["mesh"]["positions"])
    assert np.all(np.isfinite(run["energy"])) and run["energy"][-1] < run["energy_start"]


def test_simulate_bad_scene_is_an_error():
    with pytest.raises(tethash.Error, match="stepz"):
        tethash.simulate({"stepz": 3})
    with pytest.raises(ValueError, match="steps"):
        tethash.simulate(None, steps=-1)


def test_study_cell_size(tmp_path):
    box = str(SOURCE_DIR / "meshes" / "box.vtu")
    res = tethash.study("cell-size", out=tmp_path / "s", meshes=[box + "+" + box], cell_size="x0.5,x1,x2",
                        repeat=1, warmup=0)
    table = res["table"]
    assert res["points_done"] == 3 and len(table) == 3
    assert json.loads((tmp_path / "s" / "study.json").read_text())
    # Every point found the same contacts (the two copies coincide: every vertex is in the other's tets).
    assert len(set(table["contacts"].tolist())) == 1 and table["contacts"][0] > 0
    with pytest.raises(tethash.Error, match="shard"):
        tethash.study("cell-size", out=tmp_path / "t", meshes=[box], shard="3/2")
    with pytest.raises(TypeError, match="unknown argument 'cellsize'"):
        tethash.study("cell-size", out=tmp_path / "t", meshes=[box], cellsize="x1")
