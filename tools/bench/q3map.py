"""A Quake III map (IBSP version 46) as triangles: the static world for the bench.

Reads model 0 (the world, not doors or platforms): polygon and mesh faces as stored,
Bezier patches tessellated into quads of a 3x3 control block (biquadratic, SEGMENTS a side),
sky faces left out (they box the whole level in). Positions are welded where their float32
values are identical; zero-area triangles and triangles repeating an earlier one's three
vertices are dropped, so a hit's triangle index is never ambiguous.
"""
import struct

SEGMENTS = 4
SURF_SKY = 0x4
LUMP_TEXTURES, LUMP_MODELS, LUMP_VERTICES, LUMP_MESHVERTS, LUMP_FACES = 1, 7, 10, 11, 13
POLYGON, PATCH, MESH = 1, 2, 3


def lumps(data):
    if data[:4] != b"IBSP" or struct.unpack_from("<i", data, 4)[0] != 46:
        raise ValueError("not a Quake III map (IBSP version 46)")
    return [struct.unpack_from("<ii", data, 8 + 8 * i) for i in range(17)]


def records(data, lump, size):
    offset, length = lump
    return [data[offset + i * size:offset + (i + 1) * size] for i in range(length // size)]


def bezier(c, u, v):
    """A point of the biquadratic patch with the 3x3 control points c (rows of 3)."""
    def basis(t):
        return ((1 - t) ** 2, 2 * t * (1 - t), t * t)
    bu, bv = basis(u), basis(v)
    return tuple(sum(bv[j] * bu[i] * c[j][i][k] for j in range(3) for i in range(3))
                 for k in range(3))


def f32(p):
    return struct.unpack("<3f", struct.pack("<3f", *p))


def triangles(data):
    """(positions, triangles) of the map's world: positions as float32 triples, triangles as
    index triples, with the counts of what was left out."""
    L = lumps(data)
    textures = [struct.unpack_from("<i", r, 64)[0] for r in records(data, L[LUMP_TEXTURES], 72)]
    # model 0: mins, maxs (6 floats), then its first face and face count
    first, count = struct.unpack_from("<2i", data, L[LUMP_MODELS][0] + 24)
    verts = [struct.unpack_from("<3f", r) for r in records(data, L[LUMP_VERTICES], 44)]
    meshverts = [struct.unpack_from("<i", r)[0] for r in records(data, L[LUMP_MESHVERTS], 4)]
    faces = records(data, L[LUMP_FACES], 104)
    index, positions, tris = {}, [], []
    seen = set()
    counts = {"sky": 0, "zero_area": 0, "repeats": 0}

    def weld(p):
        p = f32(p)
        if p not in index:
            index[p] = len(positions)
            positions.append(p)
        return index[p]

    def add(a, b, c):
        ia, ib, ic = weld(a), weld(b), weld(c)
        pa, pb, pc = positions[ia], positions[ib], positions[ic]
        e1 = [pb[k] - pa[k] for k in range(3)]
        e2 = [pc[k] - pa[k] for k in range(3)]
        n = (e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
             e1[0] * e2[1] - e1[1] * e2[0])
        if n == (0.0, 0.0, 0.0):
            counts["zero_area"] += 1
            return
        key = tuple(sorted((ia, ib, ic)))
        if key in seen:
            counts["repeats"] += 1
            return
        seen.add(key)
        tris.append((ia, ib, ic))

    for f in faces[first:first + count]:
        texture, _, kind, vertex, nverts, meshvert, nmeshverts = struct.unpack_from("<7i", f)
        if 0 <= texture < len(textures) and textures[texture] & SURF_SKY:
            counts["sky"] += 1
            continue
        if kind in (POLYGON, MESH):
            for k in range(0, nmeshverts - 2, 3):
                a, b, c = (verts[vertex + meshverts[meshvert + k + j]] for j in range(3))
                add(a, b, c)
        elif kind == PATCH:
            w, h = struct.unpack_from("<2i", f, 96)
            grid = verts[vertex:vertex + nverts]
            for by in range(0, h - 1, 2):
                for bx in range(0, w - 1, 2):
                    c = [[grid[(by + j) * w + bx + i] for i in range(3)] for j in range(3)]
                    s = SEGMENTS
                    pts = [[bezier(c, i / s, j / s) for i in range(s + 1)] for j in range(s + 1)]
                    for j in range(s):
                        for i in range(s):
                            add(pts[j][i], pts[j + 1][i], pts[j][i + 1])
                            add(pts[j][i + 1], pts[j + 1][i], pts[j + 1][i + 1])
    return positions, tris, counts
