#!/usr/bin/env python3
"""Write scenes/meshes/hat.obj: a top hat as a closed solid of revolution.

The profile (radius, height) in m goes round the hat's cross-section: the
brim, 16 cm in radius and 6 mm thick, and a crown 9 cm in radius and 12 cm
tall whose walls and top are 6 mm thick, hollow from below (where a head
goes). Revolved about z in SEGMENTS steps, its quads and the top's fan make
a closed mesh, every triangle facing out. Run from the repository root:
python3 scenes/meshes/make_hat.py

Why 32 steps: the scene collides the hat as its convex decomposition
(parry's VHACD), which must keep the crown hollow for a coatrack's pole to
go in. With 24 steps it does not: two of its pieces are half rings of the
crown's wall just above the brim, and their hulls are half discs that close
the opening 8 mm up. With 32 steps (21 pieces) a 4 cm pole goes in to
within 1 cm of the crown's inside top.
"""
import math
import os

SEGMENTS = 32
T = 0.006  # wall thickness
PROFILE = [  # counter-clockwise in the (r, z) half-plane
    (0.084, 0.0),
    (0.16, 0.0),
    (0.16, T),
    (0.09, T),
    (0.09, 0.12),
    (0.0, 0.12),
    (0.0, 0.12 - T),
    (0.084, 0.12 - T),
]


def main():
    vertices, faces = [], []
    ring = {}  # profile index -> vertex numbers around (one on the axis)
    for i, (r, z) in enumerate(PROFILE):
        if r == 0.0:
            vertices.append((0.0, 0.0, z))
            ring[i] = [len(vertices)] * SEGMENTS
            continue
        ring[i] = []
        for k in range(SEGMENTS):
            a = 2.0 * math.pi * k / SEGMENTS
            vertices.append((r * math.cos(a), r * math.sin(a), z))
            ring[i].append(len(vertices))
    for i in range(len(PROFILE)):
        j = (i + 1) % len(PROFILE)
        for k in range(SEGMENTS):
            m = (k + 1) % SEGMENTS
            a, b, c, d = ring[i][k], ring[j][k], ring[j][m], ring[i][m]
            # Going along the profile (counter-clockwise in (r, z)) and
            # round z, (a, d, c, b) faces away from the solid.
            quad = [a, d, c, b]
            tri = [v for n, v in enumerate(quad) if v not in quad[:n]]
            faces.append(tri)
    here = os.path.dirname(os.path.abspath(__file__))
    with open(os.path.join(here, "hat.obj"), "w") as f:
        f.write("# A top hat, 16 cm brim and 12 cm crown, hollow from below.\n")
        f.write("# Written by scenes/meshes/make_hat.py: edit that, not this.\n")
        for v in vertices:
            f.write("v %.6f %.6f %.6f\n" % v)
        for face in faces:
            f.write("f " + " ".join(str(v) for v in face) + "\n")


main()
