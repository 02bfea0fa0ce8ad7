"""Meshes of hanging scenes no suite holds, built from round bars and boxes (z up, metres), and the
summary of a planner answer checked in Bullet. Used by scripts/heldout_hanging and
scripts/hook_variants; plain Python (no numpy), so it runs wherever the CLI does."""
import json
import math


def add(a, b): return tuple(x + y for x, y in zip(a, b))
def sub(a, b): return tuple(x - y for x, y in zip(a, b))
def mul(a, s): return tuple(x * s for x in a)
def dot(a, b): return sum(x * y for x, y in zip(a, b))
def cross(a, b): return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
def unit(a): return mul(a, 1 / math.sqrt(dot(a, a)))

class Mesh:
    """Closed parts, each wound outwards (checked by its signed volume), overlapping freely."""
    def __init__(self): self.V, self.F = [], []
    def part(self, V, F):
        vol = sum(dot(V[a], cross(V[b], V[c])) for a, b, c in F)
        if vol < 0: F = [(a, c, b) for a, b, c in F]
        o = len(self.V)
        self.V += V
        self.F += [(a + o, b + o, c + o) for a, b, c in F]
    def write(self, out, name):
        with open(f"{out}/{name}.ply", "w") as f:
            f.write("ply\nformat ascii 1.0\nelement vertex %d\nproperty double x\nproperty double y\n"
                    "property double z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n"
                    % (len(self.V), len(self.F)))
            f.writelines("%.6f %.6f %.6f\n" % v for v in self.V)
            f.writelines("3 %d %d %d\n" % t for t in self.F)

def box(m, lo, hi):
    V = [(x, y, z) for z in (lo[2], hi[2]) for y in (lo[1], hi[1]) for x in (lo[0], hi[0])]
    Q = ((0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5))
    m.part(V, [t for q in Q for t in ((q[0], q[1], q[2]), (q[0], q[2], q[3]))])

def frame(t):
    a = (1, 0, 0) if abs(t[0]) < 0.9 else (0, 1, 0)
    u = unit(cross(t, a))
    return u, cross(t, u)

def sweep(m, path, r, n=16, closed=False):
    """A round tube of radius r along a polyline (a ring when closed), its ends capped."""
    k = len(path)
    rings, u, t0 = [], None, None
    for i in range(k):
        if closed: t = unit(sub(path[(i + 1) % k], path[i - 1]))
        else: t = unit(sub(path[min(i + 1, k - 1)], path[max(i - 1, 0)]))
        if u is None: u, _ = frame(t)
        else:  # carried along the path by the turn from the last tangent to this one (no twist)
            a = cross(t0, t)
            s, c = math.sqrt(dot(a, a)), dot(t0, t)
            if s > 1e-12:
                a = mul(a, 1 / s)
                u = add(add(mul(u, c), mul(cross(a, u), s)), mul(a, dot(a, u) * (1 - c)))
        u = unit(sub(u, mul(t, dot(u, t))))
        t0 = t
        w = cross(t, u)
        rings.append([add(path[i], add(mul(u, r * math.cos(2 * math.pi * j / n)), mul(w, r * math.sin(2 * math.pi * j / n))))
                      for j in range(n)])
    V = [p for ring in rings for p in ring]
    F = []
    for i in range(k if closed else k - 1):
        a, b = i * n, ((i + 1) % k) * n
        for j in range(n):
            j1 = (j + 1) % n
            F += [(a + j, b + j1, b + j), (a + j, a + j1, b + j1)]
    if not closed:
        for end, ring in ((0, 0), (1, (k - 1) * n)):
            c = len(V)
            V.append(path[0] if end == 0 else path[-1])
            F += [(c, ring + (j + 1) % n, ring + j) if end == 0 else (c, ring + j, ring + (j + 1) % n) for j in range(n)]
    m.part(V, F)

def cylinder(m, p0, p1, r, n=24):
    sweep(m, [p0, p1], r, n)

def arc(c, r, a0, a1, e1, e2, k=16):
    return [add(c, add(mul(e1, r * math.cos(a0 + (a1 - a0) * i / k)), mul(e2, r * math.sin(a0 + (a1 - a0) * i / k))))
            for i in range(k + 1)]



def write_racks(out):
    """The five held-out racks: towel_rail, pegboard, j_hooks, shelf_hooks, mug_tree_six."""
    m = Mesh()  # a towel rail: a round bar 16 mm thick, 6 cm off the wall, 40 cm up
    box(m, (-0.35, 0.0, 0.0), (0.35, 0.02, 0.6))
    for x in (-0.25, 0.25): cylinder(m, (x, 0.0, 0.4), (x, -0.06, 0.4), 0.01)
    cylinder(m, (-0.3, -0.06, 0.4), (0.3, -0.06, 0.4), 0.008)
    m.write(out, "towel_rail")
    m = Mesh()  # a pegboard: 3 x 3 pegs 10 mm thick, 7 cm long, rising 10 degrees, 14 cm apart
    box(m, (-0.3, 0.0, 0.0), (0.3, 0.02, 0.6))
    rise = math.radians(10)
    for x in (-0.14, 0.0, 0.14):
        for z in (0.17, 0.31, 0.45):
            cylinder(m, (x, 0.005, z), (x, -0.07 * math.cos(rise), z + 0.07 * math.sin(rise)), 0.005)
    m.write(out, "pegboard")
    j_hooks(out, "j_hooks", 0.045, 15, 0.02, 0.008)  # 8 mm wire, 4.5 cm out rising 15 degrees, tips up 2 cm
    m = Mesh()  # three cup hooks of 6 mm wire under a shelf board: down 7 cm, out 4 cm, the tip turned up 2.5 cm
    box(m, (-0.3, -0.1, 0.4), (0.3, 0.1, 0.42))
    for x in (-0.2, 0.0, 0.2):
        sweep(m, [(x, 0.0, 0.405), (x, 0.0, 0.33), (x, -0.04, 0.33), (x, -0.04, 0.355)], 0.003, 12)
    m.write(out, "shelf_hooks")
    m = Mesh()  # a mug tree: six arms 8 cm long, 12 mm thick, rising 35 degrees at three heights
    cylinder(m, (0, 0, 0), (0, 0, 0.02), 0.11, 32)
    cylinder(m, (0, 0, 0.01), (0, 0, 0.42), 0.014)
    for k in range(6):
        yaw, z = k * math.pi / 3, (0.22, 0.29, 0.36)[k % 3]
        d = (math.cos(yaw) * math.cos(math.radians(35)), math.sin(yaw) * math.cos(math.radians(35)), math.sin(math.radians(35)))
        cylinder(m, add((0, 0, z), mul(d, 0.01)), add((0, 0, z), mul(d, 0.09)), 0.006, 16)
    m.write(out, "mug_tree_six")



def write_objects(out):
    """The held-out objects with loops: tall_mug, key_ring, pan, basket."""
    m = Mesh()  # a tall mug: 7 cm across, 11 cm tall, a D handle of 9 mm bar
    cylinder(m, (0, 0, 0), (0, 0, 0.11), 0.035, 32)
    sweep(m, [(0.03, 0, 0.09)] + arc((0.035, 0, 0.055), 0.032, math.pi / 2, -math.pi / 2, (1, 0, 0), (0, 0, 1), 12)[1:-1]
          + [(0.03, 0, 0.02)], 0.0045, 12)
    m.write(out, "tall_mug")
    m = Mesh()  # a key ring: 5 cm across, 7 mm wire
    sweep(m, arc((0, 0, 0), 0.022, 0, 2 * math.pi, (1, 0, 0), (0, 1, 0), 40)[:-1], 0.0035, 12, closed=True)
    m.write(out, "key_ring")
    m = Mesh()  # a pan: 20 cm across, 4 cm deep, a 16 cm handle with a 2 cm hole at its end
    cylinder(m, (0, 0, 0), (0, 0, 0.04), 0.1, 40)
    box(m, (0.095, -0.015, 0.025), (0.2, 0.015, 0.037))
    for lo, hi in (((0.2, -0.02, 0.025), (0.26, -0.01, 0.037)), ((0.2, 0.01, 0.025), (0.26, 0.02, 0.037)),
                   ((0.25, -0.02, 0.025), (0.26, 0.02, 0.037)), ((0.195, -0.02, 0.025), (0.21, 0.02, 0.037))):
        box(m, lo, hi)
    m.write(out, "pan")
    m = Mesh()  # a basket: 16 x 11 x 8 cm with an arched handle of 8 mm bar over its length
    box(m, (-0.08, -0.055, 0), (0.08, 0.055, 0.08))
    sweep(m, [(-0.07, 0, 0.075)] + arc((0, 0, 0.08), 0.07, math.pi, 0, (1, 0, 0), (0, 0, 1), 20)[1:-1] + [(0.07, 0, 0.075)],
          0.004, 12)
    m.write(out, "basket")


def j_hooks(out, name, reach, rise_deg, tip, wire):
    """Two J-hooks on a wall (y in [0, 0.02]), 24 cm apart, 40 cm up: an arm `reach` out rising
    `rise_deg`, its tip turned up by `tip`, bent from wire `wire` thick."""
    m = Mesh()
    box(m, (-0.3, 0.0, 0.0), (0.3, 0.02, 0.6))
    rise = math.radians(rise_deg)
    for x in (-0.12, 0.12):
        end = (x, -reach * math.cos(rise), 0.4 + reach * math.sin(rise))
        sweep(m, [(x, 0.005, 0.4), end, add(end, (0, -0.004, tip))], wire / 2, 12)
    m.write(out, name)


def summarize(path):
    """'outcome checked stayed best_stayed planning_ms bullet_best mujoco_best' of a CLI --json
    answer checked with --verify: --verify moves a checked candidate that fell behind the stable
    ones, so the planner's rank says which was best. stayed: in every engine --verify-engines
    asked; bullet_best / mujoco_best: the best kept by that engine alone (-1: not asked)."""
    try:
        d = json.load(open(path))
    except Exception:
        return "failed 0 0 0 0 -1 -1"
    c = sorted((x for x in d["candidates"] if x["stable"] and x["physics"]["checked"]),
               key=lambda x: x["physics"]["planner_rank"])
    def best_by(engine):
        if not c or not c[0]["physics"].get(engine, {}).get("checked", False):
            return -1
        return int(c[0]["physics"][engine]["stayed"])
    return "%s %d %d %d %.0f %d %d" % (d["outcome"], len(c), sum(x["physics"]["stayed"] for x in c),
                                       int(bool(c) and c[0]["physics"]["stayed"]), d["planning_ms"],
                                       best_by("bullet"), best_by("mujoco"))
