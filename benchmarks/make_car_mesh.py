"""Write scenes/car.ply: a car-sized convex body (1.8 m x 4.5 m x 1.45 m) of rounded
footprint and a cabin, a few hundred facets."""
import numpy as np, trimesh
def rounded(w, l, r, n=6):
    pts = []
    for cx, cy, a0 in ((w/2-r, l/2-r, 0), (-(w/2-r), l/2-r, 90), (-(w/2-r), -(l/2-r), 180), (w/2-r, -(l/2-r), 270)):
        for a in np.radians(np.linspace(a0, a0+90, n)):
            pts.append((cx + r*np.cos(a), cy + r*np.sin(a)))
    return np.array(pts)
body = rounded(1.8, 4.5, 0.35)
cabin = rounded(1.5, 2.4, 0.3) + [0, -0.3]
pts = np.vstack([np.c_[body, np.full(len(body), 0.25)], np.c_[body, np.full(len(body), 0.9)],
                 np.c_[cabin, np.full(len(cabin), 1.45)]])
m = trimesh.convex.convex_hull(pts)
m = m.subdivide()
print(len(m.faces), m.is_watertight)
m.export("scenes/car.ply")
