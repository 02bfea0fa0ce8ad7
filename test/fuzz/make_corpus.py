"""Writes the seed corpus test/fuzz/corpus/<target>/ (tiny valid and nearly valid inputs).

Committed; run again only to change the seeds: /usr/bin/python3 test/fuzz/make_corpus.py
"""
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))

TETRA_V = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
TETRA_F = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]


def write(target, name, data):
    d = os.path.join(HERE, "corpus", target)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


def ply_ascii(extra_prop=False, crlf=False, quad=False):
    nl = "\r\n" if crlf else "\n"
    v = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)] if quad else TETRA_V
    f = [(0, 1, 2, 3)] if quad else TETRA_F
    h = ["ply", "format ascii 1.0", "comment seed", "element vertex %d" % len(v),
         "property float x", "property float y", "property float z"]
    if extra_prop:
        h.append("property uchar red")
    h += ["element face %d" % len(f), "property list uchar int vertex_indices", "end_header"]
    body = [" ".join(str(c) for c in p) + (" 7" if extra_prop else "") for p in v]
    body += ["%d %s" % (len(t), " ".join(str(i) for i in t)) for t in f]
    return nl.join(h + body) + nl


def ply_binary(big=False, double=False):
    e = ">" if big else "<"
    fmt = "binary_big_endian" if big else "binary_little_endian"
    t = "double" if double else "float"
    h = ("ply\nformat %s 1.0\nelement vertex 4\nproperty %s x\nproperty %s y\nproperty %s z\n"
         "element face 4\nproperty list uchar int vertex_indices\nend_header\n" % (fmt, t, t, t))
    body = b"".join(struct.pack(e + ("3d" if double else "3f"), *p) for p in TETRA_V)
    body += b"".join(struct.pack(e + "B3i", 3, *f) for f in TETRA_F)
    return h.encode() + body


# The ply_binary target's own format (fuzz_targets.cpp plyBinary): shape byte, types byte,
# vertex count (u16 LE), face count (u16 LE), then the data after end_header.
def ply_binary_structured(big, coord_type, count_type, index_type, with_conf=False):
    types = ["char", "uchar", "short", "ushort", "int", "uint", "float", "double"]
    fmt = {"char": "b", "uchar": "B", "short": "h", "ushort": "H", "int": "i", "uint": "I",
           "float": "f", "double": "d"}
    shape = (1 if big else 0) | (2 if with_conf else 0) | types.index(count_type) << 2 | types.index(index_type) << 5
    tbyte = types.index(coord_type) | (types.index("float") << 3)
    e = ">" if big else "<"
    head = bytes([shape, tbyte]) + struct.pack("<HH", len(TETRA_V), len(TETRA_F))
    body = b""
    for p in TETRA_V:
        body += struct.pack(e + fmt[coord_type] * 3, *p)
        if with_conf:
            body += struct.pack(e + "f", 0.5)
    for f in TETRA_F:
        body += struct.pack(e + fmt[count_type], 3) + struct.pack(e + fmt[index_type] * 3, *f)
    return head + body


def obj(quads=False, negative=False, slashes=False):
    verts = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)] if quads else TETRA_V
    lines = ["# seed"] + ["v %g %g %g" % p for p in verts]
    if slashes:
        lines += ["vt 0 0", "vn 0 0 1"]
    for f in ([(0, 1, 2, 3)] if quads else TETRA_F):
        if negative:
            idx = [str(i - len(verts)) for i in f]
        else:
            idx = [str(i + 1) for i in f]
        if slashes:
            idx = [i + "/1/1" for i in idx]
        lines.append("f " + " ".join(idx))
    return "\n".join(lines) + "\n"


def stl_ascii():
    s = "solid seed\n"
    for f in TETRA_F:
        s += " facet normal 0 0 0\n  outer loop\n"
        for i in f:
            s += "   vertex %g %g %g\n" % TETRA_V[i]
        s += "  endloop\n endfacet\n"
    return s + "endsolid seed\n"


def stl_binary(header=b"binary seed"):
    data = header.ljust(80, b" ") + struct.pack("<I", len(TETRA_F))
    for f in TETRA_F:
        data += struct.pack("<3f", 0, 0, 0)
        for i in f:
            data += struct.pack("<3f", *TETRA_V[i])
        data += b"\0\0"
    return data


def planner_seeds():
    # fuzz_targets.cpp planner() reads: object kind and sizes, area kind and sizes, then one
    # selector byte per config field (even: the default). All zero: a 1 cm cube on a 5 cm plane
    # with the defaults; the others were drawn at random and kept when they plan something.
    import random
    rng = random.Random(7)
    seeds = {"defaults": bytes(64)}
    for i in range(40):
        seeds["random_%02d" % i] = bytes(rng.randrange(256) for _ in range(rng.randrange(16, 120)))
    return seeds


def shape_mesh(raw=False, bad_index=False):
    """fuzz_conversions.cpp shapeMesh: vertex count, per coordinate a flag byte then a range()
    byte (flag 0) or 8 raw float64 bytes (flag 1); triangle count, per index a flag byte then a
    byte index (flag 1) or 4 bytes (flag 0)."""
    verts = [(0.0, 0.0, 0.0), (0.5, 0.0, 0.0), (0.0, 0.5, 0.0), (0.0, 0.0, 0.5)]
    out = bytearray([len(verts)])
    for p in verts:
        for c in p:
            if raw:
                out += bytes([1]) + struct.pack("<d", c)
            else:
                out += bytes([0, max(0, min(255, round((c + 1) * 255 / 2)))])
    tris = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3 if not bad_index else 9)]
    out.append(len(tris))
    for t in tris:
        for i in t:
            out += bytes([1, i])
    return bytes(out)


def polygon_mesh(point_step=12, double=False, extra_field=False):
    # As fuzz_conversions.cpp reads it: height, width (u16), point_step, row-step choice, big
    # endian choice, fields (name, offset choice, offset, datatype), polygons, data length, data.
    size = 8 if double else 4
    datatype = 8 if double else 7  # PointField FLOAT64 / FLOAT32
    out = bytes([1]) + struct.pack("<H", len(TETRA_V)) + bytes([point_step, 1, 0, 1])
    fields = [(0, 0), (1, size), (2, 2 * size)] + ([(3, 3 * size)] if extra_field else [])
    out += bytes([len(fields)])
    for name, offset in fields:
        out += bytes([name, 1, offset, datatype])
    out += bytes([len(TETRA_F)])
    for f in TETRA_F:
        out += bytes([3]) + b"".join(bytes([1, i]) for i in f)
    data = b""
    for p in TETRA_V:
        point = struct.pack("<3d" if double else "<3f", *p)
        data += point.ljust(point_step, b"\0")
    return out + struct.pack("<H", len(data)) + data


def main():
    write("ply_text", "tetra_ascii.ply", ply_ascii())
    write("ply_text", "quad_extra_prop_crlf.ply", ply_ascii(extra_prop=True, crlf=True, quad=True))
    write("ply_text", "tetra_binary_le.ply", ply_binary())
    write("ply_text", "tetra_binary_be_double.ply", ply_binary(big=True, double=True))
    write("ply_binary", "le_float_uchar_int", ply_binary_structured(False, "float", "uchar", "int"))
    write("ply_binary", "be_double_ushort_uint_conf", ply_binary_structured(True, "double", "ushort", "uint", True))
    write("ply_binary", "le_short_uchar_ushort", ply_binary_structured(False, "short", "uchar", "ushort"))
    write("obj", "tetra.obj", obj())
    write("obj", "quad_negative.obj", obj(quads=True, negative=True))
    write("obj", "tetra_slashes.obj", obj(slashes=True))
    write("stl", "tetra_ascii.stl", stl_ascii())
    write("stl", "tetra_binary.stl", stl_binary())
    write("stl", "tetra_binary_solid_header.stl", stl_binary(b"solid but binary"))
    write("polygon_mesh", "tetra_float32", polygon_mesh())
    write("polygon_mesh", "tetra_float64_padded", polygon_mesh(point_step=32, double=True, extra_field=True))
    write("polygon_mesh", "tetra_float32_rgb", polygon_mesh(point_step=16, extra_field=True))
    for name, data in planner_seeds().items():
        write("planner", name, data)
    write("shape_mesh", "tetra", shape_mesh())
    write("shape_mesh", "tetra_raw_float64", shape_mesh(raw=True))
    write("shape_mesh", "tetra_bad_index", shape_mesh(bad_index=True))


if __name__ == "__main__":
    main()
