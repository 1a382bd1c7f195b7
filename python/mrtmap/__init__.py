"""mrtmap: mean radiant temperature (MRT) maps of rooms, and the comfort formulas, for Python.

The same library as the ``mrtmap`` command line (which this package also installs), with numpy
arrays in and out:

- :class:`Scene` — a radiant scene (``scene.json``, or the built-in example office): MRT at
  points (:meth:`Scene.mrt`), a person's MRT (:meth:`Scene.person`), plane radiant temperatures
  (:meth:`Scene.plane_radiant`) and maps (:meth:`Scene.map`).
- :func:`run` — the whole pipeline on a recording, as ``mrtmap run``; :class:`RunLayout` — where
  each file of its output folder is (``RunLayout(out).scene_json()``; docs/run-folder.md).
- :func:`survey` — many recordings as independent tasks on a Dask cluster, one table.
- :func:`pmv_ppd_iso`, :func:`operative_tmp`, :func:`mean_radiant_tmp`, :func:`v_relative`,
  :func:`solar_gain` (the sun on a person, SolarCal) and :func:`f_svv` — vectorised with numpy
  broadcasting, named and unitised as pythermalcomfort's.

Errors are :class:`MrtmapError` (a ``ValueError``) carrying the message the command line prints.
Temperatures are °C, lengths metres, air speeds m/s, standard errors K.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Optional, Sequence, Union

import numpy as np

from . import _mrtmap
from ._mrtmap import MrtmapError, RunLayout

__version__ = _mrtmap.__version__

__all__ = [
    "MrtmapError",
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

PathLike = Union[str, Path]

_MRT_KEYS = ("method", "rays", "seed", "directions", "replicates", "allow_open", "placement_std_m")


def _mrt_json(settings: dict) -> str:
    unknown = sorted(set(settings) - set(_MRT_KEYS))
    if unknown:
        raise MrtmapError(
            f"unknown view-factor setting {unknown[0]!r}: the settings are {', '.join(_MRT_KEYS)}"
        )
    return json.dumps(settings)


def _points(points: Any) -> np.ndarray:
    try:
        a = np.asarray(points, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise MrtmapError(f"points must be numbers: an (N, 3) array of x, y, z in metres ({e})") from None
    if a.ndim == 1 and a.shape == (3,):
        a = a.reshape(1, 3)
    if a.ndim != 2 or a.shape[1] != 3:
        raise MrtmapError(f"points must be an (N, 3) array of x, y, z in metres; got shape {a.shape}")
    return np.ascontiguousarray(a)


@dataclass(frozen=True)
class MrtResult:
    """MRT at points: ``mrt`` (°C) and ``std_error`` (K), one per point, in the points' order.

    Unpacks as ``mrt, std_error = scene.mrt(points)``.
    """

    points: np.ndarray
    mrt: np.ndarray
    std_error: np.ndarray
    view_factor_sum: Optional[np.ndarray] = None

    def __iter__(self):
        return iter((self.mrt, self.std_error))

    def __len__(self) -> int:
        return len(self.mrt)

    def __str__(self) -> str:
        rows = [
            f"point ({p[0]:.3f}, {p[1]:.3f}, {p[2]:.3f}): MRT {t:.2f} °C ± {s:.3f} K"
            for p, t, s in zip(self.points[:10], self.mrt[:10], self.std_error[:10])
        ]
        if len(self.mrt) > 10:
            rows.append(f"… and {len(self.mrt) - 10} more points")
        return "\n".join(rows)


@dataclass(frozen=True)
class PlaneRadiant:
    """Plane radiant temperatures of a small element's six faces at each point.

    ``t_pr`` and ``std_error`` are (N, 6), faces in the order of ``faces``; the asymmetries (K)
    and ISO 7730's verdicts are per point.
    """

    faces: tuple
    t_pr: np.ndarray
    std_error: np.ndarray
    vertical_asymmetry: np.ndarray
    horizontal_asymmetry: np.ndarray
    horizontal_warm_azimuth_deg: np.ndarray
    verdicts: list


@dataclass(frozen=True)
class MrtMap:
    """An MRT map at a height: ``mrt`` and ``std_error`` are (ny, nx) grids over ``x`` (nx
    values, along the map's u axis) and ``y`` (ny values, along v), NaN where the grid has no
    node (outside the floor, inside furniture; see ``refused``). ``xyz`` holds each node's point
    in the scene's frame. ``summary`` has the extremes, mean, largest ± and its parts.
    """

    height: float
    x: np.ndarray
    y: np.ndarray
    mrt: np.ndarray
    std_error: np.ndarray
    xyz: np.ndarray
    axes: dict
    refused: list
    summary: Optional[dict]
    method: str
    compute_secs: float

    def to_xarray_dict(self) -> dict:
        """A dict for ``xarray.Dataset.from_dict``: variables ``mrt`` and ``std_error`` over
        dims ``(y, x)`` with units, the height and method as attributes."""
        return {
            "coords": {
                "y": {"dims": ("y",), "data": self.y, "attrs": {"units": "m", "axis": "map v"}},
                "x": {"dims": ("x",), "data": self.x, "attrs": {"units": "m", "axis": "map u"}},
            },
            "attrs": {"height_m": self.height, "method": self.method},
            "dims": ("y", "x"),
            "data_vars": {
                "mrt": {"dims": ("y", "x"), "data": self.mrt,
                        "attrs": {"units": "degC", "long_name": "mean radiant temperature"}},
                "std_error": {"dims": ("y", "x"), "data": self.std_error,
                              "attrs": {"units": "K", "long_name": "standard error of the MRT"}},
            },
        }

    def to_dataframe(self):
        """One row per node with a value: x, y (map), X, Y, Z (scene), mrt, std_error (pandas)."""
        import pandas as pd

        ok = np.isfinite(self.mrt)
        jj, ii = np.nonzero(ok)
        return pd.DataFrame({
            "x": self.x[ii], "y": self.y[jj],
            "X": self.xyz[jj, ii, 0], "Y": self.xyz[jj, ii, 1], "Z": self.xyz[jj, ii, 2],
            "mrt": self.mrt[jj, ii], "std_error": self.std_error[jj, ii],
        })


class Scene:
    """A radiant scene: the room's surfaces with their temperatures (``scene.json``).

    Points are in the scene's frame (for a scanned room, its room frame: x, y along the floor from
    the origin corner, z above the floor), or the scan's world frame with ``frame="scan"``.
    View-factor settings are keywords, as ``[mrt]`` in project.toml: ``method`` ("auto",
    "exact", "montecarlo"), ``rays``, ``seed``, ``directions`` ("fibonacci", "random"),
    ``replicates``, ``allow_open``, ``placement_std_m``.
    A point outside the room is refused with :class:`MrtmapError`.
    """

    def __init__(self, native: "_mrtmap.Scene"):
        self._scene = native

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
        several rooms."""
        t = None if temperatures is None else str(temperatures)
        return cls(_mrtmap.Scene.load(str(path), t, room))

    @classmethod
    def example(cls) -> "Scene":
        """The built-in example office (a cold window, recessed lights), as ``mrtmap mrt``
        without ``--scene``."""
        return cls(_mrtmap.Scene.example())

    @property
    def source(self) -> str:
        """Where the scene came from."""
        return self._scene.source

    def to_json(self) -> str:
        """The scene as scene.json text."""
        return self._scene.to_json()

    def export(self, path: PathLike, to: Optional[str] = None, name: str = "room") -> int:
        """Writes the scene for another tool, as ``mrtmap export`` does: ``"hbjson"`` (Honeybee),
        ``"gbxml"``, ``"gltf"`` (binary .glb) or ``"rad"`` (Radiance), by default from the
        path's extension (.hbjson, .xml, .glb, .rad). Returns the bytes written."""
        return self._scene.export(str(path), to, name)

    def __repr__(self) -> str:
        return f"Scene({self.source!r})"

    def mrt(self, points: Any, *, frame: str = "room", **mrt: Any) -> MrtResult:
        """MRT (°C) of a small sphere at each of ``points`` ((N, 3) or (3,), metres) and its
        standard error (K), as ``mrtmap mrt --at``. Runs in parallel without the GIL."""
        p = _points(points)
        t, s, f = self._scene.mrt(p, frame, _mrt_json(mrt))
        return MrtResult(points=p, mrt=t, std_error=s, view_factor_sum=f)

    def person(
        self,
        points: Any,
        posture: str = "seated",
        facing_deg: Optional[float] = None,
        *,
        frame: str = "room",
        **mrt: Any,
    ) -> MrtResult:
        """A person's MRT (°C) at body centres ``points`` (0.6 m above the floor seated, 1.0 m
        standing) from the projected-area factors of a seated or standing body, facing
        ``facing_deg`` (from +x towards +y) or any way (None), as ``mrtmap mrt --person``."""
        if posture not in ("seated", "standing"):
            raise MrtmapError(f"posture {posture!r} is neither 'seated' nor 'standing'")
        p = _points(points)
        t, s = self._scene.person(p, posture == "standing", facing_deg, frame, _mrt_json(mrt))
        return MrtResult(points=p, mrt=t, std_error=s)

    def plane_radiant(self, points: Any, *, frame: str = "room", **mrt: Any) -> PlaneRadiant:
        """The six plane radiant temperatures (°C) and the radiant asymmetries with ISO 7730's
        verdicts at each point, as ``mrtmap mrt --plane``."""
        p = _points(points)
        t, s, js = self._scene.plane_radiant(p, frame, _mrt_json(mrt))
        rows = json.loads(js)
        return PlaneRadiant(
            faces=("up", "down", "+x", "-x", "+y", "-y"),
            t_pr=t,
            std_error=s,
            vertical_asymmetry=np.array([r["vertical_k"] for r in rows]),
            horizontal_asymmetry=np.array([r["horizontal_k"] for r in rows]),
            horizontal_warm_azimuth_deg=np.array([r["horizontal_warm_azimuth_deg"] for r in rows]),
            verdicts=[{"vertical": r["vertical"], "horizontal": r["horizontal"]} for r in rows],
        )

    def map(
        self,
        height: float = 1.1,
        grid: Sequence[int] = (20, 20),
        margin: float = 0.1,
        **mrt: Any,
    ) -> MrtMap:
        """The MRT over a ``grid`` = (nx, ny) of the floor's bounding rectangle at ``height``
        above the floor, ``margin`` from the walls: the values of ``mrtmap map``'s
        mrt_grid.csv, as arrays (nothing is written)."""
        try:
            nx, ny = (int(g) for g in grid)
        except (TypeError, ValueError):
            raise MrtmapError(f"grid must be two node counts (nx, ny); got {grid!r}") from None
        t, s, xyz, u, v, js = self._scene.map(float(height), nx, ny, float(margin), _mrt_json(mrt))
        rest = json.loads(js)
        return MrtMap(
            height=float(height), x=u, y=v, mrt=t, std_error=s, xyz=xyz, axes=rest["axes"],
            refused=[tuple(r) for r in rest["refused"]], summary=rest["summary"],
            method=rest["method"], compute_secs=rest["compute_secs"],
        )


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


class _Config:
    """A dict of project.toml's sections, handed to the native module as JSON."""

    def __init__(self, d: dict):
        self._d = d

    def __mrtmap_json__(self) -> str:
        return json.dumps(self._d)


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
    changed are reused unless ``force``.
    """
    cfg = _Config(config) if isinstance(config, dict) else (None if config is None else str(config))
    lines, secs, figures = _mrtmap.run(str(recording), str(out), cfg, force, progress)
    f = json.loads(figures)
    o = Path(out)
    layout = RunLayout(str(o))
    maps = []
    for m in f["maps"]:
        s = m["summary"]
        fs = s.get("field") or s  # summary.json flattens the field's figures
        maps.append({
            "height_m": s["height_m"],
            "grid": s["grid"],
            "csv": str(o / m["csv"]),
            "nodes": fs.get("nodes", 0),
            "min_c": fs.get("min", {}).get("mrt_c", math.nan),
            "max_c": fs.get("max", {}).get("mrt_c", math.nan),
            "mean_c": fs.get("mean_c", math.nan),
            "max_std_error_k": fs.get("max_std_error_k", math.nan),
            "summary": s,
        })
    return RunResult(
        recording=Path(recording), out=o, lines=lines, seconds=secs, stages=f["stages"],
        maps=maps, comfort=f["comfort"], level=f["level"], warnings=f["warnings"],
        surfaces=f["scene"]["surfaces"], features=f["scene"]["features"],
        paths={
            "report": str(Path(layout.report_html())),
            "run_json": str(Path(layout.run_json())),
            "scene": str(Path(layout.scene_json())),
        },
    )


def survey(recordings, out, client=None, config=None, n_workers=None):
    """Maps each of ``recordings`` into ``out/<room>`` as an independent task on a Dask cluster
    and returns one table (a pandas DataFrame, also written to ``out/survey.csv``).

    Without ``client`` a ``dask.distributed.LocalCluster`` is started (``n_workers`` processes)
    and closed; pass ``Client("tcp://scheduler:8786")`` to use a running cluster. A room that
    fails is a row with status "failed" and its error; the others go on. Needs
    ``pip install mrtmap[dask]``. See ``mrtmap._survey.survey`` for the columns.
    """
    from ._survey import survey as _survey

    return _survey(recordings, out, client=client, config=config, n_workers=n_workers)


# ---- comfort formulas, vectorised, named and unitised as pythermalcomfort's ----

def _broadcast(*xs):
    arrays = np.broadcast_arrays(*(np.asarray(x, dtype=np.float64) for x in xs))
    shape = arrays[0].shape
    return shape, [np.ascontiguousarray(a).ravel() for a in arrays]


def _check_units(units: str) -> None:
    if str(units).upper() != "SI":
        raise MrtmapError(f"units {units!r}: mrtmap takes SI units only (°C, m/s)")


@dataclass(frozen=True)
class PMVPPD:
    """PMV and PPD (%), arrays of the inputs' broadcast shape (pythermalcomfort's fields)."""

    pmv: np.ndarray
    ppd: np.ndarray


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
    to 2700 Pa, |PMV| ≤ 2); ``round_output`` rounds PMV to 2 and PPD to 1 decimal. Inputs
    broadcast like numpy's; the work runs in parallel without the GIL.
    """
    _check_units(units)
    editions = {"7730-2025": 2025, "7730-2005": 2005}
    if str(model).lower() not in editions:
        raise MrtmapError(f"model {model!r} is neither '7730-2025' nor '7730-2005'")
    shape, flat = _broadcast(tdb, tr, vr, rh, met, clo, wme)
    pmv, ppd = _mrtmap.pmv_ppd(
        *flat, editions[str(model).lower()], bool(limit_inputs), bool(round_output)
    )
    return PMVPPD(pmv=pmv.reshape(shape), ppd=ppd.reshape(shape))


def operative_tmp(tdb, tr, v, standard: str = "ISO"):
    """Operative temperature (°C) — pythermalcomfort's ``operative_tmp``: ISO 7726's
    (tdb √(10 v) + tr) / (1 + √(10 v)), or ASHRAE 55's weights by air speed ``v`` (m/s)."""
    s = str(standard).lower()
    if s not in ("iso", "ashrae"):
        raise MrtmapError(f"standard {standard!r} is neither 'ISO' nor 'ASHRAE'")
    shape, flat = _broadcast(tdb, tr, v)
    return _mrtmap.operative(*flat, s == "ashrae").reshape(shape)


def mean_radiant_tmp(tg, tdb, v, d=0.15, emissivity=0.95, standard: str = "Mixed Convection"):
    """MRT (°C) from a globe thermometer's reading — pythermalcomfort's ``mean_radiant_tmp``:
    globe temperature tg (°C), air temperature tdb (°C), air speed v (m/s), globe diameter d (m),
    emissivity; ``standard`` "ISO" (ISO 7726, the larger of natural and forced convection) or
    "Mixed Convection" (Teitelbaum et al. 2022; NaN outside 40–150 mm globes)."""
    s = str(standard).lower()
    if s not in ("iso", "mixed convection"):
        raise MrtmapError(f"standard {standard!r} is neither 'ISO' nor 'Mixed Convection'")
    shape, flat = _broadcast(tg, tdb, v, d, emissivity)
    return _mrtmap.mrt_from_globe(*flat, s == "mixed convection").reshape(shape)


mrt_from_globe = mean_radiant_tmp


def v_relative(v, met):
    """The relative air speed ISO 7730 uses (m/s): v + 0.3 (met − 1) above 1 met —
    pythermalcomfort's ``v_relative``."""
    v, met = np.asarray(v, dtype=np.float64), np.asarray(met, dtype=np.float64)
    return np.where(met > 1, np.round(v + 0.3 * (met - 1), 3), v)


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
    its range gives NaN; any other input out of its range raises :class:`MrtmapError` naming the
    element. ΔMRT = ERF / (f_eff · 6 W/m²K), to add to the long-wave MRT.
    """
    shape, flat = _broadcast(sol_altitude, sharp, sol_radiation_dir, sol_transmittance, f_svv,
                             f_bes, asw, floor_reflectance)
    erf, dmrt = _mrtmap.solar_gain(*flat, str(posture))
    erf, dmrt = erf.reshape(shape), dmrt.reshape(shape)
    if round_output:
        erf, dmrt = np.round(erf, 1), np.round(dmrt, 1)
    if shape == ():
        return SolarGain(erf=float(erf), delta_mrt=float(dmrt))
    return SolarGain(erf=erf, delta_mrt=dmrt)


def f_svv(w, h, d):
    """The sky-vault view fraction of a window ``w`` × ``h`` (m) straight ahead of a person at
    distance ``d`` (m): atan(h/2d)° · atan(w/2d)° / 16200 — pythermalcomfort's
    ``environment.f_svv`` (the CBE Comfort Tool's form); broadcasts, a float for scalars."""
    shape, flat = _broadcast(w, h, d)
    out = _mrtmap.f_svv(*flat).reshape(shape)
    return float(out) if shape == () else out
