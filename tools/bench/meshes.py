"""The bench's meshes, from the repository and from the Debian packages they come from.

bunny and sh1 are shipped in data/meshes/. The motorbike (Debian's openfoam-examples) and
the interior map oa_thor (openarena-088-data, read by q3map.py) are converted on first use
into a cache (default build/meshes/), with a provenance file
beside it. A mesh that cannot be had raises Unavailable with one sentence saying why.
"""
import gzip
import os
import subprocess
import tempfile
import zipfile

from .. import ROOT
from . import q3map

SHIPPED = {"bunny", "sh1"}
MOTORBIKE_PACKAGE = "openfoam-examples"
MOTORBIKE_FILE = ("/usr/share/doc/openfoam-examples/examples/resources/geometry/"
                  "motorBike.obj.gz")
THOR_PACKAGE = "openarena-088-data"
THOR_FILE = "/usr/share/games/openarena/baseoa/pak6-patch088.pk3"
THOR_MEMBER = "maps/oa_thor.bsp"


class Unavailable(Exception):
    """The mesh cannot be had on this machine; str() says why and what installs it."""


def package_version(package):
    """The installed version of a Debian package, or None."""
    r = subprocess.run(["dpkg-query", "-W", "-f", "${Status}|${Version}", package],
                       capture_output=True, text=True)
    status, _, version = r.stdout.partition("|")
    return version if r.returncode == 0 and status == "install ok installed" else None


def convert_motorbike(lines):
    """(OBJ text, counts) from the lines of OpenFOAM's motorBike.obj: the vertex lines as
    they are (their text reads back to the same float32 values), then one 'f a b c' line per
    triangle in file order, leaving out a triangle whose three vertices (in any order) repeat
    an earlier triangle's: the file lists some surfaces in two groups, and a repeated
    triangle would make a hit's triangle index ambiguous."""
    vertices, faces, seen, dropped = [], [], set(), 0
    for line in lines:
        fields = line.split()
        if not fields:
            continue
        if fields[0] == "v":
            vertices.append("v %s %s %s\n" % tuple(fields[1:4]))
        elif fields[0] == "f":
            idx = [int(f.split("/")[0]) for f in fields[1:]]
            idx = [i if i > 0 else len(vertices) + 1 + i for i in idx]
            for k in range(1, len(idx) - 1):  # polygons as fans, as the core's reader does
                tri = (idx[0], idx[k], idx[k + 1])
                key = tuple(sorted(tri))
                if key in seen:
                    dropped += 1
                    continue
                seen.add(key)
                faces.append("f %d %d %d\n" % tri)
    return "".join(vertices) + "".join(faces), {
        "vertices": len(vertices), "triangles": len(faces), "dropped": dropped}


def motorbike(cache):
    version = package_version(MOTORBIKE_PACKAGE)
    if version is None or not os.path.exists(MOTORBIKE_FILE):
        raise Unavailable("motorbike: Debian's %s is not installed (tools/deps.sh bench "
                          "installs it)" % MOTORBIKE_PACKAGE)
    stamp = "Package `%s` %s" % (MOTORBIKE_PACKAGE, version)
    return cached(cache, "motorbike", stamp, lambda: make_motorbike(stamp))


def make_motorbike(stamp):
    with gzip.open(MOTORBIKE_FILE, "rt", encoding="latin-1") as f:
        text, counts = convert_motorbike(f)
    return text, (
        "# motorbike.obj\n\n"
        "Made by tools/bench/meshes.py on first use; delete this folder to make it again.\n\n"
        "%s, file `%s` (OpenFOAM's motorbike-with-rider geometry). Licence as stated by the "
        "package's copyright file, `Files: *`: GPL-3+, (c) OpenFOAM Foundation, OpenCFD Ltd.\n\n"
        "The vertex lines are the original's (%d vertices); the faces are its triangles in "
        "file order, %d of them, after leaving out %d that repeat an earlier triangle's three "
        "vertices (the same surface listed in two groups), so that a hit's triangle index is "
        "never ambiguous. Z is up; the bike runs along x.\n"
        % (stamp, MOTORBIKE_FILE, counts["vertices"], counts["triangles"], counts["dropped"]))


def oa_thor(cache):
    """The OpenArena map "Thor's Valhalla" from Debian's openarena-088-data, by q3map.py."""
    version = package_version(THOR_PACKAGE)
    if version is None or not os.path.exists(THOR_FILE):
        raise Unavailable("oa_thor: Debian's %s is not installed (tools/deps.sh bench "
                          "installs it)" % THOR_PACKAGE)
    stamp = "Package `%s` %s" % (THOR_PACKAGE, version)
    return cached(cache, "oa_thor", stamp, lambda: make_oa_thor(stamp))


def make_oa_thor(stamp):
    with zipfile.ZipFile(THOR_FILE) as z:
        positions, tris, counts = q3map.triangles(z.read(THOR_MEMBER))
    # %.9g: nine digits read back to the same float32
    text = "".join("v %.9g %.9g %.9g\n" % p for p in positions) + "".join(
        "f %d %d %d\n" % (a + 1, b + 1, c + 1) for a, b, c in tris)
    return text, (
        "# oa_thor.obj\n\n"
        "Made by tools/bench/meshes.py (with q3map.py) on first use; delete this folder to make "
        "it again.\n\n"
        "%s, file `%s`, member `%s` (the OpenArena map \"Thor's Valhalla\": halls, columns, "
        "arches, long corridors). Licence as stated by the package's copyright file, entry for "
        "`oa_thor.*`: (c) \"Thor\", GPL-2 (version 2 only).\n\n"
        "The static world (model 0): %d triangles, %d vertices (welded where bit-identical); "
        "Bezier patches tessellated with %d segments per 3x3 control block; %d sky faces, %d "
        "zero-area triangles and %d repeats left out. Z is up, units are Quake units. The "
        "bench's inside camera: eye (960, -384, 2), looking at (960, 600, 2), up z, fov 90.\n"
        % (stamp, THOR_FILE, THOR_MEMBER, len(tris), len(positions), q3map.SEGMENTS,
           counts["sky"], counts["zero_area"], counts["repeats"]))


def cached(cache, name, stamp, make):
    """cache/NAME.obj, made by make() -> (obj text, provenance text) unless the provenance
    beside it already names this package version (stamp)."""
    obj = os.path.join(cache, name + ".obj")
    about = os.path.join(cache, name + ".md")
    if os.path.exists(obj) and os.path.exists(about):
        with open(about, encoding="utf-8") as f:
            if stamp in f.read():
                return obj
    text, provenance = make()
    os.makedirs(cache, exist_ok=True)
    write_atomically(obj, text)
    write_atomically(about, provenance)
    return obj


def write_atomically(path, text):
    fd, tmp = tempfile.mkstemp(dir=os.path.dirname(path), prefix=".part-")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


def mesh_path(name, cache, data=None):
    """The OBJ file of mesh `name`: MESH.obj in `data` when a folder is given (an override),
    else the shipped file or the converted cache. Raises Unavailable."""
    if data:
        path = os.path.join(data, name + ".obj")
        if not os.path.exists(path):
            raise Unavailable("%s: no %s" % (name, path))
        return path
    if name in SHIPPED:
        return os.path.join(ROOT, "data", "meshes", name + ".obj")
    if name == "motorbike":
        return motorbike(cache)
    if name == "oa_thor":
        return oa_thor(cache)
    raise Unavailable("%s: no such mesh (bunny, sh1, motorbike, oa_thor)" % name)


def main(argv=None):
    """python3 -m tools.bench.meshes MESH [--cache DIR]: prints the OBJ's path, converting it
    into the cache first when needed; exit code 3 (and why on stderr) when it cannot be had."""
    import argparse
    import sys
    ap = argparse.ArgumentParser(description="the path of a bench mesh, made on first use")
    ap.add_argument("mesh", help="bunny, sh1, motorbike or oa_thor")
    ap.add_argument("--cache", default=os.path.join(ROOT, "build", "meshes"))
    a = ap.parse_args(argv)
    try:
        print(mesh_path(a.mesh, a.cache))
    except Unavailable as e:
        print("meshes.py: %s" % e, file=sys.stderr)
        return 3
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
