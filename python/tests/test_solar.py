"""SolarCal: mrtmap.solar_gain and mrtmap.f_svv equal pythermalcomfort 4.x's on random valid
inputs (within 0.01 W/m² and 0.005 K; in practice about 1e-8)."""

import warnings

import numpy as np
import pytest

import mrtmap

ptc_models = pytest.importorskip("pythermalcomfort.models")
from pythermalcomfort.environment import f_svv as ptc_f_svv  # noqa: E402

N = 500
POSTURES = ("sitting", "standing", "supine")


@pytest.fixture(scope="module")
def inputs():
    rng = np.random.default_rng(7)
    return dict(
        sol_altitude=rng.uniform(0, 90, N), sharp=rng.uniform(0, 180, N),
        sol_radiation_dir=rng.uniform(200, 1000, N), sol_transmittance=rng.uniform(0, 1, N),
        f_svv=rng.uniform(0, 1, N), f_bes=rng.uniform(0, 1, N), asw=rng.uniform(0.5, 0.9, N),
        floor_reflectance=rng.uniform(0, 1, N),
    )


@pytest.mark.parametrize("posture", POSTURES)
def test_solar_gain_equals_pythermalcomfort(inputs, posture):
    ours = mrtmap.solar_gain(**inputs, posture=posture, round_output=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        peer = ptc_models.solar_gain(**inputs, posture=posture, round_output=False)
    assert ours.erf.shape == (N,)
    assert np.isfinite(ours.erf).all()
    np.testing.assert_allclose(ours.erf, peer.erf, rtol=0, atol=0.01)
    np.testing.assert_allclose(ours.delta_mrt, peer.delta_mrt, rtol=0, atol=0.005)
    # The gains are not all alike: the comparison spans a real range.
    assert ours.delta_mrt.max() > 5 * ours.delta_mrt.min() + 1


def test_published_vector_scalars_and_rounding():
    # grey-and-sun.md, the first vector; scalars in, floats out.
    r = mrtmap.solar_gain(30, 0, 700, 0.6, 0.04233, 1.0, round_output=False)
    assert isinstance(r.erf, float) and isinstance(r.delta_mrt, float)
    assert abs(r.erf - 68.522) < 0.01 and abs(r.delta_mrt - 16.4084) < 0.005
    rounded = mrtmap.solar_gain(30, 0, 700, 0.6, 0.04233, 1.0)
    peer = ptc_models.solar_gain(30, 0, 700, 0.6, 0.04233, 1.0)
    assert (rounded.erf, rounded.delta_mrt) == (float(peer.erf), float(peer.delta_mrt)) == (68.5, 16.4)
    # Broadcasting: a column of altitudes against a row of SHARPs.
    grid = mrtmap.solar_gain(np.array([15.0, 45.0, 75.0])[:, None], np.array([0.0, 90.0]), 800,
                             0.5, 0.1, 1.0, posture="standing")
    assert grid.erf.shape == (3, 2)


def test_out_of_range_angles_are_nan_and_other_inputs_refused():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        peer = ptc_models.solar_gain([30, -5, 95], [0, 0, 200], 700, 0.6, 0.1, 1.0)
    ours = mrtmap.solar_gain([30, -5, 95], [0, 0, 200], 700, 0.6, 0.1, 1.0)
    np.testing.assert_array_equal(np.isnan(ours.erf), np.isnan(peer.erf))
    assert np.isnan(ours.erf[1:]).all() and np.isfinite(ours.erf[0])
    with pytest.warns(RuntimeWarning, match="2 elements .* element 1: solar transmittance = 1.5 is outside"):
        r = mrtmap.solar_gain(30, 0, 700, [0.6, 1.5, 2.0], 0.1, 1.0)
    assert np.isfinite(r.erf[0]) and np.isnan(r.erf[1:]).all() and np.isnan(r.delta_mrt[1:]).all()
    with pytest.raises(mrtmap.MrtmapError, match="posture 'lying'"):
        mrtmap.solar_gain(30, 0, 700, 0.6, 0.1, 1.0, posture="lying")


def test_f_svv_equals_pythermalcomfort():
    rng = np.random.default_rng(3)
    w, h, d = rng.uniform(0.1, 5, 200), rng.uniform(0.1, 3, 200), rng.uniform(0.2, 10, 200)
    ours = mrtmap.f_svv(w, h, d)
    peer = np.array([ptc_f_svv(*x) for x in zip(w, h, d)])
    np.testing.assert_allclose(ours, peer, rtol=0, atol=1e-12)
    assert isinstance(mrtmap.f_svv(1.8, 1.3, 1.55), float)
    assert abs(mrtmap.f_svv(1.8, 1.3, 1.55) - 0.042330) < 1e-6
    with pytest.warns(RuntimeWarning, match="distance to the window"):
        assert np.isnan(mrtmap.f_svv(1, 1, 0))
