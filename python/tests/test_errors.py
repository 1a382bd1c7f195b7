"""Bad inputs raise MrtmapError (a ValueError) with the CLI's kind of message; none crashes."""

import numpy as np
import pytest

import mrtmap


@pytest.fixture(scope="module")
def scene():
    return mrtmap.Scene.example()


@pytest.mark.parametrize("points, words", [
    ([[1.0, 1.0]], "(N, 3)"),
    (np.zeros((2, 3, 1)), "(N, 3)"),
    ([[1.0, float("nan"), 1.0]], "not a finite position"),
    ([[1.0, 1.0, float("inf")]], "not a finite position"),
    ([[20.0, 1.0, 1.1]], "outside the walls"),
    ([[1.0, 1.0, -0.5]], "below the floor"),
])
def test_bad_points(scene, points, words):
    with pytest.raises(mrtmap.MrtmapError, match=None) as e:
        scene.mrt(points)
    assert words in str(e.value)
    assert isinstance(e.value, ValueError)


def test_bad_settings(scene):
    with pytest.raises(mrtmap.MrtmapError, match="rays"):
        scene.mrt([[1, 1, 1]], rays=0)
    with pytest.raises(TypeError, match="'ray'"):
        scene.mrt([[1, 1, 1]], ray=10)
    with pytest.raises(mrtmap.MrtmapError, match="method"):
        scene.mrt([[1, 1, 1]], method="magic")
    with pytest.raises(mrtmap.MrtmapError, match="posture"):
        scene.person([[1, 1, 0.6]], posture="lying")
    with pytest.raises(mrtmap.MrtmapError, match="frame"):
        scene.mrt([[1, 1, 1]], frame="world")
    with pytest.raises(mrtmap.MrtmapError, match="world_from_room"):
        scene.mrt([[1, 1, 1]], frame="scan")  # the example was not written by segmentation
    with pytest.raises(mrtmap.MrtmapError, match="grid"):
        scene.map(grid=(0, 20))  # (1, 20) is a line of 20 nodes, as `--grid 1x20`
    with pytest.raises(mrtmap.MrtmapError, match="height"):
        scene.map(height=-1)
    with pytest.raises(mrtmap.MrtmapError, match="above the floor|height|ceiling"):
        scene.map(height=5.0)


def test_bad_files_and_runs(tmp_path):
    with pytest.raises(mrtmap.MrtmapFileNotFoundError, match="missing.json does not exist"):
        mrtmap.Scene.load(tmp_path / "missing.json")
    bad = tmp_path / "scene.json"
    bad.write_text("{not json")
    with pytest.raises(mrtmap.MrtmapError, match="scene.json"):
        mrtmap.Scene.load(bad)
    with pytest.raises(mrtmap.MrtmapError):
        mrtmap.run(tmp_path / "no-such-recording", tmp_path / "out")
    with pytest.raises(mrtmap.MrtmapError, match="config"):
        mrtmap.run(tmp_path, tmp_path / "out", {"map": {"gird": [3, 3]}})
    toml = tmp_path / "project.toml"
    toml.write_text("[map]\ngrid = 3\n")
    with pytest.raises(mrtmap.MrtmapError, match="project.toml"):
        mrtmap.run(tmp_path, tmp_path / "out", toml)


def test_bad_comfort_arguments():
    # One element's inputs never raise (test_pythonic.py); arguments that are wrong for every
    # element do.
    with pytest.raises(ValueError):
        mrtmap.pmv_ppd_iso([20, 21, 22], [20, 21], 0.1, 50, 1.2, 0.5)  # shapes do not broadcast
    with pytest.raises(mrtmap.MrtmapError, match="model"):
        mrtmap.pmv_ppd_iso(22, 22, 0.1, 50, 1.2, 0.5, model="55-2023")
    with pytest.raises(mrtmap.MrtmapError, match="SI"):
        mrtmap.pmv_ppd_iso(72, 72, 0.3, 50, 1.2, 0.5, units="IP")
    with pytest.raises(mrtmap.MrtmapError, match="standard"):
        mrtmap.operative_tmp(22, 24, 0.1, standard="CIBSE")
