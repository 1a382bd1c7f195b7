"""The comfort functions equal pythermalcomfort 4.x's on 10,000 random valid inputs within 1e-6."""

import warnings

import numpy as np
import pytest

import mrtmap

ptc_models = pytest.importorskip("pythermalcomfort.models")

try:
    from pythermalcomfort.environment import mean_radiant_tmp as ptc_mrt
    from pythermalcomfort.environment import operative_tmp as ptc_to
    from pythermalcomfort.environment import v_relative as ptc_v_relative
except ImportError:  # pythermalcomfort before 4.5 kept them in utilities
    from pythermalcomfort.utilities import mean_radiant_tmp as ptc_mrt
    from pythermalcomfort.utilities import operative_tmp as ptc_to
    from pythermalcomfort.utilities import v_relative as ptc_v_relative

N = 10_000
warnings.filterwarnings("ignore")


@pytest.fixture(scope="module")
def inputs():
    rng = np.random.default_rng(42)
    return dict(
        tdb=rng.uniform(10, 30, N), tr=rng.uniform(10, 40, N), v=rng.uniform(0, 1, N),
        rh=rng.uniform(5, 95, N), met=rng.uniform(0.8, 4, N), clo=rng.uniform(0, 2, N),
    )


@pytest.mark.parametrize("limit", [False, True])
def test_pmv_ppd_iso(inputs, limit):
    i = inputs
    vr = ptc_v_relative(i["v"], i["met"])
    ours = mrtmap.pmv_ppd_iso(i["tdb"], i["tr"], vr, i["rh"], i["met"], i["clo"],
                              limit_inputs=limit, round_output=False)
    peer = ptc_models.pmv_ppd_iso(i["tdb"], i["tr"], vr, i["rh"], i["met"], i["clo"],
                                  limit_inputs=limit, round_output=False)
    assert ours.pmv.shape == (N,)
    np.testing.assert_array_equal(np.isnan(ours.pmv), np.isnan(peer.pmv))
    np.testing.assert_allclose(ours.pmv, peer.pmv, rtol=0, atol=1e-6, equal_nan=True)
    np.testing.assert_allclose(ours.ppd, peer.ppd, rtol=0, atol=1e-6, equal_nan=True)
    if limit:
        assert 0 < np.isnan(ours.pmv).sum() < N  # both sides of the limits were drawn


def test_pmv_rounded_and_broadcast(inputs):
    i = inputs
    ours = mrtmap.pmv_ppd_iso(i["tdb"][:50], 25.0, 0.1, 50, 1.2, 0.5)
    peer = ptc_models.pmv_ppd_iso(i["tdb"][:50], 25.0, 0.1, 50, 1.2, 0.5)
    np.testing.assert_array_equal(ours.pmv, peer.pmv)
    np.testing.assert_array_equal(ours.ppd, peer.ppd)
    grid = mrtmap.pmv_ppd_iso(np.linspace(18, 28, 7)[:, None], np.linspace(15, 35, 5)[None, :],
                              0.1, 50, 1.2, 0.5)
    assert grid.pmv.shape == (7, 5)
    # ISO 7730:2005's code differs by its first guess only: within 0.002, not equal.
    a = mrtmap.pmv_ppd_iso(25, 25, 0.1, 50, 1.1, 0.5, model="7730-2005", round_output=False)
    assert float(a.pmv) == pytest.approx(-0.13201636, abs=1e-7)


def test_operative_and_v_relative(inputs):
    i = inputs
    for std in ("ISO", "ASHRAE"):
        v = np.minimum(i["v"], 0.99)
        np.testing.assert_allclose(mrtmap.operative_tmp(i["tdb"], i["tr"], v, standard=std),
                                   ptc_to(i["tdb"], i["tr"], v, standard=std), rtol=0, atol=1e-6)
    np.testing.assert_array_equal(mrtmap.v_relative(i["v"], i["met"]),
                                  ptc_v_relative(i["v"], i["met"]))


def test_mean_radiant_tmp(inputs):
    rng = np.random.default_rng(7)
    tg = rng.uniform(15, 35, N)
    tdb = tg + rng.uniform(-6, 6, N)
    v = rng.uniform(0.05, 1.0, N)
    d = rng.choice([0.038, 0.05, 0.1, 0.15], N)
    e = rng.uniform(0.93, 0.97, N)
    for std in ("ISO", "Mixed Convection"):
        ours = mrtmap.mean_radiant_tmp(tg, tdb, v, d, e, standard=std)
        peer = ptc_mrt(tg, tdb, v, d, e, standard=std)
        np.testing.assert_array_equal(np.isnan(ours), np.isnan(peer))
        np.testing.assert_allclose(ours, peer, rtol=0, atol=1e-6, equal_nan=True)


def test_inputs_broadcast_where_they_lie_as_numpy_does():
    """Inputs are read in the broadcast shape without being copied to it: a column against a
    row, a strided and a transposed array, three axes with ones in between; each element equals
    the same computation on inputs broadcast by numpy first."""
    rng = np.random.default_rng(7)
    cases = [
        (np.linspace(18, 28, 9)[:, None], np.linspace(15, 35, 6)[None, :], 0.1),
        (rng.uniform(18, 28, (6, 9)).T, rng.uniform(15, 35, 12)[::2], rng.uniform(0, 0.5, (9, 1))),
        (rng.uniform(18, 28, (3, 1, 5)), rng.uniform(15, 35, (4, 1)), rng.uniform(0, 0.5, (1, 4, 5))),
    ]
    for tdb, tr, vr in cases:
        shape = np.broadcast_shapes(np.shape(tdb), np.shape(tr), np.shape(vr))
        ours = mrtmap.pmv_ppd_iso(tdb, tr, vr, 50, 1.2, 0.5, round_output=False)
        full = [np.array(np.broadcast_to(x, shape)).ravel() for x in (tdb, tr, vr)]
        flat = mrtmap.pmv_ppd_iso(*full, 50, 1.2, 0.5, round_output=False)
        assert ours.pmv.shape == shape
        np.testing.assert_array_equal(ours.pmv.ravel(), flat.pmv)
        np.testing.assert_array_equal(ours.ppd.ravel(), flat.ppd)
        peer = ptc_models.pmv_ppd_iso(*full, 50, 1.2, 0.5, round_output=False)
        np.testing.assert_allclose(ours.pmv.ravel(), peer.pmv, rtol=0, atol=1e-9)
        to = mrtmap.operative_tmp(tdb, tr, vr)
        np.testing.assert_allclose(to.ravel(), mrtmap.operative_tmp(*full), rtol=0, atol=0)
    with pytest.raises(ValueError, match="shape mismatch|broadcast"):
        mrtmap.pmv_ppd_iso(np.zeros(3) + 20, np.zeros(4) + 20, 0.1, 50, 1.2, 0.5)


def test_a_broadcast_too_big_for_memory_raises_memory_error():
    """A column of 100,000 against a row of 100,000 asks 80 GB for each result: a MemoryError,
    not an aborted interpreter."""
    with pytest.raises(MemoryError, match="do not fit in memory"):
        mrtmap.pmv_ppd_iso(np.zeros((100_000, 1)) + 22, np.zeros((1, 100_000)) + 22,
                           0.1, 50, 1.2, 0.7)
    with pytest.raises(MemoryError):
        mrtmap.operative_tmp(np.zeros((100_000, 1)) + 22, np.zeros((1, 100_000)) + 22, 0.1)
