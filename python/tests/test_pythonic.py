"""The package behaves as a pythermalcomfort and numpy user expects (issue 54's Python items, issue
53's "results as Python objects"): one bad element gives NaN there, scalars give floats, scenes
pickle and change, Ctrl-C stops a run, keywords are typed, errors are Python's own kinds."""

import _thread
import inspect
import json
import pickle
import time
import warnings
from pathlib import Path

import numpy as np
import pytest

import mrtmap

ptc_models = pytest.importorskip("pythermalcomfort.models")
from pythermalcomfort.environment import mean_radiant_tmp as ptc_mrt  # noqa: E402
from pythermalcomfort.environment import operative_tmp as ptc_to  # noqa: E402


def peer_pmv(*args, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return ptc_models.pmv_ppd_iso(*args, **kw)


# ---- 1. comfort functions: NaN at a bad element, floats for scalars, limit_inputs, tsv ----

def test_a_nan_or_refused_element_is_nan_there_and_the_others_are_numbers():
    tdb = [22.0, np.nan, 24.0, 25.0, 26.0]
    rh = [50.0, 50.0, 150.0, 50.0, -5.0]  # 150 % and −5 % are beyond the formula
    ours = mrtmap.pmv_ppd_iso(tdb, 24, 0.1, rh, 1.2, 0.5)
    peer = peer_pmv(tdb, 24, 0.1, rh, 1.2, 0.5)
    np.testing.assert_array_equal(np.isnan(ours.pmv), [False, True, True, False, True])
    np.testing.assert_array_equal(ours.pmv, peer.pmv)
    np.testing.assert_array_equal(ours.ppd, peer.ppd)


def test_limit_inputs_false_computes_outside_iso_ranges_as_pythermalcomfort():
    # 35 °C air and 3 m/s lie outside ISO 7730's ranges but within the formula's.
    args = ([22, 35, 25], [24, 24, 45], [0.1, 0.1, 3.0], 50, 1.2, 0.5)
    limited = mrtmap.pmv_ppd_iso(*args)
    assert np.isfinite(limited.pmv[0]) and np.isnan(limited.pmv[1:]).all()
    free = mrtmap.pmv_ppd_iso(*args, limit_inputs=False, round_output=False)
    assert np.isfinite(free.pmv).all()
    peer = peer_pmv(*args, limit_inputs=False, round_output=False)
    np.testing.assert_allclose(free.pmv, peer.pmv, rtol=0, atol=1e-6)
    np.testing.assert_allclose(free.ppd, peer.ppd, rtol=0, atol=1e-6)


def test_an_element_the_formula_refuses_warns_naming_it_when_not_limited():
    with pytest.warns(RuntimeWarning, match=r"1 element .*element 1: relative humidity"):
        r = mrtmap.pmv_ppd_iso([22, 22, 22], 22, 0.1, [50, 150, 50], 1.2, 0.5, limit_inputs=False)
    assert np.isnan(r.pmv[1]) and np.isfinite(r.pmv[[0, 2]]).all()
    # A NaN input is NaN out without a word, as numpy's arithmetic.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = mrtmap.pmv_ppd_iso([22, np.nan], 22, 0.1, 50, 1.2, 0.5, limit_inputs=False)
    assert np.isnan(r.pmv[1]) and np.isfinite(r.pmv[0])


def test_other_comfort_functions_give_nan_at_a_bad_element():
    with pytest.warns(RuntimeWarning, match="element 0: air speed"):
        to = mrtmap.operative_tmp([22, 22, np.nan], 24, [-0.1, 0.1, 0.1])
    np.testing.assert_array_equal(np.isnan(to), [True, False, True])
    assert to[1] == pytest.approx(float(ptc_to(22, 24, 0.1)), abs=1e-9)
    with pytest.warns(RuntimeWarning, match="element 0"):
        tr = mrtmap.mean_radiant_tmp([25, 25], 22, [-0.1, 0.1], standard="ISO")
    assert np.isnan(tr[0])
    assert tr[1] == pytest.approx(float(ptc_mrt(25, 22, 0.1, standard="ISO")), abs=1e-6)


def test_scalars_in_give_python_floats_out():
    r = mrtmap.pmv_ppd_iso(25, 25, 0.1, 50, 1.4, 0.5)
    peer = peer_pmv(25, 25, 0.1, 50, 1.4, 0.5)
    assert type(r.pmv) is float and type(r.ppd) is float
    assert (r.pmv, r.ppd, r.tsv) == (float(peer.pmv), float(peer.ppd), peer.tsv)
    assert type(mrtmap.operative_tmp(22, 24, 0.1)) is float
    assert type(mrtmap.mean_radiant_tmp(25, 22, 0.1)) is float
    assert type(mrtmap.v_relative(0.1, 1.4)) is float
    assert type(mrtmap.pmv_ppd_iso(np.float64(25), 25, 0.1, 50, 1.4, 0.5).pmv) is float
    # Arrays stay arrays, even of one element.
    assert mrtmap.pmv_ppd_iso([25], 25, 0.1, 50, 1.4, 0.5).pmv.shape == (1,)


@pytest.mark.parametrize("limit", [True, False])
def test_tsv_equals_pythermalcomforts(limit):
    rng = np.random.default_rng(5)
    n = 2000
    args = (rng.uniform(5, 40, n), rng.uniform(5, 50, n), rng.uniform(0, 1.5, n),
            rng.uniform(5, 95, n), rng.uniform(0.8, 4, n), rng.uniform(0, 2, n))
    ours = mrtmap.pmv_ppd_iso(*args, limit_inputs=limit)
    peer = peer_pmv(*args, limit_inputs=limit)
    assert ours.tsv.shape == (n,)
    labels = lambda a: [str(x) for x in a]  # noqa: E731 — NaN as "nan" on both sides
    assert labels(ours.tsv) == labels(peer.tsv)
    assert len(set(labels(ours.tsv))) >= 5  # the draws span most categories


# ---- 2. scenes: pickle, JSON and dicts, another temperature ----

def test_scene_pickles_round_trips_and_recomputes_with_another_temperature():
    s = mrtmap.Scene.example()
    pts = [[2.0, 1.5, 1.1], [1.0, 1.0, 0.6]]
    before = s.mrt(pts).mrt_c
    back = pickle.loads(pickle.dumps(s))
    assert back.to_json() == s.to_json() and back.source == s.source
    np.testing.assert_array_equal(back.mrt(pts).mrt_c, before)
    again = mrtmap.Scene.from_json(s.to_json())
    np.testing.assert_array_equal(again.mrt(pts).mrt_c, before)
    np.testing.assert_array_equal(mrtmap.Scene.from_dict(s.to_dict()).mrt(pts).mrt_c, before)
    # The window 15 K warmer: the same as editing scene.json by hand, and warmer than before.
    assert "window-1" in s.ids()
    warm = s.with_surface_temperature("window-1", 25.0)
    d = s.to_dict()
    for surface in d["surfaces"]:
        for f in surface.get("features", []):
            if f["id"] == "window-1":
                f["temperature_c"] = 25.0
    by_hand = mrtmap.Scene.from_dict(d)
    np.testing.assert_allclose(warm.mrt(pts).mrt_c, by_hand.mrt(pts).mrt_c, rtol=0, atol=1e-12)
    # A dict built with numpy (arrays for polygons, float32 temperatures) reads the same (it
    # raised "Object of type ndarray is not JSON serializable").
    with_numpy = s.to_dict()
    for surface in with_numpy["surfaces"]:
        surface["polygon"] = np.array(surface["polygon"])
        surface["temperature_c"] = np.float64(surface["temperature_c"])
    np.testing.assert_array_equal(mrtmap.Scene.from_dict(with_numpy).mrt(pts).mrt_c, before)
    assert (warm.mrt(pts).mrt_c > before).all()
    np.testing.assert_array_equal(s.mrt(pts).mrt_c, before)  # the original is unchanged
    # The changed scene pickles too.
    np.testing.assert_array_equal(pickle.loads(pickle.dumps(warm)).mrt(pts).mrt_c,
                                  warm.mrt(pts).mrt_c)


def test_scene_changes_and_texts_are_checked():
    s = mrtmap.Scene.example()
    with pytest.raises(mrtmap.MrtmapError, match="no surface, feature or occluder 'windw'.*window-1"):
        s.with_surface_temperature("windw", 20.0)
    with pytest.raises(mrtmap.MrtmapError, match="not a finite number"):
        s.with_surface_temperature("window-1", float("nan"))
    with pytest.raises(mrtmap.MrtmapError, match="scene JSON"):
        mrtmap.Scene.from_json("{not json")
    with pytest.raises(TypeError, match="dict"):
        mrtmap.Scene.from_dict("{}")


def map_mean(scene):
    return float(np.nanmean(scene.map(grid=(5, 5)).mrt_c))


def test_scenes_go_to_dask_worker_processes():
    distributed = pytest.importorskip("dask.distributed")
    s = mrtmap.Scene.example()
    scenes = [s, s.with_surface_temperature("window-1", 30.0)]
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        means = client.gather(client.map(map_mean, scenes))
    assert means == [map_mean(x) for x in scenes]
    assert means[1] > means[0]


# ---- 3. Ctrl-C ----

def test_keyboard_interrupt_raised_by_progress_stops_the_run(scans, tmp_path):
    calls = []

    def progress(stage, done, total):
        calls.append(stage)
        if "fusing" in stage:
            raise KeyboardInterrupt

    t0 = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        mrtmap.run(scans[0], tmp_path / "out", progress=progress)
    stopped_after = time.perf_counter() - t0
    layout = mrtmap.RunLayout(tmp_path / "out")
    # It stopped before segmentation: no scene, no map, no report; no call after the interrupt.
    assert not any("segment" in c or "mapping" in c for c in calls), calls
    assert calls[-1].startswith("fusing")
    for f in (layout.scene_json(), layout.mrt_grid_csv(1.1), layout.report_html()):
        assert not Path(f).exists(), f
    # A whole run takes longer than the stopped one.
    t0 = time.perf_counter()
    mrtmap.run(scans[0], tmp_path / "whole")
    assert stopped_after < time.perf_counter() - t0


def test_ctrl_c_during_a_run_raises_keyboard_interrupt(scans, tmp_path):
    sent = []

    def progress(stage, done, total):
        # SIGINT as Ctrl-C gives it, once, from the pipeline's thread: the main thread must
        # notice it while it waits.
        if not sent:
            sent.append(stage)
            _thread.interrupt_main()

    with pytest.raises(KeyboardInterrupt):
        mrtmap.run(scans[1], tmp_path / "out", progress=progress)
    assert sent
    assert not (tmp_path / "out" / "report.html").exists()


@pytest.mark.parametrize("stage", ["fusing", "segmenting", "mapping MRT", "comfort"])
def test_ctrl_c_stops_a_run_within_a_second_in_every_stage(scans, tmp_path, stage):
    """Issue 63: Ctrl-C is looked at inside every long stage (fusion's frames, segmentation's
    steps, a map's and the comfort maps' nodes), not only between stages: the run stops within a
    second of it, whichever stage it falls in, and what was finished is reused."""
    sent = []

    def progress(name, done, total):
        if not sent and stage in name:
            sent.append(time.perf_counter())
            _thread.interrupt_main()

    out = tmp_path / "out"
    config = {"map": {"quantities": ["mrt", "mrt_seated"], "grid": [20, 20]}}
    with pytest.raises(KeyboardInterrupt):
        mrtmap.run(scans[2], out, config=config, progress=progress)
    assert sent, f"no stage named {stage!r}"
    took = time.perf_counter() - sent[0]
    assert took < 1.0, f"stopped {took:.2f} s after Ctrl-C in {stage}"
    assert not (out / "report.html").exists()
    # The run folder is resumable: the next run finishes it.
    done = mrtmap.run(scans[2], out, config=config)
    assert (out / "report.html").exists() and done.maps
    if stage != "fusing":
        assert any(s["skipped"] for s in done.stages), done.stages


# ---- 4. typed keywords ----

def test_settings_are_typed_keywords():
    s = mrtmap.Scene.example()
    for f in (s.mrt, s.person, s.plane_radiant, s.map, mrtmap.run):
        kinds = {p.kind for p in inspect.signature(f).parameters.values()}
        assert inspect.Parameter.VAR_KEYWORD not in kinds, f
    assert {"height", "grid", "margin", "method", "rays", "seed"} <= set(
        inspect.signature(s.map).parameters)
    with pytest.raises(TypeError, match="'hight'"):
        s.map(hight=1.1)
    with pytest.raises(TypeError, match="'rayz'"):
        s.mrt([[2, 1.5, 1.1]], rayz=100)
    with pytest.raises(ValueError, match=r"grid \(-3, 4\) must have at least 1 node each way"):
        s.map(grid=(-3, 4))
    with pytest.raises(TypeError, match="grid must be two whole node counts"):
        s.map(grid=(2.5, 4))


def test_numpy_scalars_are_numbers():
    s = mrtmap.Scene.example()
    plain = s.map(height=1.1, grid=(6, 5), margin=0.2)
    numpy = s.map(height=np.float64(1.1), grid=(np.int64(6), np.int32(5)), margin=np.float32(0.2))
    np.testing.assert_allclose(numpy.mrt_c, plain.mrt_c, rtol=0, atol=1e-6)  # float32's margin
    a = s.mrt([[2, 1.5, 1.1]], method="montecarlo", rays=2000, seed=3)
    b = s.mrt([[2, 1.5, 1.1]], method="montecarlo", rays=np.int64(2000), seed=np.uint64(3),
              placement_std_m=np.float64(0.0))
    assert a.mrt_c[0] == b.mrt_c[0]
    p = s.person([[2, 1.5, 0.6]], facing_deg=np.float64(90))
    assert p.mrt_c[0] == s.person([[2, 1.5, 0.6]], facing_deg=90).mrt_c[0]


# ---- 5. Python's exception kinds ----

def test_missing_files_are_file_not_found_errors(scans, tmp_path):
    missing = tmp_path / "missing.json"
    for call in (lambda: mrtmap.Scene.load(missing),
                 lambda: mrtmap.Scene.load(scans[0], temperatures=tmp_path / "t.csv"),
                 lambda: mrtmap.run(tmp_path / "no-such-recording", tmp_path / "out"),
                 lambda: mrtmap.run(scans[0], tmp_path / "out", tmp_path / "project.toml")):
        with pytest.raises(FileNotFoundError) as e:
            call()
        assert isinstance(e.value, mrtmap.MrtmapError)
        assert "does not exist" in str(e.value)


def test_wrong_argument_types_are_type_errors(tmp_path):
    s = mrtmap.Scene.example()
    for call, words in (
        (lambda: mrtmap.Scene.load(123), "path must be a path"),
        (lambda: mrtmap.run(123, tmp_path / "out"), "recording must be a path"),
        (lambda: mrtmap.run(tmp_path, tmp_path / "out", 42), "config must be a path"),
        (lambda: mrtmap.run(tmp_path, tmp_path / "out", progress="yes"), "progress must be"),
        (lambda: mrtmap.Scene.from_json(b"{}"), "scene.json's text"),
        (lambda: s.mrt([["a", 1, 1]]), "points must be numbers"),
        (lambda: s.map(height="high"), "height"),
    ):
        with pytest.raises(TypeError, match=words):
            call()


# ---- 7. results cross as Python objects ----

def test_native_results_are_dicts_not_json_text():
    native = mrtmap.Scene.example()._scene
    m = native.map(1.1, 4, 3, 0.1)
    assert isinstance(m, dict) and isinstance(m["summary"], dict) and isinstance(m["axes"], dict)
    assert m["mrt_c"].shape == (3, 4) and m["summary"]["nodes"] == np.isfinite(m["mrt_c"]).sum()
    pl = native.plane_radiant(np.array([[2.0, 1.5, 1.1]]))
    assert pl["faces"] == ("up", "down", "+x", "-x", "+y", "-y")
    assert isinstance(pl["verdicts"][0]["vertical"], dict)
    assert not any(isinstance(v, str) and v.lstrip().startswith(("{", "[")) for v in m.values())
    assert json.loads(json.dumps(m["summary"])) == m["summary"]  # plain data
