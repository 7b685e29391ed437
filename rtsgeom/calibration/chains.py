"""Pair calibrations chained along an arc, independent chains calibrated side by side.

Each pair (I, J) is calibrated with channel I at the delay offset the pairs before it chained
(``channels.channel_offsets``: J's offset is I's plus the pair's delay), so a pair waits for
the pairs that set its I. Pairs that share no front end with each other (directly or through
other pairs) set no offset the others read: each such group, a *chain*, is calibrated in
order on its own, and the chains in separate processes (``_lib.parallel.local_map``). The
calibrations are those of the one-by-one loop, bit for bit (the same pairs, each with the
same offsets, summed in the same order). 32 targets on a 64-front-end arc use 32 pairs, most
of them chains of one.
"""

from __future__ import annotations

import functools

from .._lib.parallel import available_cores, local_map
from .._lib.util import tell
from .channels import channel_offsets
from .pair import calibrate_pair

__all__ = ["pair_chains", "calibrate_chained", "MIN_PARALLEL_CHAINS"]

MIN_PARALLEL_CHAINS = 4  # fewer chains are calibrated here (forking would cost more)


def pair_chains(pairs) -> list[list[tuple[int, int]]]:
    """The ``pairs`` grouped into chains: pairs connected through shared front ends, each
    chain in the pairs' given order, the chains in the order of their first pair."""
    pairs = [tuple(int(q) for q in p) for p in pairs]
    root = {}

    def find(q):
        while root.setdefault(q, q) != q:
            root[q] = root[root[q]]
            q = root[q]
        return q
    for i, j in pairs:
        root[find(i)] = find(j)
    chains: dict = {}
    for p in pairs:
        chains.setdefault(find(p[0]), []).append(p)
    return list(chains.values())


def _calibrate_chain(setup, paths, probe, n_fe, chain):
    """One chain's calibrations in order, each at the offsets its chain set so far."""
    cals = {}
    for pair in chain:
        base = channel_offsets(n_fe, cals)
        cals[pair] = calibrate_pair(setup, paths, pair, probe, (base[pair[0]], base[pair[0]]),
                                    seed=setup.scene.seed)
    return cals


def calibrate_chained(setup, paths, pairs, probe, progress=None, workers=None) -> dict:
    """The ``pairs``' calibrations as the one-by-one loop gives them (module doc), the chains
    in ``workers`` processes (None: the cores this process may run on) where there are at
    least ``MIN_PARALLEL_CHAINS``. ``progress``: each pair's message, or a count of the
    pairs calibrated (``_lib.util.tell``)."""
    pairs = [tuple(int(q) for q in p) for p in pairs]
    chains = pair_chains(pairs)
    one = functools.partial(_calibrate_chain, setup, paths, probe, setup.fe.count)
    n_workers = available_cores() if workers is None else int(workers)
    if len(chains) < MIN_PARALLEL_CHAINS:
        n_workers = 1
    done = [0]
    sizes = [len(c) for c in chains]

    def counted(k, total):
        done[0] = sum(sizes[:k])
        tell(progress, None, "calibrating pairs", done[0], len(pairs))
    found = local_map(one, chains, n_workers, progress=counted)
    merged = {p: cal for cals in found for p, cal in cals.items()}
    cals = {p: merged[p] for p in pairs}
    if getattr(progress, "count", None) is None:  # messages, in the pairs' order
        for p in pairs:
            tell(progress, f"calibrated pair {p}: delta_tau {cals[p].delta_tau_s * 1e12:.1f} ps")
    return cals
