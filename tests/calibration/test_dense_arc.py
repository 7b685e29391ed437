"""Arcs of many front ends: the probes that measure each front end alone stay on the RuT's
range axis (measured in turns, a frame each, where they do not fit one frame), every front end
is detected, and no Python warning with a source line reaches a user of the CLI."""

from __future__ import annotations

import copy
import tomllib
import warnings
from pathlib import Path

import numpy as np
import pytest

from rtsgeom.calibration.probes import (PROBE_RANGE_LIMIT, ProbeWarning, probe_front_ends,
                                        probe_layout, probe_ranges, probes_per_frame)
from rtsgeom.errors import RtsgeomWarning
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.scene import parse_scene

TEMPLATE = Path(__file__).resolve().parents[2] / "scenes" / "template.toml"


def dense_arc(n: int, step_deg: float, **radar):
    """The template's bench with ``n`` front ends ``step_deg`` apart (narrow modules and
    cutouts so that neighbours fit), no noise unless ``radar`` sets it, one target."""
    doc = copy.deepcopy(tomllib.loads(TEMPLATE.read_text()))
    doc["radar"].pop("snr_db", None)
    doc["radar"].update(radar)
    a0 = -step_deg * (n - 1) / 2
    doc["rts"]["front_ends"] = [{"angle_deg": a0 + k * step_deg, "rx_tx_separation_m": 0.012,
                                 "cable_length_m": 1.0} for k in range(n)]
    doc["sheet"].update(angle_min_deg=a0 - 4, angle_max_deg=-a0 + 4, cutout_diameter_m=0.024)
    doc["targets"] = [{"range_m": 20.0, "angle_deg": step_deg / 2}]
    return parse_scene(doc, "dense.toml")


@pytest.mark.parametrize("n", [2, 5, 17, 33, 64, 130])
@pytest.mark.parametrize("radar", [{}, {"samples_per_chirp": 128},
                                   {"samples_per_chirp": 256, "adc_rate_hz": 6.25e6}])
def test_probe_layout_stays_on_the_range_axis(n, radar):
    """Every probe below PROBE_RANGE_LIMIT of the range axis, at most probes_per_frame a
    frame, apart within a frame as probe_ranges spaces them, the frames ceil(n / k) (linear in
    n); where all fit one frame, the layout is probe_ranges' (33 front ends 2 deg apart used
    to put probes at up to 111 m on a 77 m axis and lose 12 front ends)."""
    setup = build_setup(dense_arc(n, 1.0, **radar))
    radar_cfg = setup.scene.radar
    ranges, turn = probe_layout(setup, n)
    k = probes_per_frame(setup, n)
    assert np.all(ranges <= PROBE_RANGE_LIMIT * radar_cfg.max_range_m)
    assert turn.max() + 1 == -(-n // k)
    assert np.max(np.bincount(turn)) <= k
    for t in range(turn.max() + 1):
        r = ranges[turn == t]
        assert np.allclose(r, probe_ranges(setup, k)[:r.size])
    if k == n:
        assert np.all(turn == 0) and np.allclose(ranges, probe_ranges(setup, n))


@pytest.mark.parametrize("n,step_deg", [(33, 2.0), (40, 1.0)])
def test_every_front_end_of_a_dense_arc_is_detected(n, step_deg):
    """Each front end alone, measured in turns: all detected, no warning, their measured
    angles step_deg apart (within 0.1 deg: frames measured in different turns agree) and
    within 0.5 deg of the geometric azimuth (the near field and the Rx/Tx split move each by
    about 0.3 deg)."""
    setup = build_setup(dense_arc(n, step_deg, snr_db=20.0, chirps_per_tx=32))
    assert probes_per_frame(setup, n) < n  # the case that failed: more than one frame
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        probe = probe_front_ends(setup, exact_paths(setup), seed=3)
    assert np.all(np.isfinite(probe.angle_rad))
    assert np.max(np.abs(np.diff(probe.angle_rad) - np.radians(step_deg))) < np.radians(0.1)
    assert np.max(np.abs(probe.angle_rad - setup.fe_azimuth_rad())) < np.radians(0.5)
    assert np.all(np.abs(20 * np.log10(probe.gain_correction)) < 3.0)


def test_cli_prints_any_warning_as_one_line(capsys):
    """The CLI's showwarning: rtsgeom's warnings and any other (numpy's RuntimeWarning) as one
    line ``rtsgeom: warning: ...``, never a file name and source line."""
    from rtsgeom.cli._common import show_warning
    assert issubclass(ProbeWarning, RtsgeomWarning) and issubclass(ProbeWarning, RuntimeWarning)
    show_warning(ProbeWarning("front end(s) [3] not detected"), ProbeWarning, __file__, 10)
    show_warning(RuntimeWarning("invalid value encountered"), RuntimeWarning, __file__, 11,
                 line="x = 0 / 0")
    err = capsys.readouterr().err.splitlines()
    assert err == ["rtsgeom: warning: front end(s) [3] not detected",
                   "rtsgeom: warning: RuntimeWarning: invalid value encountered"]


def test_pair_chains_group_pairs_through_shared_front_ends():
    """Pairs that share a front end, directly or through others, form one chain (in the
    given order); the others are chains of their own."""
    from rtsgeom.calibration.chains import pair_chains
    assert pair_chains([(0, 1), (2, 3), (3, 4), (6, 7), (1, 2)]) == [
        [(0, 1), (2, 3), (3, 4), (1, 2)], [(6, 7)]]
    assert pair_chains([(0, 1), (2, 3), (4, 5)]) == [[(0, 1)], [(2, 3)], [(4, 5)]]
    assert pair_chains([]) == []


@pytest.mark.slow
def test_chains_side_by_side_calibrate_as_the_one_by_one_loop():
    """calibrate_chained (five chains, two processes) gives the calibrations of the loop that
    calibrates one pair after the other at the offsets the pairs before it chained, bit for
    bit, on an arc whose front ends carry mounting and phase errors (chained offsets of tens
    of ps)."""
    from rtsgeom.calibration.chains import calibrate_chained
    from rtsgeom.calibration.channels import channel_offsets
    from rtsgeom.calibration.pair import calibrate_pair

    scene = dense_arc(10, 4.0, snr_db=20.0, chirps_per_tx=32)
    fes = [fe.evolve(radial_offset_m=0.3e-3 * (k % 3), phase_offset_rad=0.2 * k)
           for k, fe in enumerate(scene.rts.front_ends)]
    scene = scene.evolve(rts=scene.rts.evolve(front_ends=tuple(fes)))
    setup = build_setup(scene)
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, scene.seed)
    pairs = [(0, 1), (1, 2), (3, 4), (5, 6), (7, 8)]
    loop = {}
    for pair in pairs:
        base = channel_offsets(setup.fe.count, loop)
        loop[pair] = calibrate_pair(setup, paths, pair, probe, (base[pair[0]], base[pair[0]]),
                                    seed=scene.seed)
    got = calibrate_chained(setup, paths, pairs, probe, workers=2)
    assert list(got) == pairs
    assert [got[p].to_dict() for p in pairs] == [loop[p].to_dict() for p in pairs]
    assert abs(loop[(0, 1)].delta_tau_s) > 1e-12  # (1, 2) was calibrated at a chained offset
