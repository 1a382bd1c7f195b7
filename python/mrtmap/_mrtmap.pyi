"""Type stubs of mrtmap's native module (crates/mrtmap-py). Use the package's API (`mrtmap.Scene`,
`mrtmap.run`, …); these are the calls it makes."""

from typing import Callable, Optional

import numpy as np
import numpy.typing as npt

__version__: str

class MrtmapError(ValueError):
    """An error of mrtmap's: the one-sentence message the command line prints."""

class Scene:
    @staticmethod
    def load(path: str, temperatures: Optional[str] = None, room: Optional[str] = None) -> "Scene": ...
    @staticmethod
    def example() -> "Scene": ...
    @property
    def source(self) -> str: ...
    def export(self, path: str, to: Optional[str] = None, name: Optional[str] = None) -> int: ...
    def to_json(self) -> str: ...
    def mrt(
        self, points: npt.ArrayLike, frame: str, mrt_json: str
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
    def person(
        self,
        points: npt.ArrayLike,
        standing: bool,
        facing_deg: Optional[float],
        frame: str,
        mrt_json: str,
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
    def plane_radiant(
        self, points: npt.ArrayLike, frame: str, mrt_json: str
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], str]: ...
    def map(
        self, height_m: float, nx: int, ny: int, margin_m: float, mrt_json: str
    ) -> tuple[
        npt.NDArray[np.float64],
        npt.NDArray[np.float64],
        npt.NDArray[np.float64],
        npt.NDArray[np.float64],
        npt.NDArray[np.float64],
        str,
    ]: ...

def run(
    recording: str,
    out: str,
    config: object = None,
    force: bool = False,
    progress: Optional[Callable[[str, int, int], None]] = None,
) -> tuple[list[str], float, str]: ...
def pmv_ppd(
    tdb: npt.ArrayLike,
    tr: npt.ArrayLike,
    vr: npt.ArrayLike,
    rh: npt.ArrayLike,
    met: npt.ArrayLike,
    clo: npt.ArrayLike,
    wme: npt.ArrayLike,
    edition: int,
    limit: bool,
    round: bool,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def operative(
    tdb: npt.ArrayLike, tr: npt.ArrayLike, v: npt.ArrayLike, ashrae: bool
) -> npt.NDArray[np.float64]: ...
def mrt_from_globe(
    tg: npt.ArrayLike,
    tdb: npt.ArrayLike,
    v: npt.ArrayLike,
    d: npt.ArrayLike,
    emissivity: npt.ArrayLike,
    mixed: bool,
) -> npt.NDArray[np.float64]: ...
def solar_gain(
    sol_altitude: npt.ArrayLike,
    sharp: npt.ArrayLike,
    sol_radiation_dir: npt.ArrayLike,
    sol_transmittance: npt.ArrayLike,
    f_svv: npt.ArrayLike,
    f_bes: npt.ArrayLike,
    asw: npt.ArrayLike,
    floor_reflectance: npt.ArrayLike,
    posture: str,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def f_svv(
    w: npt.ArrayLike, h: npt.ArrayLike, d: npt.ArrayLike
) -> npt.NDArray[np.float64]: ...
def cli_main(argv: list[str]) -> int: ...
