"""How a Monte-Carlo study draws: one small frozen config shared by every study that draws
built setups (tolerance, the yield search, the chain check, arc design, coverage, a drive).

:class:`MonteCarlo` says how many setups are drawn, from which seed, with which distribution,
in chunks of what size, by which mapper (a process pool or a Dask cluster), reporting progress
where, and whether the target's sub-bin position is drawn per draw. What is drawn (the error
scales: :class:`~.draws.Bounds`) and what is asked of the draws (the spec, the cases) belong to
the study. The draws depend on ``seed``, ``draws`` and ``distribution`` alone: neither the chunk
size nor the mapper changes a result.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Callable, Iterable

from .args import STUDY_ARGS, Arg, check_sigma_mm, check_study_args
from .draws import DEFAULT_CHUNK

# the arguments' declarations (.args) are re-exported: the studies import them with the config
__all__ = ["MonteCarlo", "Progress", "Mapper", "MC_FIELDS", "Arg", "STUDY_ARGS",
           "check_study_args", "check_sigma_mm"]

Progress = Callable[[str, int, int], None]  # (label, draws done, draws total)
Mapper = Callable[[Callable, list], Iterable]  # ordered map of a pure function over chunks


@dataclass(frozen=True)
class MonteCarlo:
    """How a study draws its built setups.

    Parameters
    ----------
    draws : int
        Setups drawn, in [1, 10 000 000] (:data:`STUDY_ARGS`; the engine also takes 0).
    seed : int, optional
        Random seed in [0, 2**63 - 1]; None: the scene's seed (:meth:`seeded`).
    distribution : {'normal', 'uniform'}
        The errors' distribution: the scales are standard deviations, or uniform bounds.
    chunk : int
        Draws evaluated at once (memory); results do not depend on it.
    mapper : callable, optional
        ``mapper(func, chunks)``, an ordered map (a process pool, a Dask cluster); None: in
        this process, one chunk at a time.
    progress : callable, optional
        ``progress(label, done, total)`` after each chunk.
    subbin : bool
        The target's sub-bin position drawn per draw (uniform over one range bin); False:
        at the bin centre.

    Raises
    ------
    ParameterError
        A field outside its range, naming it.

    Examples
    --------
    >>> mc = MonteCarlo(draws=2000, seed=4)
    >>> mc.seeded(scene.seed).seed  # doctest: +SKIP
    4
    """

    draws: int = 10_000
    seed: int | None = None
    distribution: str = "normal"
    chunk: int = DEFAULT_CHUNK
    mapper: Mapper | None = dataclasses.field(default=None, compare=False)
    progress: Progress | None = dataclasses.field(default=None, compare=False)
    subbin: bool = True

    def __post_init__(self):
        fn = "MonteCarlo"
        STUDY_ARGS["draws"].check(self.draws, "draws", fn, lo=0)  # the engine: 0, no result
        check_study_args(fn, seed=self.seed, distribution=self.distribution)
        STUDY_ARGS["chunk"].check(self.chunk, "chunk", fn, lo=1)  # any chunk: the same draws

    def __repr__(self) -> str:
        seed = "scene's" if self.seed is None else self.seed
        return (f"MonteCarlo(draws={self.draws}, seed={seed}, {self.distribution}"
                + ("" if self.subbin else ", bin centre") + ")")

    def seeded(self, seed: int) -> "MonteCarlo":
        """This config with ``seed`` where it has none (a scene's seed)."""
        return self if self.seed is not None else dataclasses.replace(self, seed=int(seed))

    def evolve(self, **changes) -> "MonteCarlo":
        """A copy with ``changes`` (checked again)."""
        return dataclasses.replace(self, **changes)

    @classmethod
    def split(cls, options: dict) -> tuple["MonteCarlo", dict]:
        """``options`` of an old-style call parted into a :class:`MonteCarlo` (its fields) and
        the rest."""
        mine = {k: options[k] for k in MC_FIELDS if k in options}
        return cls(**mine), {k: v for k, v in options.items() if k not in MC_FIELDS}


#: the names :class:`MonteCarlo` takes
MC_FIELDS = tuple(f.name for f in dataclasses.fields(MonteCarlo))
