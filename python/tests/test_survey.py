"""A survey of three short scans on a LocalCluster, one corrupted on purpose: that one is
reported, the other two are mapped."""

import pandas as pd
import pytest

import mrtmap

pytest.importorskip("dask.distributed")


def test_survey_reports_the_broken_room_and_maps_the_others(scans, tmp_path, fresh_copy):
    rooms = [fresh_copy(s, s.name) for s in scans]
    (rooms[1] / "rig.toml").write_text("[depth]\nwidth = 'wide'\n")  # corrupted
    from dask.distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        seen = []
        table = mrtmap.survey(rooms, tmp_path / "survey", client=client,
                              config={"map": {"grid": [8, 8]}},
                              progress=lambda done, total, row: seen.append((done, total, row)))
    # Progress: one call per room as it finishes, counting up to three.
    assert [(d, t) for d, t, _ in seen] == [(1, 3), (2, 3), (3, 3)]
    assert sorted(r["room"] for _, _, r in seen) == ["room-1", "room-2", "room-3"]
    assert list(table["room"]) == ["room-1", "room-2", "room-3"]
    assert list(table["status"]) == ["ok", "failed", "ok"]
    assert "rig.toml" in table.loc[1, "error"]
    ok = table[table.status == "ok"]
    assert (ok["nodes"] == 64).all()
    assert ((ok["mrt_min_c"] <= ok["mrt_mean_c"]) & (ok["mrt_mean_c"] <= ok["mrt_max_c"])).all()
    assert ok["mrt_mean_c"].between(15, 30).all()
    csv = pd.read_csv(tmp_path / "survey" / "survey.csv")
    assert list(csv["status"]) == ["ok", "failed", "ok"]
    assert (tmp_path / "survey" / "room-3" / "report.html").exists()
    assert not (tmp_path / "survey" / "room-2" / "report.html").exists()


def test_survey_refuses_colliding_names(tmp_path):
    with pytest.raises(ValueError, match="share a folder name"):
        mrtmap.survey([tmp_path / "a" / "scan", tmp_path / "b" / "scan"], tmp_path / "out")
