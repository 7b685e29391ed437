"""Write scenes/car.ply: a car-sized convex body (1.8 m x 4.5 m x 1.45 m) of rounded footprint
and a cabin, a few hundred facets.

The rounded corners (radius 0.35 m) are cut into 30 facets of 3 deg each: physical optics sees a
faceted curve as flat strips, each returning only within its own lobe, ``lambda / (2 w)`` for a
strip ``w = radius x step`` wide; the lobes of neighbouring strips overlap at half their width
for ``step <= sqrt(lambda / (2 radius))`` (4.3 deg at 77 GHz). With 3 deg steps the car seen
15 m away by a RuT at a bumper radar's height returns 12 +- 1 dBsm at every heading
between its nose and its flank, as a cylinder of the corner's radius and height does in its
Fresnel zone (k a |F(L)|^2, 12 dBsm); 18 deg steps left dips of up to 18 dB between the
strips' lobes as the car turned, 6 deg steps dips of 13 dB. z = 0 is 0.5 m above the ground
(MOUNT_M), a bumper radar's mounting height: the object's origin sits at the RuT's height, so the
mesh's ground is at z = -0.5 m. Seen from the ground (z = 0 at the ground) the RuT would be below
the body, which starts 0.25 m up, and see only its lower edges (4 dBsm nose on, not 28).
"""
import numpy as np
import trimesh

CORNER_POINTS = 31  # 30 facets of 3 deg per quarter circle
MOUNT_M = 0.5  # the RuT's height above the ground: the mesh's z = 0


def rounded(w, l, r, n=CORNER_POINTS):
    pts = []
    for cx, cy, a0 in ((w/2-r, l/2-r, 0), (-(w/2-r), l/2-r, 90), (-(w/2-r), -(l/2-r), 180),
                       (w/2-r, -(l/2-r), 270)):
        for a in np.radians(np.linspace(a0, a0+90, n)):
            pts.append((cx + r*np.cos(a), cy + r*np.sin(a)))
    return np.array(pts)


def main() -> None:
    body = rounded(1.8, 4.5, 0.35)
    cabin = rounded(1.5, 2.4, 0.3) + [0, -0.3]
    pts = np.vstack([np.c_[body, np.full(len(body), 0.25)], np.c_[body, np.full(len(body), 0.9)],
                     np.c_[cabin, np.full(len(cabin), 1.45)]]) - [0, 0, MOUNT_M]
    m = trimesh.convex.convex_hull(pts)
    print(len(m.faces), len(m.facets), m.is_watertight)
    m.export("scenes/car.ply")


if __name__ == "__main__":
    main()
