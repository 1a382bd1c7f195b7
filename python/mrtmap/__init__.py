"""mrtmap: mean radiant temperature (MRT) maps of rooms, and the comfort formulas, for Python.

The same library as the ``mrtmap`` command line (which this package also installs), with numpy
arrays in and out:

- :class:`Scene` — a radiant scene (``scene.json``, its text or dict, or the built-in example
  office): MRT at points (:meth:`Scene.mrt`), a person's MRT (:meth:`Scene.person`), plane
  radiant temperatures (:meth:`Scene.plane_radiant`) and maps (:meth:`Scene.map`); a copy with one
  surface at another temperature (:meth:`Scene.with_surface_temperature`); picklable.
- :func:`run` — the whole pipeline on a recording, as ``mrtmap run`` (Ctrl-C stops it);
  :class:`RunLayout` — where each file of its output folder is (``RunLayout(out).scene_json()``;
  docs/run-folder.md).
- :func:`survey` — many recordings as independent tasks on a Dask cluster, one table.
- :func:`pmv_ppd_iso`, :func:`operative_tmp`, :func:`mean_radiant_tmp`, :func:`v_relative`,
  :func:`solar_gain` (the sun on a person, SolarCal) and :func:`f_svv` — vectorised with numpy
  broadcasting, named and unitised as pythermalcomfort's; NaN where an element's inputs are NaN
  or refused, never an error for one element.

Errors are :class:`MrtmapError` (a ``ValueError``) carrying the message the command line prints;
a missing file is :class:`MrtmapFileNotFoundError` (also a ``FileNotFoundError``); an argument of
the wrong type is a ``TypeError``. Temperatures are °C, lengths metres, air speeds m/s, standard
errors K; names end in their unit as the files' columns do (``mrt_c``, ``std_error_k``).
"""

from __future__ import annotations

import json
import operator
import os
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Optional, Sequence, Tuple, Union

import numpy as np

from . import _mrtmap
from ._mrtmap import MrtmapError, MrtmapFileNotFoundError, RunLayout

__version__ = _mrtmap.__version__

__all__ = [
    "MrtmapError",
    "MrtmapFileNotFoundError",
    "Scene",
    "MrtResult",
    "PlaneRadiant",
    "MrtMap",
    "RunResult",
    "RunLayout",
    "run",
    "survey",
    "pmv_ppd_iso",
    "PMVPPD",
    "operative_tmp",
    "mean_radiant_tmp",
    "mrt_from_globe",
    "v_relative",
    "solar_gain",
    "SolarGain",
    "f_svv",
]

PathLike = Union[str, "os.PathLike[str]"]


def _path(p: Any, what: str) -> str:
    """``p`` as a path string; TypeError naming ``what`` when it is not a str or PathLike."""
    try:
        return os.fspath(p)
    except TypeError:
        raise TypeError(
            f"{what} must be a path (str or os.PathLike); got {type(p).__name__} {p!r}"
        ) from None


def _points(points: Any) -> np.ndarray:
    try:
        a = np.asarray(points, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise TypeError(f"points must be numbers: an (N, 3) array of x, y, z in metres ({e})") from None
    if a.ndim == 1 and a.shape == (3,):
        a = a.reshape(1, 3)
    if a.ndim != 2 or a.shape[1] != 3:
        raise MrtmapError(f"points must be an (N, 3) array of x, y, z in metres; got shape {a.shape}")
    return np.ascontiguousarray(a)


def _grid(grid: Any) -> Tuple[int, int]:
    """(nx, ny) as two ints (numpy's integers too); TypeError for anything else."""
    try:
        nx, ny = grid
        return operator.index(nx), operator.index(ny)
    except (TypeError, ValueError):
        raise TypeError(f"grid must be two whole node counts (nx, ny); got {grid!r}") from None


@dataclass(frozen=True)
class MrtResult:
    """MRT at points: ``mrt_c`` (°C) and ``std_error_k`` (K), one per point, in the points' order.

    Unpacks as ``mrt_c, std_error_k = scene.mrt(points)``.
    """

    points: np.ndarray
    mrt_c: np.ndarray
    std_error_k: np.ndarray
    view_factor_sum: Optional[np.ndarray] = None

    def __iter__(self):
        return iter((self.mrt_c, self.std_error_k))

    def __len__(self) -> int:
        return len(self.mrt_c)

    def __str__(self) -> str:
        rows = [
            f"point ({p[0]:.3f}, {p[1]:.3f}, {p[2]:.3f}): MRT {t:.2f} °C ± {s:.3f} K"
            for p, t, s in zip(self.points[:10], self.mrt_c[:10], self.std_error_k[:10])
        ]
        if len(self.mrt_c) > 10:
            rows.append(f"… and {len(self.mrt_c) - 10} more points")
        return "\n".join(rows)


@dataclass(frozen=True)
class PlaneRadiant:
    """Plane radiant temperatures of a small element's six faces at each point.

    ``t_pr_c`` (°C) and ``std_error_k`` (K) are (N, 6), faces in the order of ``faces``; the
    asymmetries (K) and ISO 7730's verdicts are per point.
    """

    faces: tuple
    t_pr_c: np.ndarray
    std_error_k: np.ndarray
    vertical_asymmetry_k: np.ndarray
    horizontal_asymmetry_k: np.ndarray
    horizontal_warm_azimuth_deg: np.ndarray
    verdicts: list


@dataclass(frozen=True)
class MrtMap:
    """An MRT map at a height: ``mrt_c`` (°C) and ``std_error_k`` (K) are (ny, nx) grids over
    ``u_m`` (nx values, along the map's u axis) and ``v_m`` (ny values, along v), NaN where the
    grid has no node (outside the floor, inside furniture; see ``refused``). ``xyz`` holds each
    node's point in the scene's frame. ``summary`` has the extremes, mean, largest ± and its
    parts. The names are mrt_grid.csv's columns.
    """

    height_m: float
    u_m: np.ndarray
    v_m: np.ndarray
    mrt_c: np.ndarray
    std_error_k: np.ndarray
    xyz: np.ndarray
    axes: dict
    refused: list
    summary: Optional[dict]
    method: str
    compute_secs: float

    def to_xarray_dict(self) -> dict:
        """A dict for ``xarray.Dataset.from_dict``: variables ``mrt_c`` and ``std_error_k`` over
        dims ``(v_m, u_m)`` with units, the height and method as attributes."""
        return {
            "coords": {
                "v_m": {"dims": ("v_m",), "data": self.v_m, "attrs": {"units": "m", "axis": "map v"}},
                "u_m": {"dims": ("u_m",), "data": self.u_m, "attrs": {"units": "m", "axis": "map u"}},
            },
            "attrs": {"height_m": self.height_m, "method": self.method},
            "dims": ("v_m", "u_m"),
            "data_vars": {
                "mrt_c": {"dims": ("v_m", "u_m"), "data": self.mrt_c,
                          "attrs": {"units": "degC", "long_name": "mean radiant temperature"}},
                "std_error_k": {"dims": ("v_m", "u_m"), "data": self.std_error_k,
                                "attrs": {"units": "K", "long_name": "standard error of the MRT"}},
            },
        }

    def to_dataframe(self):
        """One row per node with a value, with mrt_grid.csv's columns and names: x, y, z (the
        scene's frame), mrt_c, std_error_k, i, j (column and row), u_m, v_m (the map's axes)."""
        import pandas as pd

        jj, ii = np.nonzero(np.isfinite(self.mrt_c))
        return pd.DataFrame({
            "x": self.xyz[jj, ii, 0], "y": self.xyz[jj, ii, 1], "z": self.xyz[jj, ii, 2],
            "mrt_c": self.mrt_c[jj, ii], "std_error_k": self.std_error_k[jj, ii],
            "i": ii, "j": jj, "u_m": self.u_m[ii], "v_m": self.v_m[jj],
        })


class Scene:
    """A radiant scene: the room's surfaces with their temperatures (``scene.json``).

    Points are in the scene's frame (for a scanned room, its room frame: x, y along the floor from
    the origin corner, z above the floor), or the scan's world frame with ``frame="scan"``.
    View-factor settings are keywords, as ``[mrt]`` in project.toml: ``method`` ("auto",
    "exact", "montecarlo"), ``rays``, ``seed``, ``directions`` ("fibonacci", "random"),
    ``replicates``, ``allow_open``, ``placement_std_m``.
    A point outside the room is refused with :class:`MrtmapError`. Scenes pickle (as their
    JSON), so Dask and multiprocessing can ship them to other processes.
    """

    def __init__(self, native: "_mrtmap.Scene"):
        if not isinstance(native, _mrtmap.Scene):
            raise TypeError(
                "Scene() wraps the native scene: use Scene.load(path), Scene.from_json(text), "
                "Scene.from_dict(d) or Scene.example()"
            )
        self._scene = native

    def __reduce__(self):
        return (Scene, (self._scene,))

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Scene) and self.to_json() == other.to_json()

    __hash__ = None  # type: ignore[assignment]

    @classmethod
    def load(
        cls,
        path: PathLike,
        temperatures: Optional[PathLike] = None,
        room: Optional[str] = None,
    ) -> "Scene":
        """Reads ``scene.json`` (format mrtmap-scene/1), or a Honeybee model (``.hbjson``) with
        its faces' temperatures from ``temperatures`` (a CSV of ``identifier,temperature_c``; a
        ``*`` row for the rest) or from its own mrtmap ``user_data``; ``room`` picks one of
        several rooms. A missing file raises :class:`MrtmapFileNotFoundError`."""
        t = None if temperatures is None else _path(temperatures, "temperatures")
        return cls(_mrtmap.Scene.load(_path(path, "path"), t, room))

    @classmethod
    def from_json(cls, text: str, source: Optional[str] = None) -> "Scene":
        """A scene from scene.json's text (format mrtmap-scene/1), checked as a file is;
        ``source`` says where it came from in messages."""
        if not isinstance(text, str):
            raise TypeError(f"text must be scene.json's text (str); got {type(text).__name__}")
        return cls(_mrtmap.Scene(text, source))

    @classmethod
    def from_dict(cls, scene: dict, source: Optional[str] = None) -> "Scene":
        """A scene from scene.json's content as a dict (``json.load`` of the file)."""
        if not isinstance(scene, dict):
            raise TypeError(f"scene must be a dict of scene.json's content; got {type(scene).__name__}")
        return cls.from_json(json.dumps(scene, default=_plain), source)

    @classmethod
    def example(cls) -> "Scene":
        """The built-in example office (a cold window, recessed lights), as ``mrtmap mrt``
        without ``--scene``."""
        return cls(_mrtmap.Scene.example())

    @property
    def source(self) -> str:
        """Where the scene came from."""
        return self._scene.source

    def ids(self) -> list:
        """Every surface's, feature's and occluder's id (each surface followed by its features)."""
        return self._scene.ids()

    def to_json(self) -> str:
        """The scene as scene.json text."""
        return self._scene.to_json()

    def to_dict(self) -> dict:
        """The scene as scene.json's content (a dict)."""
        return json.loads(self._scene.to_json())

    def with_surface_temperature(self, id: str, temperature_c: float) -> "Scene":
        """A copy with the surface, feature or occluder ``id`` at ``temperature_c`` (°C): to ask
        "what if the window were warmer" and recompute. The surface's temperature raster, if it
        had one, gives way to the one value. An unknown id raises, listing the ids."""
        return Scene(self._scene.with_surface_temperature(id, temperature_c))

    def export(self, path: PathLike, to: Optional[str] = None, name: str = "room") -> int:
        """Writes the scene for another tool, as ``mrtmap export`` does: ``"hbjson"`` (Honeybee),
        ``"gbxml"``, ``"gltf"`` (binary .glb) or ``"rad"`` (Radiance), by default from the
        path's extension (.hbjson, .xml, .glb, .rad). Returns the bytes written."""
        return self._scene.export(_path(path, "path"), to, name)

    def __repr__(self) -> str:
        return f"Scene({self.source!r})"

    def mrt(
        self,
        points: Any,
        *,
        frame: str = "room",
        method: Optional[str] = None,
        rays: Optional[int] = None,
        seed: Optional[int] = None,
        directions: Optional[str] = None,
        replicates: Optional[int] = None,
        allow_open: Optional[bool] = None,
        placement_std_m: Optional[float] = None,
    ) -> MrtResult:
        """MRT (°C) of a small sphere at each of ``points`` ((N, 3) or (3,), metres) and its
        standard error (K), as ``mrtmap mrt --at``. Runs in parallel without the GIL."""
        p = _points(points)
        d = self._scene.mrt(p, frame=frame, method=method, rays=rays, seed=seed,
                            directions=directions, replicates=replicates, allow_open=allow_open,
                            placement_std_m=placement_std_m)
        return MrtResult(points=p, **d)

    def person(
        self,
        points: Any,
        posture: str = "seated",
        facing_deg: Optional[float] = None,
        *,
        frame: str = "room",
        method: Optional[str] = None,
        rays: Optional[int] = None,
        seed: Optional[int] = None,
        directions: Optional[str] = None,
        replicates: Optional[int] = None,
        allow_open: Optional[bool] = None,
        placement_std_m: Optional[float] = None,
    ) -> MrtResult:
        """A person's MRT (°C) at body centres ``points`` (0.6 m above the floor seated, 1.0 m
        standing) from the projected-area factors of a seated or standing body, facing
        ``facing_deg`` (from +x towards +y) or any way (None), as ``mrtmap mrt --person``."""
        p = _points(points)
        d = self._scene.person(p, posture, facing_deg, frame=frame, method=method, rays=rays,
                               seed=seed, directions=directions, replicates=replicates,
                               allow_open=allow_open, placement_std_m=placement_std_m)
        return MrtResult(points=p, **d)

    def plane_radiant(
        self,
        points: Any,
        *,
        frame: str = "room",
        method: Optional[str] = None,
        rays: Optional[int] = None,
        seed: Optional[int] = None,
        directions: Optional[str] = None,
        replicates: Optional[int] = None,
        allow_open: Optional[bool] = None,
        placement_std_m: Optional[float] = None,
    ) -> PlaneRadiant:
        """The six plane radiant temperatures (°C) and the radiant asymmetries with ISO 7730's
        verdicts at each point, as ``mrtmap mrt --plane``."""
        d = self._scene.plane_radiant(
            _points(points), frame=frame, method=method, rays=rays, seed=seed,
            directions=directions, replicates=replicates, allow_open=allow_open,
            placement_std_m=placement_std_m)
        return PlaneRadiant(**d)

    def map(
        self,
        height: float = 1.1,
        grid: Sequence[int] = (20, 20),
        margin: float = 0.1,
        *,
        method: Optional[str] = None,
        rays: Optional[int] = None,
        seed: Optional[int] = None,
        directions: Optional[str] = None,
        replicates: Optional[int] = None,
        allow_open: Optional[bool] = None,
        placement_std_m: Optional[float] = None,
    ) -> MrtMap:
        """The MRT over a ``grid`` = (nx, ny) of the floor's bounding rectangle at ``height`` (m)
        above the floor, ``margin`` (m) from the walls: the values of ``mrtmap map``'s
        mrt_grid.csv, as arrays (nothing is written)."""
        nx, ny = _grid(grid)
        d = self._scene.map(height, nx, ny, margin, method=method, rays=rays, seed=seed,
                            directions=directions, replicates=replicates, allow_open=allow_open,
                            placement_std_m=placement_std_m)
        return MrtMap(height_m=float(height), refused=[tuple(r) for r in d.pop("refused")], **d)


@dataclass(frozen=True)
class RunResult:
    """What :func:`run` did: the output folder's main files, the maps' figures, the comfort
    shares, the temperatures' level, per-stage timings and warnings. ``str()`` gives what
    ``mrtmap run`` prints."""

    recording: Path
    out: Path
    lines: list
    seconds: float
    stages: list
    maps: list
    comfort: Optional[dict]
    level: Optional[dict]
    warnings: list
    surfaces: int
    features: int
    paths: dict = field(default_factory=dict)

    def __str__(self) -> str:
        return "\n".join(self.lines)

    @property
    def timings(self) -> dict:
        """Seconds per stage (of the run that made the stage's outputs)."""
        return {s["stage"]: s["secs"] for s in self.stages}


def run(
    recording: PathLike,
    out: PathLike,
    config: Union[None, PathLike, dict] = None,
    *,
    force: bool = False,
    progress: Optional[Callable[[str, int, int], None]] = None,
) -> RunResult:
    """The whole pipeline on ``recording`` (a recording folder, a ROS 1/2 bag, an MCAP file or an
    RTAB-Map database) into ``out``, as ``mrtmap run``: fuse, segment, MRT maps, report.html.

    ``config`` is None (the defaults), a path to project.toml, or a dict of its sections (e.g.
    ``{"map": {"grid": [10, 10]}, "air": {"temperature_c": 21.0}}``). ``progress`` is called
    as ``progress(stage, done, total)`` from the pipeline's threads. Stages whose inputs have not
    changed are reused unless ``force``. Ctrl-C (or a ``KeyboardInterrupt`` raised by
    ``progress``) stops the run before its next stage and raises ``KeyboardInterrupt``; the
    stages done are kept and reused by the next run.
    """
    rec = _path(recording, "recording")
    o = _path(out, "out")
    if config is not None and not isinstance(config, dict):
        config = _path(config, "config")
    if progress is not None and not callable(progress):
        raise TypeError(f"progress must be a callable (stage, done, total); got {progress!r}")
    d = _mrtmap.run(rec, o, config, force, progress)
    return RunResult(recording=Path(recording), out=Path(out), **d)


def survey(recordings, out, client=None, config=None, n_workers=None, progress=None):
    """Maps each of ``recordings`` into ``out/<room>`` as an independent task on a Dask cluster
    and returns one table (a pandas DataFrame, also written to ``out/survey.csv``).

    Without ``client`` a ``dask.distributed.LocalCluster`` is started (``n_workers`` processes)
    and closed; pass ``Client("tcp://scheduler:8786")`` to use a running cluster. A room that
    fails is a row with status "failed" and its error; the others go on. ``progress``: True
    prints a line per room as it finishes; a callable is called as ``progress(done, total,
    row)``. Needs ``pip install mrtmap[dask]``. See ``mrtmap._survey.survey`` for the columns.
    """
    from ._survey import survey as _survey

    return _survey(recordings, out, client=client, config=config, n_workers=n_workers,
                   progress=progress)


# ---- comfort formulas, vectorised, named and unitised as pythermalcomfort's ----

def _plain(x):
    """numpy's arrays and scalars as Python's lists and numbers, for ``json.dumps`` (a scene dict
    built with numpy raised "Object of type ndarray is not JSON serializable")."""
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, np.generic):
        return x.item()
    raise TypeError(f"{type(x).__name__} is not a number, list or text a scene can hold")


def _broadcast(*xs):
    """The inputs' broadcast shape and each input as a contiguous array in its own shape: the
    native side reads them in the broadcast shape where they lie (a column against a row is not
    copied to the grid's size)."""
    arrays = [np.asarray(x, dtype=np.float64) for x in xs]
    # (ascontiguousarray would make a scalar's 0-d array 1-d; a 0-d array is contiguous.)
    arrays = [a if a.flags.c_contiguous else np.ascontiguousarray(a) for a in arrays]
    shape = np.broadcast_shapes(*(a.shape for a in arrays))
    return shape, [list(shape)] + arrays


def _shaped(a: np.ndarray, shape: tuple):
    """The flat result in the inputs' broadcast shape; a Python float for scalar inputs."""
    return float(a[0]) if shape == () else a.reshape(shape)


def _warn_refused(what: str, count: int, first: Optional[str]) -> None:
    """A RuntimeWarning (as numpy's "invalid value") when a formula refused elements: NaN there."""
    if count:
        warnings.warn(
            f"{what}: {count} element{'s' if count > 1 else ''} outside what the formula accepts "
            f"gave NaN (the first, {first})",
            RuntimeWarning,
            stacklevel=3,
        )


def _check_units(units: str) -> None:
    if str(units).upper() != "SI":
        raise MrtmapError(f"units {units!r}: mrtmap takes SI units only (°C, m/s)")


# pythermalcomfort's thermal sensation vote bins: PMV below each edge (NaN at 10 and above).
_TSV_EDGES = np.array([-2.5, -1.5, -0.5, 0.5, 1.5, 2.5, 10.0])
_TSV_LABELS = np.array(["Cold", "Cool", "Slightly Cool", "Neutral", "Slightly Warm", "Warm", "Hot",
                        np.nan], dtype=object)


def _tsv(pmv):
    return _TSV_LABELS[np.digitize(pmv, _TSV_EDGES, right=False)]


@dataclass(frozen=True)
class PMVPPD:
    """PMV and PPD (%), with pythermalcomfort's fields: floats for scalar inputs, else arrays of
    the inputs' broadcast shape; NaN where an element is outside ISO 7730's ranges (with
    ``limit_inputs``) or its inputs are NaN or refused. ``tsv`` is the thermal sensation vote the
    PMV predicts, as pythermalcomfort's: "Cold" below −2.5, "Cool" below −1.5, "Slightly Cool"
    below −0.5, "Neutral" below 0.5, "Slightly Warm" below 1.5, "Warm" below 2.5, "Hot" below 10,
    NaN otherwise (a str, or an object array of them; made when first read)."""

    pmv: Any
    ppd: Any

    @property
    def tsv(self):
        return _tsv(self.pmv)


def pmv_ppd_iso(
    tdb, tr, vr, rh, met, clo, wme=0, model: str = "7730-2025", units: str = "SI",
    limit_inputs: bool = True, round_output: bool = True,
) -> PMVPPD:
    """PMV and PPD by ISO 7730 (Fanger) — pythermalcomfort's ``pmv_ppd_iso``, same arguments.

    tdb air temperature (°C), tr mean radiant temperature (°C), vr relative air speed (m/s; see
    :func:`v_relative`), rh relative humidity (%), met metabolic rate (met), clo clothing (clo),
    wme external work (met). ``model`` "7730-2025" or "7730-2005" picks the edition's annex D
    code (they differ in the clothing temperature's first guess, up to 0.002 in PMV;
    pythermalcomfort 4 uses 2025's for both). With ``limit_inputs`` the results are NaN outside
    ISO 7730's ranges (10–30 °C tdb, 10–40 °C tr, 0–1 m/s, 0.8–4 met, 0–2 clo, vapour pressure up
    to 2700 Pa, |PMV| ≤ 2); without, they are computed wherever the formula accepts the inputs
    (NaN elsewhere, e.g. a humidity of 150 %, with a RuntimeWarning naming the first such
    element). A NaN input gives NaN at its element. ``round_output`` rounds PMV to 2 and PPD to 1
    decimal. Inputs broadcast like numpy's; the work runs in parallel without the GIL.
    """
    _check_units(units)
    editions = {"7730-2025": 2025, "7730-2005": 2005}
    if str(model).lower() not in editions:
        raise MrtmapError(f"model {model!r} is neither '7730-2025' nor '7730-2005'")
    shape, flat = _broadcast(tdb, tr, vr, rh, met, clo, wme)
    pmv, ppd, count, first = _mrtmap.pmv_ppd(
        *flat, editions[str(model).lower()], bool(limit_inputs), bool(round_output)
    )
    if not limit_inputs:
        _warn_refused("pmv_ppd_iso", count, first)
    return PMVPPD(pmv=_shaped(pmv, shape), ppd=_shaped(ppd, shape))


def operative_tmp(tdb, tr, v, standard: str = "ISO"):
    """Operative temperature (°C) — pythermalcomfort's ``operative_tmp``: ISO 7726's
    (tdb √(10 v) + tr) / (1 + √(10 v)), or ASHRAE 55's weights by air speed ``v`` (m/s); a float
    for scalar inputs, NaN where an input is NaN or refused (with a RuntimeWarning)."""
    s = str(standard).lower()
    if s not in ("iso", "ashrae"):
        raise MrtmapError(f"standard {standard!r} is neither 'ISO' nor 'ASHRAE'")
    shape, flat = _broadcast(tdb, tr, v)
    out, count, first = _mrtmap.operative(*flat, s == "ashrae")
    _warn_refused("operative_tmp", count, first)
    return _shaped(out, shape)


def mean_radiant_tmp(tg, tdb, v, d=0.15, emissivity=0.95, standard: str = "Mixed Convection"):
    """MRT (°C) from a globe thermometer's reading — pythermalcomfort's ``mean_radiant_tmp``:
    globe temperature tg (°C), air temperature tdb (°C), air speed v (m/s), globe diameter d (m),
    emissivity; ``standard`` "ISO" (ISO 7726, the larger of natural and forced convection) or
    "Mixed Convection" (Teitelbaum et al. 2022; NaN outside 40–150 mm globes). A float for scalar
    inputs; NaN where an input is NaN or refused (with a RuntimeWarning)."""
    s = str(standard).lower()
    if s not in ("iso", "mixed convection"):
        raise MrtmapError(f"standard {standard!r} is neither 'ISO' nor 'Mixed Convection'")
    shape, flat = _broadcast(tg, tdb, v, d, emissivity)
    out, count, first = _mrtmap.mrt_from_globe(*flat, s == "mixed convection")
    _warn_refused("mean_radiant_tmp", count, first)
    return _shaped(out, shape)


mrt_from_globe = mean_radiant_tmp


def v_relative(v, met):
    """The relative air speed ISO 7730 uses (m/s): v + 0.3 (met − 1) above 1 met —
    pythermalcomfort's ``v_relative``; a float for scalar inputs."""
    v, met = np.asarray(v, dtype=np.float64), np.asarray(met, dtype=np.float64)
    out = np.where(met > 1, np.round(v + 0.3 * (met - 1), 3), v)
    return float(out) if out.ndim == 0 else out


@dataclass(frozen=True)
class SolarGain:
    """The sun's effective radiant field ``erf`` (W/m²) and the rise ``delta_mrt`` (K) of the mean
    radiant temperature it causes (pythermalcomfort's fields): floats for scalar inputs, else
    arrays of the inputs' broadcast shape."""

    erf: Any
    delta_mrt: Any


def solar_gain(
    sol_altitude, sharp, sol_radiation_dir, sol_transmittance, f_svv, f_bes, asw=0.7,
    posture: str = "sitting", floor_reflectance=0.6, round_output: bool = True,
) -> SolarGain:
    """The sun on a person behind glass: SolarCal (ASHRAE 55-2023 Appendix C) —
    pythermalcomfort's ``models.solar_gain``, same arguments and results.

    sol_altitude solar altitude (deg, 0–90), sharp the sun's horizontal angle from the person's
    front (deg, 0–180), sol_radiation_dir direct normal irradiance (W/m²), sol_transmittance the
    glazing's total solar transmittance (0–1), f_svv the sky-vault view fraction (0–1, see
    :func:`f_svv`), f_bes the fraction of the body in the beam (0–1), asw short-wave
    absorptivity, posture "sitting", "standing" or "supine", floor_reflectance (0–1).
    ``round_output`` rounds both to 1 decimal. As pythermalcomfort, an altitude or SHARP outside
    its range gives NaN; any other input out of its range gives NaN with a RuntimeWarning naming
    the first such element. ΔMRT = ERF / (f_eff · 6 W/m²K), to add to the long-wave MRT.
    """
    shape, flat = _broadcast(sol_altitude, sharp, sol_radiation_dir, sol_transmittance, f_svv,
                             f_bes, asw, floor_reflectance)
    erf, dmrt, count, first = _mrtmap.solar_gain(*flat, str(posture))
    _warn_refused("solar_gain", count, first)
    if round_output:
        erf, dmrt = np.round(erf, 1), np.round(dmrt, 1)
    return SolarGain(erf=_shaped(erf, shape), delta_mrt=_shaped(dmrt, shape))


def f_svv(w, h, d):
    """The sky-vault view fraction of a window ``w`` × ``h`` (m) straight ahead of a person at
    distance ``d`` (m): atan(h/2d)° · atan(w/2d)° / 16200 — pythermalcomfort's
    ``environment.f_svv`` (the CBE Comfort Tool's form); broadcasts, a float for scalars, NaN
    where refused (with a RuntimeWarning)."""
    shape, flat = _broadcast(w, h, d)
    out, count, first = _mrtmap.f_svv(*flat)
    _warn_refused("f_svv", count, first)
    return _shaped(out, shape)
