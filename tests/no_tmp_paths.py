#!/usr/bin/python3
"""No fixed path under /tmp in the tools and scripts (ctest label "lab").

usage: tests/no_tmp_paths.py [ROOT]

A fixed name in the shared /tmp belongs to whichever user made it first: a second user's
command then fails on it (tools/deps.sh's old logs did). Logs, scratch and caches go into the
clone (build/) or a private folder from mktemp or tempfile, removed when the command ends.
Everything but tests/ and the documentation is checked: /tmp/NAME, and mktemp or mkdtemp
given /tmp itself (the user's TMPDIR is theirs to choose). And every tools test that makes
temporary folders imports tests/tools/scratch.py, which removes them when it ends.
"""
import os
import re
import subprocess
import sys

PATTERNS = [
    (re.compile(r"/tmp/[\w$.{-]"), "a fixed path under /tmp"),
    (re.compile(r"mktemp(\s+-\w+)*\s+[\"']?/tmp"), "mktemp in /tmp itself (mktemp -t uses TMPDIR)"),
    (re.compile(r"dir\s*=\s*[\"']/tmp[\"']"), "a temporary folder in /tmp itself (tempfile uses TMPDIR)"),
]
SKIP = re.compile(r"^(tests/|docs/|build/|out/)|\.md$|(^|/)node_modules/|package-lock\.json$")


def files(root):
    try:
        out = subprocess.run(["git", "-C", root, "ls-files", "-z"], check=True, capture_output=True,
                             text=True).stdout
        listed = [f for f in out.split("\0") if f]
    except (OSError, subprocess.CalledProcessError):
        listed = []
    if not listed:  # outside git (a copied tree)
        for base, dirs, names in os.walk(root):
            dirs[:] = [d for d in dirs if d not in (".git", "build", "out", "node_modules")]
            listed += [os.path.relpath(os.path.join(base, n), root) for n in names]
    return [f for f in listed if not SKIP.search(f)]


def unscratched(root):
    """The tools tests that use tempfile without tests/tools/scratch.py."""
    folder = os.path.join(root, "tests", "tools")
    found = []
    for name in sorted(os.listdir(folder)) if os.path.isdir(folder) else []:
        if name.startswith("test_") and name.endswith(".py"):
            with open(os.path.join(folder, name), encoding="utf-8") as f:
                text = f.read()
            if "tempfile" in text and "from tests.tools import scratch" not in text:
                found.append(f"tests/tools/{name}: temporary folders without tests.tools.scratch (left in /tmp)")
    return found


def main(argv):
    root = os.path.abspath(argv[0] if argv else os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    found, checked = [], 0
    for rel in files(root):
        try:
            with open(os.path.join(root, rel), encoding="utf-8") as f:
                text = f.read()
        except (UnicodeDecodeError, OSError):
            continue  # binary (meshes, images)
        checked += 1
        for number, line in enumerate(text.splitlines(), 1):
            for pattern, what in PATTERNS:
                if pattern.search(line):
                    found.append(f"{rel}:{number}: {what}: {line.strip()[:120]}")
    found += unscratched(root)
    for f in found:
        print("FAIL  " + f)
    print(f"{checked} files checked, {len(found)} found (fixed /tmp paths, unscratched tools tests)")
    return 1 if found or checked == 0 else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
