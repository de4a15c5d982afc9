#!/usr/bin/env python3
"""Writes a closed cylinder as an OBJ: a side of quads split into triangles and two caps as triangle fans.

Usage: python3 make_cylinder.py OUT.obj [--segments 64] [--radius 1] [--height 2]

The axis is +Y (glTF's up), centred on the origin. Positions only (no normals): the side and the caps share
the two rings of vertices, so the mesh is closed and manifold, and the 90-degree rims are creases while the
side's edges (5.6 degrees apart at 64 segments) are smooth. Faces wind counter-clockwise seen from outside.
"""

import argparse
import math


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out")
    parser.add_argument("--segments", type=int, default=64)
    parser.add_argument("--radius", type=float, default=1.0)
    parser.add_argument("--height", type=float, default=2.0)
    args = parser.parse_args()
    n, r, h = args.segments, args.radius, args.height
    if n < 3:
        parser.error("--segments must be at least 3")

    lines = [f"# closed cylinder: {n} segments, radius {r}, height {h}, axis +Y", "o cylinder"]
    # Vertices 1..n: bottom ring, n+1..2n: top ring, 2n+1: bottom centre, 2n+2: top centre (OBJ is 1-based).
    for y in (-h / 2, h / 2):
        for i in range(n):
            a = 2 * math.pi * i / n
            x, z = r * math.cos(a) + 0.0, -r * math.sin(a) + 0.0  # + 0.0 turns -0.0 into 0.0
            lines.append(f"v {x:.9g} {y:.9g} {z:.9g}")
    lines.append(f"v 0 {-h / 2:.9g} 0")
    lines.append(f"v 0 {h / 2:.9g} 0")
    bottom_centre, top_centre = 2 * n + 1, 2 * n + 2

    # Going round with i, the ring runs counter-clockwise seen from +Y (x = cos a, z = -sin a).
    for i in range(n):
        j = (i + 1) % n
        b0, b1, t0, t1 = 1 + i, 1 + j, 1 + n + i, 1 + n + j
        lines.append(f"f {b0} {b1} {t1}")  # side, outward
        lines.append(f"f {b0} {t1} {t0}")
    for i in range(n):
        j = (i + 1) % n
        lines.append(f"f {top_centre} {1 + n + i} {1 + n + j}")  # top fan, facing +Y
        lines.append(f"f {bottom_centre} {1 + j} {1 + i}")  # bottom fan, facing -Y

    with open(args.out, "w", encoding="ascii") as f:
        f.write("\n".join(lines) + "\n")
    print(f"{args.out}: {2 * n + 2} vertices, {4 * n} triangles")


if __name__ == "__main__":
    main()
