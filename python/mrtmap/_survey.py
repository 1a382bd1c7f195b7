"""Surveys of many rooms (`mrtmap.survey`): each recording mapped as an independent task on a
Dask cluster.

    import mrtmap
    table = mrtmap.survey(["scans/room-101", "scans/room-102", "scans/room-103"], "survey-out")
    print(table)

Without ``client`` the survey starts a ``dask.distributed.LocalCluster`` on this machine and
closes it afterwards; pass a ``Client`` to use a running cluster, e.g.
``Client("tcp://scheduler:8786")`` (every worker needs ``pip install mrtmap`` and read access to
the recordings, and ``out`` must be a path the workers can write, such as a shared file system).
Dask schedules the work; a room that fails is a row with ``status`` "failed" and its error, and the
other rooms go on. The table is also written to ``out/survey.csv`` (whole or not at all).
"""

from __future__ import annotations

import os
import sys
import traceback
from pathlib import Path
from typing import Any, Callable, Iterable, Optional, Union

COLUMNS = [
    "room", "recording", "status", "error", "height_m", "nodes", "mrt_min_c", "mrt_mean_c",
    "mrt_max_c", "max_std_error_k", "share_a", "share_b", "share_c", "share_outside",
    "surfaces", "features", "warnings", "seconds", "out",
]


def _row(recording: str, out: str, **values) -> dict:
    """A table row: every column, None where not given."""
    row = {c: None for c in COLUMNS}
    row.update(room=Path(recording).name, recording=str(recording), out=str(out), **values)
    return row


def map_room(recording: str, out: str, config: Any = None) -> dict:
    """One room: ``mrtmap.run`` into ``out``, summarised as one row of the survey table. Never
    raises: a failure is a row with status "failed" and the error's message."""
    import mrtmap

    try:
        r = mrtmap.run(recording, out, config)
    except Exception as e:  # noqa: BLE001 — one room's failure is data, not the survey's end
        msg = str(e) if isinstance(e, mrtmap.MrtmapError) else "".join(
            traceback.format_exception_only(type(e), e)).strip()
        return _row(recording, out, status="failed", error=msg)
    m = r.maps[0] if r.maps else {}
    row = _row(
        recording, out, status="ok", error="", height_m=m.get("height_m"), nodes=m.get("nodes"),
        mrt_min_c=m.get("min_c"), mrt_mean_c=m.get("mean_c"), mrt_max_c=m.get("max_c"),
        max_std_error_k=m.get("max_std_error_k"), surfaces=r.surfaces, features=r.features,
        warnings=" | ".join(r.warnings), seconds=r.seconds,
    )
    shares = (r.comfort or {}).get("pmv_category_share")
    if shares:
        row.update(share_a=shares[0], share_b=shares[1], share_c=shares[2], share_outside=shares[3])
    return row


def _print_progress(done: int, total: int, row: dict) -> None:
    print(f"survey: {row['room']} {row['status']} ({done} of {total} rooms)", file=sys.stderr,
          flush=True)


def _write_csv_atomically(df, path: Path) -> None:
    tmp = path.with_name(path.name + ".tmp")
    df.to_csv(tmp, index=False)
    os.replace(tmp, path)


def survey(
    recordings: Iterable[Union[str, os.PathLike]],
    out: Union[str, os.PathLike],
    client: Optional[Any] = None,
    config: Any = None,
    n_workers: Optional[int] = None,
    progress: Union[None, bool, Callable[[int, int, dict], None]] = None,
):
    """Maps each of ``recordings`` into ``out/<room>`` as an independent Dask task and returns
    the table (a pandas DataFrame, one row per recording, in their order; also ``out/survey.csv``).

    ``client``: a ``dask.distributed.Client``; without one, a ``LocalCluster`` of ``n_workers``
    processes (default: one per recording up to the CPU count) is started and closed.
    ``config``: as :func:`mrtmap.run`'s (a path to project.toml or a dict), for every room; with
    ``[air] temperature_c`` and ``[map] quantities = ["mrt", "pmv"]`` the table gets the share of
    each room's floor in each ISO 7730 category.
    Columns: room, recording, status ("ok" or "failed"), error, height_m, nodes, mrt_min_c,
    mrt_mean_c, mrt_max_c, max_std_error_k, share_a, share_b, share_c, share_outside, surfaces,
    features, warnings, seconds, out.
    ``progress``: True prints ``survey: room-2 ok (2 of 3 rooms)`` to stderr as each room
    finishes; a callable is called as ``progress(done, total, row)`` (``row`` the room's row of
    the table), in the order the rooms finish.
    """
    import pandas as pd
    from dask.distributed import Client, LocalCluster, as_completed

    if progress is True:
        progress = _print_progress
    elif progress is not None and progress is not False and not callable(progress):
        raise TypeError(f"progress must be None, True or a callable (done, total, row); got {progress!r}")

    recs = [str(r) for r in recordings]
    if not recs:
        raise ValueError("survey: no recordings given")
    names = [Path(r).name for r in recs]
    if len(set(names)) != len(names):
        raise ValueError("survey: two recordings share a folder name; their outputs would collide")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    outs = [str(out / n) for n in names]
    own = client is None
    cluster = None
    if own:
        workers = n_workers or max(1, min(len(recs), os.cpu_count() or 1))
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
    try:
        futures = client.map(map_room, recs, outs, config=config, pure=False)
        index = {f.key: k for k, f in enumerate(futures)}
        rows: list = [None] * len(futures)
        for done, fut in enumerate(as_completed(futures), start=1):
            k = index[fut.key]
            try:
                rows[k] = fut.result()
            except Exception as e:  # noqa: BLE001 — a worker lost mid-task: report the room
                rows[k] = _row(recs[k], outs[k], status="failed",
                               error=f"the task failed on its worker: {e}")
            if progress:
                progress(done, len(futures), rows[k])
    finally:
        if own:
            client.close()
            cluster.close()
    table = pd.DataFrame(rows, columns=COLUMNS)
    _write_csv_atomically(table, out / "survey.csv")
    return table
