"""The identification's arguments refused word for word, its captures checked as they arrive
(a copy of a recording refused), the noise fingerprint's invariants, and the result's table,
summary and JSON in closed form on hand-made fits."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from conftest import DEFAULT_SCENE
from rtsgeom.errors import CaptureError, ParameterError
from rtsgeom.identify.capture import Capture
from rtsgeom.identify.fit import FrontEndFit
from rtsgeom.identify.identification import (MAX_CAPTURES, SAME_RECORDING, Identification,
                                             _captures, identify, noise_fingerprint)
from rtsgeom.scene import load_scene

_CAPS = ("must be a list (or an iterable) of Capture (rtsgeom.identify.read_capture(path) "
         "reads one)")


@pytest.fixture(scope="module")
def scene():
    return load_scene(DEFAULT_SCENE)


def _cap(seed, active=0, shape=(16, 2, 256), scale=1.0):
    rng = np.random.default_rng(seed)
    data = scale * (rng.normal(size=shape) + 1j * rng.normal(size=shape))
    return Capture(data, active, 1.0, 0.0, 1.0, source=f"cap{seed}")


@pytest.mark.parametrize("captures, message", [
    (None, f"identify: captures = None: {_CAPS}"),
    ("cap.npy", f"identify: captures = 'cap.npy': {_CAPS}"),
    (b"cap", f"identify: captures = b'cap': {_CAPS}"),
    (Path("cap.npy"), f"identify: captures = PosixPath('cap.npy'): {_CAPS}"),
    (3, f"identify: captures = 3: {_CAPS}"),
    ([], "identify: captures = []: must hold at least one capture"),
    ([1.5], "identify: captures[0] = 1.5: must be a Capture (rtsgeom.identify.read_capture(path) "
            "reads one)")])
def test_identify_refuses_what_is_not_captures(scene, captures, message):
    with pytest.raises(ParameterError) as exc:
        identify(scene, captures)
    assert str(exc.value) == message


def test_identify_refuses_a_lone_capture_and_bad_flags(scene):
    cap = _cap(0)
    with pytest.raises(ParameterError) as exc:
        identify(scene, cap)
    assert str(exc.value) == ("identify: captures = Capture('cap0', front end 0,... complex128, "
                              f"no radar record): {_CAPS}")
    for kw, message in (
            ({"reference": -1}, "identify: reference = -1: must be in [0, 10000]"),
            ({"reference": 10_001}, "identify: reference = 10001: must be in [0, 10000]"),
            ({"accept_misfit": 1}, "identify: accept_misfit = 1: must be true or false"),
            ({"radar_channels": "yes"}, "identify: radar_channels = 'yes': must be true or "
                                        "false")):
        with pytest.raises(ParameterError) as exc:
            identify(scene, [cap], **kw)
        assert str(exc.value) == message


class _Many:
    """A sized iterable of ``n`` captures (none is made: the size is refused first)."""

    def __init__(self, n):
        self.n = n

    def __len__(self):
        return self.n

    def __iter__(self):
        return iter(())


def test_captures_are_capped_and_checked_as_they_arrive():
    assert MAX_CAPTURES == 1024
    with pytest.raises(ParameterError) as exc:
        list(_captures(_Many(1025)))
    assert str(exc.value) == "identify: captures: 1025: must be at most 1024"
    with pytest.raises(ParameterError, match=r"^identify: captures = \[\]: must hold at least"):
        list(_captures(_Many(1024)))  # the size is taken; it holds none
    caps = [_cap(k) for k in range(3)]
    assert list(_captures(iter(caps))) == caps  # a generator, each passed on as it is


def test_a_generator_of_too_many_captures_stops_at_the_cap():
    def gen():
        for k in range(MAX_CAPTURES + 1):
            yield _cap(k, active=k, shape=(4, 1, 2))  # one per front end: none compared
    with pytest.raises(ParameterError) as exc:
        list(_captures(gen()))
    assert str(exc.value) == "identify: captures: more than 1024: must be at most 1024"


@pytest.mark.parametrize("scale", [1.0, -3.0, 1e30, 1e-30])
def test_a_copy_of_a_recording_is_refused_for_the_same_front_end_only(scale):
    """A copy (or a scaled copy) of a capture of the same front end is the same recording
    (|cos| of the fingerprints 1 > 0.5); of another front end it is another measurement."""
    assert SAME_RECORDING == 0.5
    a = _cap(1)
    copy = Capture(a.data * scale, 0, 1.0, 0.0, 1.0, source="copy.npy")
    with pytest.raises(CaptureError) as exc:
        list(_captures([a, _cap(2), copy]))
    assert str(exc.value) == ("copy.npy: the same recording as cap1 (their receiver noise "
                              "agrees, |cos| 1.000): must be an independent capture (a copy "
                              "counts its noise twice)")
    other = Capture(a.data * scale, 1, 1.0, 0.0, 1.0, source="other.npy")
    assert len(list(_captures([a, other]))) == 2


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_noise_fingerprint_is_unit_norm_and_scale_free(seed):
    cap = _cap(seed, shape=(32, 3, 16))
    f = noise_fingerprint(cap)
    assert f.shape == (16,) and np.linalg.norm(f) == pytest.approx(1.0, abs=1e-12)
    for s in (2.0, -1e-20, 1e25):
        g = noise_fingerprint(Capture(cap.data * s, 0, 1.0, 0.0, 1.0))
        assert np.allclose(g, f * np.sign(s), atol=1e-12)
    # independent noise: nearly orthogonal (about 1/sqrt(16) each)
    assert abs(np.vdot(f, noise_fingerprint(_cap(seed + 10, shape=(32, 3, 16))))) < 0.9
    zero = noise_fingerprint(Capture(np.zeros((8, 1, 4), complex), 0, 1.0, 0.0, 1.0))
    assert np.array_equal(zero, np.zeros(4))


def test_the_fingerprint_reads_the_doppler_bin_farthest_from_probe_and_zero():
    """A probe tone at Doppler bin k and noise elsewhere: the fingerprint is virtual channel 0's
    Hann-windowed transform at the bin farthest from both k and 0 (circularly)."""
    from rtsgeom.radar.windows import window
    n_l, n = 16, 8
    rng = np.random.default_rng(5)
    d = np.arange(n_l)
    for k, far in ((4, 10), (0, 8), (8, 4), (12, 6)):
        x = 1e-3 * (rng.normal(size=(n_l, 1, n)) + 1j * rng.normal(size=(n_l, 1, n)))
        x[:, 0, :] += 100.0 * np.exp(2j * np.pi * k * d / n_l)[:, None]
        f = noise_fingerprint(Capture(x, 0, 1.0, 0.0, 1.0))
        y = x[:, 0, :] / np.max(np.abs(x[:, 0, :]))
        want = (window("hann", n_l) * np.exp(-2j * np.pi * far * d / n_l)) @ y
        assert np.allclose(f, want / np.linalg.norm(want), atol=1e-12), (k, far)


# -- the result, on hand-made fits --

def _fit(index, est, std, reasons=(None,) * 7, residual=1.0, misfit=None, corr=None):
    return FrontEndFit(index, np.array(est, float), np.array(std, float), tuple(reasons),
                       np.eye(7) if corr is None else corr, residual, 1.0, 2 + index, misfit)


@pytest.fixture(scope="module")
def ident(scene):
    corr = np.eye(7)
    corr[0, 1] = corr[1, 0] = 0.6  # radial-tangential: shown
    corr[4, 5] = corr[5, 4] = -0.9  # delay-gain: both channel parameters, not shown
    corr[0, 6] = corr[6, 0] = 0.5  # at 0.5: not shown
    corr[2, 6] = corr[6, 2] = -0.51  # height-phase: shown
    a = _fit(0, [1e-3, -2e-3, 0.5e-3, math.radians(1.0), 2e-12, math.log(2.0), math.radians(10)],
             [1e-4, 2e-4, 3e-4, math.radians(0.1), 1e-12, 0.01, math.radians(1.0)], corr=corr,
             residual=0.8)
    why = (None, None, "height: no elevation", None, "delay: one range", None, None)
    b = _fit(3, [0.0, 1e-3, 0.0, 0.0, 0.0, 0.0, 0.0], [1e-4] * 7, why, residual=2.0,
             misfit="front end 3: residual")
    return Identification(scene, (a, b))


def test_the_table_shows_each_parameter_in_its_unit_and_nan_where_not_identifiable(ident):
    cols = ident._columns()
    assert cols["front_end"] == [0, 3]
    assert cols["radial_offset_mm"] == pytest.approx([1.0, 0.0])
    assert cols["radial_offset_std_mm"] == pytest.approx([0.1, 0.1])
    assert cols["tangential_offset_mm"] == pytest.approx([-2.0, 1.0])
    assert cols["height_offset_mm"][0] == pytest.approx(0.5) and math.isnan(
        cols["height_offset_mm"][1])
    assert math.isnan(cols["height_offset_std_mm"][1]) and cols["height_offset_std_mm"][0] == pytest.approx(0.3)
    assert cols["yaw_offset_deg"] == pytest.approx([1.0, 0.0])
    assert cols["yaw_offset_std_deg"][0] == pytest.approx(0.1)
    assert cols["delay_offset_ps"][0] == pytest.approx(2.0) and math.isnan(
        cols["delay_offset_ps"][1])
    assert cols["gain_db"][0] == pytest.approx(20 * math.log10(2.0))
    assert cols["gain_std_db"][0] == pytest.approx(0.01 * 20 / math.log(10))
    assert cols["phase_deg"][0] == pytest.approx(10.0) and cols["phase_std_deg"][0] == \
        pytest.approx(1.0)
    assert cols["residual_rms"] == [0.8, 2.0]
    assert ident.fit(3) is ident.fits[1] and ident.fit(1) is None


def test_the_summary_names_what_was_identified(ident, scene):
    title, rows = ident._summary()
    assert title == f"{scene.name}: 2 front ends identified"
    assert rows == [("front end 0", "r 1+-0.1 t -2+-0.2 h 0.5+-0.3 yaw 1+-0.1 (mm, yaw deg), "
                                    "residual 0.80, 2 captures"),
                    ("front end 3", "r 0+-0.1 t 1+-0.1 yaw 0+-0.0057 (mm, yaw deg), residual "
                                    "2.00, 5 captures")]
    none = Identification(scene, (_fit(1, [0.0] * 7, [1.0] * 7, ("x",) * 7),))
    assert none._summary()[1] == [("front end 1", "nothing identifiable, residual 1.00, "
                                                   "3 captures")]


def test_the_json_has_values_stds_reasons_and_the_strong_correlations(ident, scene):
    d = ident.to_dict()
    fe0, fe3 = d["front_ends"]
    assert fe0["radial_offset_mm"] == pytest.approx({"value": 1.0, "std": 0.1})
    assert fe0["yaw_offset_deg"] == pytest.approx({"value": 1.0, "std": 0.1})
    assert fe0["not_identifiable"] == {} and fe0["misfit"] is None and fe0["captures"] == 2
    assert fe0["correlations"] == [
        {"a": "radial_offset", "b": "tangential_offset", "r": 0.6},
        {"a": "height_offset", "b": "phase", "r": -0.51}]
    assert fe3["height_offset_mm"] is None
    assert fe3["not_identifiable"] == {"height_offset_mm": "height: no elevation"}
    assert fe3["misfit"] == "front end 3: residual" and fe3["residual_rms"] == 2.0
    ch0, ch3 = d["channels"]
    assert (ch0["index"], ch0["front_end"]) == (0, 0)
    assert ch0["delay_offset_s"] == pytest.approx({"value": 2e-12, "std": 1e-12})
    assert ch0["gain_db"] == pytest.approx({"value": 20 * math.log10(2.0),
                                            "std": 0.01 * 20 / math.log(10)})
    assert ch0["phase_deg"] == pytest.approx({"value": 10.0, "std": 1.0})
    assert ch3["delay_offset_s"] is None and ch3["not_identifiable"] == {
        "delay_offset_s": "delay: one range"}
    assert d["scene"] == scene.name
    assert d["residual_rms"] == pytest.approx(math.sqrt((0.8 ** 2 + 2.0 ** 2) / 2))
    assert d["residual_rms_unit"] == "measured noise std of one range-Doppler value"
    assert d["residual_limit"] == 3.0
    assert d["model_fits"] is False and "radar_channels" not in d
    fits = Identification(scene, (ident.fits[0],)).to_dict()
    assert fits["model_fits"] is True and fits["residual_rms"] == pytest.approx(0.8)
    assert Identification(scene, ()).to_dict()["residual_rms"] is None


def test_the_figure_draws_each_front_ends_offsets_with_their_sigmas(ident, scene):
    """One errorbar series per mounting axis (radial, tangential, height) at the front ends'
    indices (shifted by -0.12, 0, +0.12), the values and 1-sigma bars in mm, NaN where not
    identifiable; with the radar's channels a second panel of each antenna's phase in deg,
    the references (fixed) as open markers without a bar."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig = ident.plot()
    assert len(fig.axes) == 1
    ax = fig.axes[0]
    cols = ident._columns()
    bars = ax.containers
    assert [b.get_label() for b in bars] == ["radial", "tangential", "height"]
    for k, (b, name) in enumerate(zip(bars, ("radial", "tangential", "height"))):
        line = b.lines[0]
        assert np.allclose(np.asarray(line.get_xdata(), float),
                           np.array([0, 3]) + (k - 1) * 0.12, atol=1e-12)
        assert np.allclose(np.asarray(line.get_ydata(), float),
                           np.asarray(cols[f"{name}_offset_mm"], float), atol=1e-12,
                           equal_nan=True)
        seg = b.lines[2][0].get_segments()[0]  # front end 0's bar: value -+ its sigma
        assert np.allclose(sorted(seg[:, 1]), [cols[f"{name}_offset_mm"][0]
                                               + d * cols[f"{name}_offset_std_mm"][0]
                                               for d in (-1, 1)], rtol=1e-12)
    assert ax.get_title() == f"{scene.name}: identified mounting offsets"
    plt.close(fig)
    assert ident.plot("my title").axes[0].get_title() == "my title"
    plt.close("all")


def test_the_figure_of_a_joint_fit_shows_each_antennas_phase(ident, scene):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from rtsgeom.identify.joint import RadarChannelsFit
    ph = np.radians([0.0, 10.0, -5.0, 0.0, 3.0])
    why = (("ref", "ref"), (None, None), (None, None), ("ref", "ref"), (None, None))
    radar = RadarChannelsFit(np.zeros(5), ph, np.full(5, 0.01), np.radians(np.full(5, 0.5)),
                             why, 2, 0, 0, 3)
    fig = Identification(scene, ident.fits, radar).plot()
    assert len(fig.axes) == 2
    assert fig._suptitle.get_text() == f"{scene.name}: identified mounting and radar channels"
    ax_r = fig.axes[1]
    pts = ax_r.containers
    assert len(pts) == 5
    assert [float(b.lines[0].get_xdata()[0]) for b in pts] == [0, 1, 2, 3, 4]
    assert np.allclose([float(b.lines[0].get_ydata()[0]) for b in pts],
                       [0.0, 10.0, -5.0, 0.0, 3.0], atol=1e-12)
    fixed = [b.lines[2] == () or len(b.lines[2]) == 0 for b in pts]
    assert fixed == [True, False, False, True, False]
    assert [t.get_text() for t in ax_r.get_xticklabels()] == ["TX0*", "TX1", "RX0", "RX1*",
                                                               "RX2"]
    assert ax_r.get_xlabel() == "antenna (* fixed: reference or unseen)"
    plt.close(fig)
