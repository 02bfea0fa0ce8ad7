"""Objects no suite holds, built here (z up, metres): a can, a cone (a truncated one, wide end down),
a stemmed glass, a bottle with a neck, a curved tapering tube (a banana) and a book; and a second
set (`--second`): a hexagonal prism, a wedge (a door stop), an L bracket, a torus, a frustum (a
lamp's base) and a tall carton. Used by scripts/heldout_objects (planned on as meshes) and
scripts/heldout_scans (planned on their simulated scans); plain Python (no numpy)."""
import math
import sys

NAMES = ("can", "cone", "glass", "bottle", "banana", "book")
SECOND = ("hex_prism", "wedge", "l_bracket", "torus", "frustum", "carton")


def write(out, name, V, F):
    with open(f"{out}/{name}.ply", "w") as o:
        o.write("ply\nformat ascii 1.0\nelement vertex %d\nproperty double x\nproperty double y\n"
                "property double z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n" % (len(V), len(F)))
        o.writelines("%.6f %.6f %.6f\n" % v for v in V)
        o.writelines("%d %s\n" % (len(f), " ".join(map(str, f))) for f in F)


def extrude(poly, h, tris):
    """A prism: polygon `poly` (counter-clockwise in xy, triangulated by `tris`) from z 0 to h."""
    n = len(poly)
    V = [(x, y, 0.0) for x, y in poly] + [(x, y, h) for x, y in poly]
    F = [f for a, b, c in tris for f in ((a, c, b), (n + a, n + b, n + c))]
    for i in range(n):
        j = (i + 1) % n
        F += [(i, j, n + j), (i, n + j, n + i)]
    return V, F


def revolve(profile, n=32):
    """A solid of revolution about z: (radius, height) from the bottom's middle to the top's."""
    V, F, rings = [], [], []
    for r, z in profile:
        if r == 0:
            rings.append([len(V)]); V.append((0, 0, z))
        else:
            rings.append(list(range(len(V), len(V) + n)))
            V += [(r * math.cos(2 * math.pi * k / n), r * math.sin(2 * math.pi * k / n), z) for k in range(n)]
    for A, B in zip(rings, rings[1:]):
        for k in range(n):
            if len(A) == 1:
                F.append((A[0], B[(k + 1) % n], B[k]))
            elif len(B) == 1:
                F.append((A[k], A[(k + 1) % n], B[0]))
            else:
                F += [(A[k], A[(k + 1) % n], B[(k + 1) % n]), (A[k], B[(k + 1) % n], B[k])]
    return V, F


def write_second(out):
    r = 0.028  # a hexagonal prism 5.6 cm across its corners, 16 cm long along x, on a flat face
    V, F = extrude([(r * math.cos(math.pi / 3 * k), r * math.sin(math.pi / 3 * k)) for k in range(6)], 0.16,
                   [(0, i, i + 1) for i in range(1, 5)])
    write(out, "hex_prism", [(z, x, y + r * math.sin(math.pi / 3)) for x, y, z in V], F)  # cyclic: same handedness
    # A wedge: a right triangle 12 cm long and 3.5 cm tall (x, z), 5 cm wide (y); swapping y and z
    # mirrors, so the faces are turned over.
    V, F = extrude([(0, 0), (0.12, 0), (0.0, 0.035)], 0.05, [(0, 1, 2)])
    write(out, "wedge", [(x, z, y) for x, y, z in V], [(a, c, b) for a, b, c in F])
    # An L bracket: legs 10 and 7 cm, 2 cm thick (x, z), 4 cm wide (y).
    V, F = extrude([(0, 0), (0.10, 0), (0.10, 0.02), (0.02, 0.02), (0.02, 0.07), (0, 0.07)], 0.04,
                   [(0, 1, 2), (0, 2, 3), (0, 3, 4), (0, 4, 5)])
    write(out, "l_bracket", [(x, z, y) for x, y, z in V], [(a, c, b) for a, b, c in F])
    n, m, R, rt = 32, 16, 0.045, 0.018  # a torus lying: 4.5 cm to the tube's middle, the tube 3.6 cm across
    V = [((R + rt * math.cos(2 * math.pi * j / m)) * math.cos(2 * math.pi * i / n),
          (R + rt * math.cos(2 * math.pi * j / m)) * math.sin(2 * math.pi * i / n), rt + rt * math.sin(2 * math.pi * j / m))
         for i in range(n) for j in range(m)]
    F = []
    for i in range(n):
        for j in range(m):
            a, b = i * m + j, ((i + 1) % n) * m + j
            c, d = ((i + 1) % n) * m + (j + 1) % m, i * m + (j + 1) % m
            F += [(a, b, c), (a, c, d)]
    write(out, "torus", V, F)
    write(out, "frustum", *revolve([(0, 0), (0.06, 0), (0.035, 0.09), (0, 0.09)]))  # a lamp's base, 9 cm tall
    bx, by, bz = 0.07, 0.07, 0.20  # a tall carton
    V = [(a, b, c) for c in (0, bz) for (a, b) in [(0, 0), (bx, 0), (bx, by), (0, by)]]
    write(out, "carton", V, [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)])


def write_objects(out):
    write(out, "can", *revolve([(0, 0), (0.033, 0), (0.033, 0.12), (0, 0.12)]))
    write(out, "cone", *revolve([(0, 0), (0.045, 0), (0.01, 0.09), (0, 0.09)]))
    write(out, "glass", *revolve([(0, 0), (0.035, 0), (0.035, 0.004), (0.005, 0.006), (0.004, 0.07), (0.03, 0.09),
                             (0.04, 0.14), (0, 0.14)]))
    write(out, "bottle", *revolve([(0, 0), (0.035, 0), (0.035, 0.17), (0.012, 0.21), (0.012, 0.24), (0, 0.24)]))
    # A tube along a 12 cm arc of +-0.6 rad, 1.8 cm across at its middle tapering to 0.7 cm, capped.
    n, m, R, r = 16, 24, 0.12, 0.018
    V, F, rows = [], [], []
    for i in range(m + 1):
        t = -0.6 + 1.2 * i / m
        cx, cz, rr = R * math.sin(t), R * (1 - math.cos(t)), r * (0.4 + 0.6 * math.sin(math.pi * i / m))
        rows.append(list(range(len(V), len(V) + n)))
        V += [(cx - rr * math.cos(2 * math.pi * k / n) * math.sin(t), rr * math.sin(2 * math.pi * k / n),
               cz + rr * math.cos(2 * math.pi * k / n) * math.cos(t)) for k in range(n)]
    for A, B in zip(rows, rows[1:]):
        for k in range(n):
            F += [(A[k], A[(k + 1) % n], B[(k + 1) % n]), (A[k], B[(k + 1) % n], B[k])]
    for row, sign in ((rows[0], 1), (rows[-1], -1)):
        c = len(V)
        V.append(tuple(sum(V[j][q] for j in row) / n for q in range(3)))
        F += [(c, row[(k + 1) % n], row[k]) if sign > 0 else (c, row[k], row[(k + 1) % n]) for k in range(n)]
    write(out, "banana", V, F)
    bx, by, bz = 0.15, 0.22, 0.03  # a book
    V = [(a, b, c) for c in (0, bz) for (a, b) in [(0, 0), (bx, 0), (bx, by), (0, by)]]
    F = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    write(out, "book", V, F)


if __name__ == "__main__":
    if "--second" in sys.argv[2:]:
        write_second(sys.argv[1])
    else:
        write_objects(sys.argv[1])
