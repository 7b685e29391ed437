"""Which front ends enclose a direction.

1-D (an arc, azimuth-only RuT): sorted intervals of the front ends' azimuths. 2-D (a sphere and
a RuT with elevation): the Delaunay triangulation (``scipy.spatial.Delaunay``, ``find_simplex``)
of the front ends' direction cosines u = (sin az cos el, sin el); a triangle's two neighbours
that together form a convex quadrilateral of four front ends make one quadrilateral cell.
"""

from __future__ import annotations

import numpy as np

from ..errors import CellUnreachable

__all__ = ["enclosing_cell", "CellUnreachable"]


def _interval(u: float, x: np.ndarray) -> tuple[int, ...]:
    order = np.argsort(x)
    a = x[order]
    k = int(np.searchsorted(a, u, side="right")) - 1
    k = min(max(k, 0), a.size - 2)
    if a.size < 2 or not a[k] <= u <= a[k + 1]:
        raise CellUnreachable(f"direction cosine {u:.6f} is outside the front ends' span "
                              f"[{a[0]:.6f}, {a[-1]:.6f}]")
    return int(order[k]), int(order[k + 1])


def enclosing_cell(u, points, quads: bool = True) -> tuple[int, ...]:
    """Indices of the front ends whose cell holds direction ``u`` (D,).

    ``points`` (F, D): the front ends' direction cosines. D = 1: the adjacent pair (sorted
    intervals). D = 2: the enclosing Delaunay triangle, or with ``quads`` the quadrilateral it
    forms with the neighbour across its longest edge when those four front ends are the
    corners of a convex quadrilateral (a rectangular cell of an az x el grid: its diagonal is
    that edge). Raises :class:`CellUnreachable` outside the front ends' hull."""
    pts = np.asarray(points, float)
    u = np.atleast_1d(np.asarray(u, float))
    if pts.shape[1] == 1:
        return _interval(float(u[0]), pts[:, 0])
    if pts.shape[0] < 3:
        raise CellUnreachable(f"{pts.shape[0]} front ends cannot enclose a 2-D direction "
                              "(a cell needs at least 3 not on one line)")
    # here, not at the top: scipy.spatial (70 ms of imports) serves the 2-D cells alone
    from scipy.spatial import ConvexHull, Delaunay
    tri = Delaunay(pts)
    s = int(tri.find_simplex(u[None])[0])
    if s < 0:
        raise CellUnreachable(
            f"direction (u_az, u_el) = ({u[0]:.6f}, {u[1]:.6f}) is outside every cell of the "
            f"front ends (their hull spans u_az [{pts[:, 0].min():.6f}, {pts[:, 0].max():.6f}],"
            f" u_el [{pts[:, 1].min():.6f}, {pts[:, 1].max():.6f}])")
    corners = [int(i) for i in tri.simplices[s]]
    if not quads:
        return tuple(sorted(corners))
    edge_len = [np.linalg.norm(pts[corners[(k + 1) % 3]] - pts[corners[(k + 2) % 3]])
                for k in range(3)]
    k = int(np.argmax(edge_len))  # the edge opposite corner k
    nb = int(tri.neighbors[s][k])
    if nb < 0:
        return tuple(sorted(corners))
    other = [int(i) for i in tri.simplices[nb] if i not in corners][0]
    four = corners + [other]
    if len(ConvexHull(pts[four]).vertices) == 4:  # convex: a quadrilateral cell
        return tuple(sorted(four))
    return tuple(sorted(corners))
