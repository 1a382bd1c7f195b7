"""The API gives what the command line gives: on the example scene and on a short simulated scan."""

import csv
import json
from pathlib import Path

import numpy as np
import pytest

import mrtmap
from conftest import mrtmap_cli


def cli_points(*args):
    return json.loads(mrtmap_cli("mrt", *args, "--json").stdout)


def test_example_mrt_equals_the_cli():
    pts = [[2.0, 1.5, 1.1], [0.5, 0.5, 0.6], [3.9, 3.3, 1.7]]
    r = mrtmap.Scene.example().mrt(pts)
    args = [a for p in pts for a in ("--at", ",".join(map(str, p)))]
    ref = cli_points(*args)["points"]
    assert r.mrt_c.shape == (3,) and r.std_error_k.shape == (3,)
    np.testing.assert_allclose(r.mrt_c, [p["mrt_c"] for p in ref], rtol=0, atol=1e-9)
    np.testing.assert_allclose(r.std_error_k, [p["std_error_k"] for p in ref], rtol=0, atol=1e-9)
    # The CLI prints 20.68 °C at (2, 1.5, 1.1); so does str().
    assert "MRT 20.68 °C" in str(r).splitlines()[0]
    mrt, se = r  # unpacks
    assert mrt[0] == r.mrt_c[0]


def test_montecarlo_settings_reach_the_engine():
    s = mrtmap.Scene.example()
    a = s.mrt([[2.0, 1.5, 1.1]], method="montecarlo", rays=4000, seed=3)
    ref = cli_points("--at", "2,1.5,1.1", "--method", "montecarlo", "--rays", 4000, "--seed", 3)
    assert a.mrt_c[0] == pytest.approx(ref["points"][0]["mrt_c"], abs=1e-9)
    b = s.mrt([[2.0, 1.5, 1.1]], method="montecarlo", rays=4000, seed=4)
    assert a.mrt_c[0] != b.mrt_c[0]  # another seed, another draw


def test_person_and_planes_equal_the_cli():
    s = mrtmap.Scene.example()
    p = s.person([[2.0, 1.5, 0.6]], posture="seated", facing_deg=90)
    ref = cli_points("--at", "2,1.5,0.6", "--person", "seated", "--facing", 90)["persons"][0]
    assert p.mrt_c[0] == pytest.approx(ref["mrt_c"], abs=1e-9)
    pl = s.plane_radiant([[2.0, 1.5, 1.1]])
    ref = cli_points("--at", "2,1.5,1.1", "--plane")["planes"][0]
    np.testing.assert_allclose(pl.t_pr_c[0], [f[1] for f in ref["faces"]], atol=1e-9)
    assert pl.faces == tuple(f[0] for f in ref["faces"])
    assert pl.vertical_asymmetry_k[0] == pytest.approx(ref["vertical_k"], abs=1e-9)


def read_grid(path):
    rows = list(csv.DictReader(open(path)))
    return {(int(r["i"]), int(r["j"])): r for r in rows}


def test_example_map_equals_the_cli_grid(tmp_path):
    m = mrtmap.Scene.example().map(height=1.1, grid=(12, 9), margin=0.2)
    mrtmap_cli("map", "--grid", "12x9", "--margin-m", 0.2, "--out", tmp_path)
    grid = read_grid(tmp_path / "mrt_grid.csv")
    assert m.mrt_c.shape == (9, 12) and m.u_m.shape == (12,) and m.v_m.shape == (9,)
    assert np.isfinite(m.mrt_c).sum() == sum(1 for r in grid.values() if r["mrt_c"])
    for (i, j), r in grid.items():
        assert m.mrt_c[j, i] == pytest.approx(float(r["mrt_c"]), abs=5.1e-5)  # the CSV's 4 decimals
        assert m.xyz[j, i, 0] == pytest.approx(float(r["x"]), abs=5.1e-5)
    d = m.to_xarray_dict()
    assert d["data_vars"]["mrt_c"]["dims"] == ("v_m", "u_m")
    assert d["data_vars"]["mrt_c"]["data"] is m.mrt_c
    assert m.summary["mean_c"] == pytest.approx(float(np.nanmean(m.mrt_c)), abs=1e-9)


def test_dataframe_has_the_csvs_columns_and_values(tmp_path):
    # Issue 54: to_dataframe() said mrt/std_error where mrt_grid.csv says mrt_c/std_error_k.
    pd = pytest.importorskip("pandas")
    m = mrtmap.Scene.example().map(height=1.1, grid=(12, 9), margin=0.2)
    mrtmap_cli("map", "--grid", "12x9", "--margin-m", 0.2, "--out", tmp_path)
    csv_df = pd.read_csv(tmp_path / "mrt_grid.csv").dropna(subset=["mrt_c"])
    df = m.to_dataframe()
    assert set(df.columns) <= set(csv_df.columns), set(df.columns) - set(csv_df.columns)
    assert {"x", "y", "z", "mrt_c", "std_error_k", "i", "j", "u_m", "v_m"} <= set(df.columns)
    assert len(df) == len(csv_df)
    both = df.merge(csv_df, on=["i", "j"], suffixes=("", "_csv"))
    assert len(both) == len(df)
    for col in ("x", "y", "z", "mrt_c", "std_error_k", "u_m", "v_m"):
        np.testing.assert_allclose(both[col], both[f"{col}_csv"], rtol=0, atol=5.1e-5, err_msg=col)


def test_run_equals_the_cli_on_a_short_scan(scans, tmp_path):
    rec = scans[0]
    seen = []
    r = mrtmap.run(rec, tmp_path / "py", {"map": {"grid": [10, 10]}},
                   progress=lambda stage, done, total: seen.append(stage))
    mrtmap_cli("run", rec, "--out", tmp_path / "cli", "--grid", "10x10")
    py_grid = (tmp_path / "py" / "map-1.10m" / "mrt_grid.csv").read_text()
    cli_grid = (tmp_path / "cli" / "map-1.10m" / "mrt_grid.csv").read_text()
    assert py_grid == cli_grid
    assert (tmp_path / "py" / "report.html").exists()
    assert r.maps[0]["nodes"] == 100 and r.maps[0]["min_c"] <= r.maps[0]["mean_c"] <= r.maps[0]["max_c"]
    assert {"fuse", "segment"} <= {s["stage"].split()[0] for s in r.stages}
    assert all(t >= 0 for t in r.timings.values())
    assert r.surfaces >= 6
    assert any("fusing" in s for s in seen), seen
    assert "ran " in str(r)
    # The scene it wrote answers as the CLI does at a point of the room.
    scene = mrtmap.Scene.load(r.paths["scene"])
    a = scene.mrt([[1.5, 1.5, 1.1]])
    ref = cli_points("--scene", r.paths["scene"], "--at", "1.5,1.5,1.1")["points"][0]
    assert a.mrt_c[0] == pytest.approx(ref["mrt_c"], abs=1e-9)
    # The map's figures are summary.json's, read from named fields (issue 53: no guessing).
    summary_json = mrtmap.RunLayout(tmp_path / "py").summary_json(1.1)
    summary = json.loads(Path(summary_json).read_text())
    assert r.maps[0]["mean_c"] == summary["mean_c"] and r.maps[0]["nodes"] == summary["nodes"]
    assert r.maps[0]["min_c"] == summary["min"]["mrt_c"] and r.maps[0]["summary"]["height_m"] == 1.1
    # The paths it gives are the run folder's layout's, and the layout's files are there.
    layout = mrtmap.RunLayout(tmp_path / "py")
    assert r.paths == {"report": layout.report_html(), "run_json": layout.run_json(),
                       "scene": layout.scene_json()}
    assert r.maps[0]["csv"] == layout.mrt_grid_csv(1.1)
    for f in (layout.cloud_ply(), layout.fusion_json(), layout.poses_txt(), layout.frames_json(),
              layout.scene_json(), layout.segment_json(), layout.segments_ply(),
              layout.level_json(), layout.mrt_grid_csv(1.1), layout.mrt_map_png(1.1),
              layout.mrt_map_svg(1.1), layout.summary_json(1.1)):
        assert Path(f).is_file(), f


def test_run_layout_names_the_documented_files():
    layout = mrtmap.RunLayout("out")
    assert mrtmap.RunLayout.map_dir_name(1.1) == "map-1.10m"
    assert Path(layout.mrt_grid_csv(1.7)) == Path("out/map-1.70m/mrt_grid.csv")
    assert Path(layout.scene_json()) == Path("out/segment/scene.json")
    assert Path(layout.comfort_csv("mrt_seated")) == Path("out/comfort/mrt_seated.csv")
    assert Path(layout.export_file("gltf")) == Path("out/export/room.glb")
    with pytest.raises(mrtmap.MrtmapError, match="pmvv"):
        layout.comfort_png("pmvv")
    with pytest.raises(mrtmap.MrtmapError, match="the formats are"):
        layout.export_file("obj")


def test_map_goes_into_xarray():
    xr = pytest.importorskip("xarray")
    m = mrtmap.Scene.example().map(grid=(6, 5))
    ds = xr.Dataset.from_dict(m.to_xarray_dict())
    assert ds["mrt_c"].dims == ("v_m", "u_m") and ds["mrt_c"].shape == (5, 6)
    assert ds["mrt_c"].attrs["units"] == "degC" and ds["std_error_k"].attrs["units"] == "K"
    np.testing.assert_array_equal(ds["mrt_c"].values, m.mrt_c)
    assert float(ds["mrt_c"].sel(u_m=m.u_m[2], v_m=m.v_m[3])) == m.mrt_c[3, 2]
