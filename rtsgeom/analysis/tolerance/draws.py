"""The tolerance studies' draws: one stream of mounting errors per front end, the RuT's pose
and the target's sub-bin position, chunk by chunk, the same whatever the chunk size.

Each draw moves every front end drawn radially, tangentially and in height (normal with the
given sigmas, or uniform within the given bounds: :class:`Bounds`), turns it about the vertical
(yaw) and the tangent (pitch), moves and turns the RuT, and places the target at a sub-bin
position: uniform over one range bin in steps of the RTS's delay resolution (the positions an
RTS can set, :func:`subbin_positions`).

Four independent streams, so that adding one kind of error leaves the others' draws as they
were:

* offsets: ``numpy.random.default_rng(seed)``, unit draws (k, F, 3) chunk by chunk;
* sub-bin positions: ``default_rng([seed, 1])``, indices (k,) into the positions;
* the RuT's pose: ``default_rng([seed, 2])``, (k, 4) (x, y, z, yaw);
* the rotations: ``default_rng([seed, 3])``, (k, F, 2) (yaw, pitch).

A chunk is handed around as the streams' states at its start (:class:`DrawChunk`, a few hundred
bytes instead of the draws: what a cluster is sent), and regenerates its draws bit for bit. A
front-end pair's study draws F = 2 front ends, a cell's its Q, a whole arc's every front end:
the offsets of a two-front-end arc are the pair study's, bit for bit.

Tolerance bounds are given as the value of the tolerance and the sigma level it stands for:
normal errors have sigma = bound / sigma_level ("+-0.2 mm at 3 sigma"); uniform errors are
uniform in [-bound, +bound] (the sigma level does not apply).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Iterator

import numpy as np
from scipy.constants import c

from ...errors import ParameterError
from .args import DISTRIBUTIONS, MAX_SIGMA_MM, STUDY_ARGS

__all__ = ["AXES", "DISTRIBUTIONS", "DEFAULT_CHUNK", "MAX_SIGMA_MM", "Bounds",
           "unit_block", "subbin_positions", "centre_index", "DrawChunk", "DrawStreams", "draw_chunks",
           "standard_draws", "subbin_draws", "draw_offsets", "draw_subbins"]

AXES = ("radial", "tangential", "height")
DEFAULT_CHUNK = 10_000

#: the streams beside the offsets' ``default_rng(seed)``: ``default_rng([seed, stream])``;
#: every quantity drawn beside the offsets has its own, so none is correlated with them
SUBBIN_STREAM, RUT_STREAM, ROTATION_STREAM = 1, 2, 3
PHASE_STREAM, NOISE_STREAM = 4, 7  # the RuT's antenna phases, receiver noise (kpi)


@dataclass(frozen=True)
class Bounds:
    """The per-draw error scales (SI): the standard deviation (normal) or the bound (uniform).

    ``offsets_m`` (3,) radial, tangential, height of every front end; ``yaw_rad``,
    ``pitch_rad`` its mounting rotations; ``rut_position_m`` (3,) and ``rut_yaw_rad`` the
    RuT's pose.

    Attributes
    ----------
    offsets_m : (float, float, float)
    yaw_rad, pitch_rad : float
    rut_position_m : (float, float, float)
    rut_yaw_rad : float
    """

    offsets_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    yaw_rad: float = 0.0
    pitch_rad: float = 0.0
    rut_position_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rut_yaw_rad: float = 0.0

    @classmethod
    def from_tolerances(cls, tol: dict, distribution: str, sigma_level: float = 3.0) -> "Bounds":
        """From tolerances (SI; keys as the fields): the scale is tol / sigma_level for normal
        errors, tol itself for uniform ones."""
        k = 1.0 / sigma_level if distribution == "normal" else 1.0
        return cls(tuple(k * float(v) for v in tol.get("offsets_m", (0.0,) * 3)),
                   k * float(tol.get("yaw_rad", 0.0)), k * float(tol.get("pitch_rad", 0.0)),
                   tuple(k * float(v) for v in tol.get("rut_position_m", (0.0,) * 3)),
                   k * float(tol.get("rut_yaw_rad", 0.0)))

    def scaled(self, s: float) -> "Bounds":
        return Bounds(tuple(s * v for v in self.offsets_m), s * self.yaw_rad, s * self.pitch_rad,
                      tuple(s * v for v in self.rut_position_m), s * self.rut_yaw_rad)

    def with_offsets(self, offsets_m) -> "Bounds":
        """These bounds with other offset scales (3,) (m)."""
        return Bounds(tuple(float(x) for x in offsets_m), self.yaw_rad, self.pitch_rad,
                      self.rut_position_m, self.rut_yaw_rad)

    @property
    def rotations(self) -> bool:
        return self.yaw_rad != 0.0 or self.pitch_rad != 0.0

    @property
    def rut_pose(self) -> bool:
        return any(self.rut_position_m) or self.rut_yaw_rad != 0.0

    @property
    def zero(self) -> bool:
        """Whether no error is drawn at all (the draws differ in the target's position only)."""
        return not (any(self.offsets_m) or self.rotations or self.rut_pose)

    def check(self) -> None:
        vals = [*self.offsets_m, self.yaw_rad, self.pitch_rad, *self.rut_position_m,
                self.rut_yaw_rad]
        if not all(math.isfinite(v) and v >= 0 for v in vals):
            raise ParameterError(f"tolerance bounds {vals}: must be finite and >= 0")

    def to_dict(self) -> dict:
        return {"radial_mm": self.offsets_m[0] * 1e3, "tangential_mm": self.offsets_m[1] * 1e3,
                "height_mm": self.offsets_m[2] * 1e3, "yaw_deg": math.degrees(self.yaw_rad),
                "pitch_deg": math.degrees(self.pitch_rad),
                "rut_position_mm": [v * 1e3 for v in self.rut_position_m],
                "rut_yaw_deg": math.degrees(self.rut_yaw_rad)}


def unit_block(rng: np.random.Generator, shape, distribution: str) -> np.ndarray:
    """The next unit-scale draws of ``shape`` from ``rng``: standard normal, or uniform in
    [-1, 1]."""
    if distribution == "normal":
        return rng.standard_normal(shape)
    return rng.uniform(-1.0, 1.0, shape)


def _subbin_block(rng: np.random.Generator, k: int, positions: int) -> np.ndarray:
    """The next ``k`` sub-bin indices of the sub-bin stream ``rng``."""
    return np.minimum((rng.random(k) * positions).astype(int), positions - 1)


def subbin_positions(range_resolution_m: float, delay_resolution_s: float) -> np.ndarray:
    """The sub-bin positions (delay steps, int (U,)) across one range bin of
    ``range_resolution_m`` for an RTS of ``delay_resolution_s``: U = round(2 dR / (c0 dtau))
    (at least 1) steps, ``arange(U) - U // 2`` (the bin centre is 0). A real target sits
    anywhere in its range bin; an RTS places it at a delay it can realise."""
    n_bin = max(1, round(2 * float(range_resolution_m) / c / float(delay_resolution_s)))
    return np.arange(n_bin) - n_bin // 2


def centre_index(steps) -> int:
    """Index of the bin centre (offset 0) in sub-bin positions ``steps``."""
    return int(np.flatnonzero(np.asarray(steps) == 0)[0])


def _generator_at(state: dict) -> np.random.Generator:
    """A generator whose bit generator continues from the saved ``state``."""
    bit = getattr(np.random, state["bit_generator"])()
    bit.state = state
    return np.random.Generator(bit)


@dataclass(frozen=True)
class DrawChunk:
    """One chunk of a study's draws, as the states of its streams at the chunk's start (see the
    module); :meth:`unit` and :meth:`errors` regenerate the chunk's draws bit for bit (a stream
    continued from a saved state is the same stream). A stream not drawn has state None."""

    k: int
    count: int  # front ends drawn
    distribution: str
    state: dict  # of the offsets' stream default_rng(seed)
    subbin_state: dict | None  # None: every draw at the bin centre
    rut_state: dict | None
    rotation_state: dict | None
    positions: int  # sub-bin positions across one bin
    centre: int  # the bin centre's index (without sub-bin draws)

    def offsets(self) -> np.ndarray:
        """Unit offsets (k, F, 3)."""
        return unit_block(_generator_at(self.state), (self.k, self.count, 3), self.distribution)

    def subbin(self) -> np.ndarray:
        """The chunk's sub-bin indices (k,)."""
        if self.subbin_state is None:
            return np.full(self.k, self.centre)
        return _subbin_block(_generator_at(self.subbin_state), self.k, self.positions)

    def errors(self, bounds: Bounds) -> dict:
        """The chunk's physical errors: ``offsets_m`` (k, F, 3), ``yaw_rad``, ``pitch_rad``
        (k, F), ``rut_offset_m`` (k, 3), ``rut_yaw_rad`` (k,) (None where its bound is zero or
        its stream was not drawn: the nominal arithmetic stays untouched) and ``subbin`` (k,)."""
        out = {"offsets_m": self.offsets() * np.asarray(bounds.offsets_m, float),
               "yaw_rad": None, "pitch_rad": None, "rut_offset_m": None, "rut_yaw_rad": None,
               "subbin": self.subbin()}
        if bounds.rotations and self.rotation_state is not None:
            rot = unit_block(_generator_at(self.rotation_state), (self.k, self.count, 2),
                             self.distribution)
            out["yaw_rad"], out["pitch_rad"] = rot[..., 0] * bounds.yaw_rad, rot[..., 1] * bounds.pitch_rad
        if bounds.rut_pose and self.rut_state is not None:
            rut = unit_block(_generator_at(self.rut_state), (self.k, 4), self.distribution)
            out["rut_offset_m"] = rut[:, :3] * np.asarray(bounds.rut_position_m)
            out["rut_yaw_rad"] = rut[:, 3] * bounds.rut_yaw_rad
        return out


@dataclass(frozen=True)
class DrawStreams:
    """Which of a study's random streams :func:`draw_chunks` draws beside the offsets':
    ``positions``, the count of sub-bin positions (None: no sub-bin stream, every draw at
    the bin centre ``centre``, an index into them); ``rotations`` (the front ends' yaw and
    pitch) and ``rut`` (the RuT's pose): whether those streams are drawn."""

    positions: int | None = None
    centre: int = 0
    rotations: bool = False
    rut: bool = False


def draw_chunks(seed: int, draws: int, count: int, distribution: str = "normal",
                chunk: int = DEFAULT_CHUNK, streams: DrawStreams = DrawStreams()
                ) -> Iterator[DrawChunk]:
    """A study's draws chunk by chunk as :class:`DrawChunk` (the streams advanced here by
    drawing each chunk once: normal draws take a varying number of raw numbers each):
    ``draws`` of ``count`` front ends' offsets, and the ``streams`` beside them."""
    positions, centre = streams.positions, streams.centre
    rotations, rut = streams.rotations, streams.rut
    STUDY_ARGS["distribution"].check(distribution, "distribution", "draw_chunks")
    rng = np.random.default_rng(seed)
    g_sub = None if positions is None else np.random.default_rng([int(seed), SUBBIN_STREAM])
    g_rut = np.random.default_rng([seed, RUT_STREAM]) if rut else None
    g_rot = np.random.default_rng([seed, ROTATION_STREAM]) if rotations else None
    chunk = max(1, int(chunk))
    for start in range(0, draws, chunk):
        k = min(chunk, draws - start)
        states = []
        for g, shape, kind in ((rng, (k, count, 3), "unit"), (g_sub, k, "subbin"),
                               (g_rut, (k, 4), "unit"), (g_rot, (k, count, 2), "unit")):
            states.append(None if g is None else g.bit_generator.state)
            if g is not None and kind == "unit":
                unit_block(g, shape, distribution)
            elif g is not None:
                _subbin_block(g, k, int(positions))
        yield DrawChunk(k, int(count), distribution, states[0], states[1], states[2], states[3],
                        int(positions or 1), int(centre))


def standard_draws(seed: int, draws: int, distribution: str = "normal",
                   chunk: int = DEFAULT_CHUNK, front_ends: int = 2) -> Iterator[np.ndarray]:
    """The unit offsets (k, front_ends, 3) chunk by chunk: the offsets' stream of
    :func:`draw_chunks`, materialised."""
    for part in draw_chunks(seed, draws, front_ends, distribution, chunk):
        yield part.offsets()


def subbin_draws(seed: int, draws: int, positions: int, chunk: int = DEFAULT_CHUNK
                 ) -> Iterator[np.ndarray]:
    """The target's sub-bin indices (k,) chunk by chunk: the sub-bin stream of
    :func:`draw_chunks`, materialised."""
    rng = np.random.default_rng([int(seed), SUBBIN_STREAM])
    chunk = max(1, int(chunk))
    for start in range(0, draws, chunk):
        yield _subbin_block(rng, min(chunk, draws - start), positions)


def draw_offsets(seed: int, draws: int, sigma_m, distribution: str = "normal",
                 front_ends: int = 2) -> np.ndarray:
    """All mounting errors (draws, front_ends, 3) of a study at once (m; ``sigma_m`` (3,) the
    per-axis standard deviation or uniform bound)."""
    z = list(standard_draws(seed, draws, distribution, max(draws, 1), front_ends))
    z = z[0] if z else np.zeros((0, front_ends, 3))
    return z * np.asarray(sigma_m, float)


def draw_subbins(seed: int, draws: int, positions: int) -> np.ndarray:
    """All sub-bin positions (draws,) of a study at once."""
    z = list(subbin_draws(seed, draws, positions, max(draws, 1)))
    return z[0] if z else np.zeros(0, int)
