"""Tests of ``rtsgeom.calibration.channels``: closed forms and invariants on grids of inputs."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import make_scene, small_noiseless


@pytest.mark.parametrize("grid", [(2, 1), (4, 1), (2, 2), (3, 2), (3, 3)])
def test_pair_edges_are_neighbours_in_1d_and_delaunay_edges_in_2d(grid):
    """The pairs an N-channel calibration sweeps: in 1-D the F - 1 neighbours by direction
    (whatever the channel numbering); in 2-D the edges of the Delaunay triangulation, 3 F - 3
    - h of them for F points with h on the hull (Euler), each joining two given channels."""
    from rtsgeom.calibration.channels import pair_edges
    n_a, n_e = grid
    rng = np.random.default_rng(n_a * 10 + n_e)
    az = np.arange(n_a) * 0.1 + rng.uniform(-0.01, 0.01, n_a)
    if n_e == 1:
        u = az[:, None]
        perm = rng.permutation(n_a)
        u_fe = np.empty_like(u)
        u_fe[perm] = u  # channel perm[k] sits at the k-th direction
        edges = pair_edges(u_fe, range(n_a))
        want = sorted(tuple(sorted((int(perm[k]), int(perm[k + 1])))) for k in range(n_a - 1))
        assert sorted(edges) == want
        return
    el = np.arange(n_e) * 0.08
    u_fe = np.array([(a, e) for a in az for e in el]) + rng.uniform(-0.003, 0.003, (n_a * n_e, 2))
    f = len(u_fe)
    from scipy.spatial import ConvexHull
    h = len(ConvexHull(u_fe).vertices)
    edges = pair_edges(u_fe, range(f))
    assert len(edges) == len(set(edges)) == 3 * f - 3 - h
    assert all(0 <= i < j < f for i, j in edges)
    # a subset of channels: only edges among them
    sub = [0, 1, f - 1]
    assert {q for e in pair_edges(u_fe, sub) for q in e} == set(sub)


def test_channel_calibration_of_one_channel_is_its_own_reference():
    from rtsgeom.calibration.channels import calibrate_channels
    from rtsgeom.calibration.probes import probe_front_ends
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    setup = build_setup(small_noiseless())
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, 1)
    for q in (0, 1):
        cal = calibrate_channels(setup, paths, [q], probe)
        assert cal.reference == q and np.all(cal.offsets_s == 0.0) and cal.tree == []
        assert cal.gain_correction == pytest.approx(tuple(probe.gain_correction))


@pytest.mark.parametrize("seed", [3, 5])
def test_channel_calibration_depends_on_the_seed_modulo_2_to_the_32(seed):
    """``scene.seed`` may be up to 2^63 - 1; every noise draw of the calibration (the pair
    sweeps and the residual check at the cell centre) takes it modulo 2^32, so seeds 2^32
    apart give the same calibration and residual, and neighbouring seeds different noise."""
    from rtsgeom.calibration.channels import calibrate_channels
    from rtsgeom.calibration.probes import probe_front_ends
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    setup = build_setup(make_scene(lambda d: d["radar"].update(
        chirps_per_tx=32, samples_per_chirp=128, adc_rate_hz=12.5e6, snr_db=20.0)))
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, 1)

    def cal(s):
        return calibrate_channels(setup, paths, (0, 1), probe, seed=s, span_s=(-0.3e-9, 0.3e-9),
                                  step_s=100e-12)
    a = cal(seed)
    for k in (1, 2 ** 8):
        b = cal(seed + k * 2 ** 32)
        assert np.array_equal(a.offsets_s, b.offsets_s) and a.residual_deg == b.residual_deg
    assert cal(seed + 1).residual_deg != a.residual_deg
