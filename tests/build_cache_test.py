"""The compiler cache shares objects between clones without sharing their paths.

    python3 -m tests.build_cache_test COMPILER LAUNCHER...

LAUNCHER is the build's CMAKE_CXX_COMPILER_LAUNCHER (env CCACHE_BASEDIR=<the source> ...
ccache). Two trees, A and B, hold the same source; each is compiled from its own build folder
with the launcher, its base folder set to that tree as CMakeLists.txt sets it, and a cache of
the test's own. B's compile must be a hit on A's entry (a second clone, a kit or a lab user
reuses the first one's objects), and B's object and warnings must not name A's folder: a
failing check shows the test's __FILE__ as its file:line, and a student must see their own
file there, not another clone's (ccache's depend mode, for one, breaks this: it compiles with
absolute paths and serves them to every later tree).
"""

import os
import subprocess
import sys
import tempfile

SOURCE = """#include "where.hpp"
const char* where() { return __FILE__; }
int unused() { int never_used; return 0; }  // a warning, cached with the object
"""


def compile_in(tree, cache, compiler, launcher):
    """Compiles TREE/src/a.cpp in TREE/build as ninja would: (the object's bytes, stderr)."""
    argv = [f"CCACHE_BASEDIR={tree}" if a.startswith("CCACHE_BASEDIR=") else a for a in launcher]
    argv += [compiler, "-Wall", "-I", os.path.join(tree, "src"), "-MD", "-MT", "a.o", "-MF",
             "a.o.d", "-o", "a.o", "-c", os.path.join(tree, "src", "a.cpp")]
    env = dict(os.environ, CCACHE_DIR=cache, CCACHE_CONFIGPATH=os.path.join(cache, "none.conf"))
    build = os.path.join(tree, "build")
    r = subprocess.run(argv, cwd=build, env=env, capture_output=True, text=True, timeout=120)
    if r.returncode != 0:
        sys.exit(f"FAIL  the compile in {tree} failed:\n{r.stderr}")
    with open(os.path.join(build, "a.o"), "rb") as f:
        return f.read(), r.stderr


def hits(cache):
    """Cache hits so far (direct and preprocessed)."""
    out = subprocess.run(["ccache", "--print-stats"], env=dict(os.environ, CCACHE_DIR=cache),
                         capture_output=True, text=True, check=True).stdout
    stats = dict(line.split("\t", 1) for line in out.splitlines() if "\t" in line)
    return sum(int(stats.get(k, 0)) for k in ("direct_cache_hit", "preprocessed_cache_hit"))


def main():
    compiler, launcher = sys.argv[1], sys.argv[2:]
    if not any(os.path.basename(a) == "ccache" for a in launcher):
        print("this build compiles without ccache: nothing to test")
        return 77
    failures = []
    with tempfile.TemporaryDirectory(prefix="boxes-cache-") as tmp:
        cache = os.path.join(tmp, "cache")
        os.makedirs(cache)
        open(os.path.join(cache, "none.conf"), "w").close()
        trees = [os.path.join(tmp, name) for name in ("first-clone", "second-clone")]
        for tree in trees:
            os.makedirs(os.path.join(tree, "build"))
            os.makedirs(os.path.join(tree, "src"))
            with open(os.path.join(tree, "src", "a.cpp"), "w") as f:
                f.write(SOURCE)
            with open(os.path.join(tree, "src", "where.hpp"), "w") as f:
                f.write("const char* where();\n")
        compile_in(trees[0], cache, compiler, launcher)
        before = hits(cache)
        obj, warnings = compile_in(trees[1], cache, compiler, launcher)
        checks = [
            (hits(cache) == before + 1, "the second clone's compile is a hit on the first's entry"),
            (trees[0].encode() not in obj, "the second clone's object names no path of the first"),
            (trees[0] not in warnings, "the second clone's warnings name no path of the first"),
            (b"src/a.cpp" in obj, "the object holds the source's own path (__FILE__)"),
        ]
        for ok, what in checks:
            print(("ok    " if ok else "FAIL  ") + what)
            if not ok:
                failures.append(what)
        if failures:
            print(f"the second clone's warnings:\n{warnings}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
