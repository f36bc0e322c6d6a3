#!/usr/bin/python3
"""Hostile submissions against the grader's box (ctest label "grading"): what grading reads of
a student's tree, what a student's test sees and fills, what one bad submission costs.

usage: python3 -m tests.box_test SCENARIO WORK_DIR
  links       grade TREE on trees with links in steps/: the reference's solutions through
              /proc/self/cwd, /etc/shadow, a root-only file, /dev/zero, a FIFO, a linked
              folder. The grader reads none of them (each is named with its reason), never
              hangs, and the tree scores what its regular files earn; with bubblewrap and
              without it (--no-isolation)
  archives    grade-class on a class with bad submissions (a zip holding triangle.cpp both
              as a file and a folder, a member name of 300 characters, a tar bomb) and
              hostile names (escape sequences, a newline, a spreadsheet formula): each bad
              one is its own "not graded" row, the others are graded, the progress lines
              and class.csv carry the names escaped
  neighbours  grade-class --jobs 2 with the submissions and --out outside the repository:
              one student's test tries to read another student's sources, the class list,
              cache.json, class.csv, the workers' grading trees and reports, /etc/shadow,
              the solutions and home, and sees none of them; another fills every place it
              can write; the honest students beside them get exactly their points
              (skipped, 77, where bubblewrap cannot run: without it the class grader runs
              only trusted code)
  disk-full   grade-class on a grading disk too full to grade (BOXES_GRADE_MIN_FREE_MB
              above what is free): every row says "not graded: ..., retry", none is kept,
              and the next run grades them all

WORK_DIR is the class grading's (tests/class_grading_test.py): its primed grading folders
WORK_DIR/workers are reused, so these scenarios rebuild only the sources they change.
"""
import csv
import json
import os
import shutil
import subprocess
import sys
import tarfile
import tempfile
import time
import zipfile

from tests.class_grading_test import (HOSTILE_HEADERS, ROOT, SKIPPED, TIMEOUT, check, exercises, failures,
                                      first_step, isolation_works, no_isolation, step_ids, table, tool)
from tools.grading.class_bench import student_sources
from tools.grading.submissions import MAX_MEMBERS, write_files


def step_files(solved):
    """The first step's sources (and the others' stubs) with the exercises `solved` kept."""
    return {rel: text for rel, text in student_sources(solved).items()}


def outside():
    """A folder outside the repository, home and /tmp (the layout that showed the hole: a
    shared folder elsewhere)."""
    base = "/var/tmp" if os.access("/var/tmp", os.W_OK) else None
    return tempfile.mkdtemp(prefix="boxes-box-", dir=base)


def hostile(body):
    """The reference's sources with the last exercise of the first step's solution replaced
    by `body` (it runs in that exercise's test cases); returns (files, exercise id)."""
    files = step_files(step_ids())
    target = [e for e in exercises(ROOT) if e.id == step_ids()[-1]][0]
    lines = files[target.path].split("\n")
    lines[target.begin + 1:target.end] = ["    " + line for line in body]
    files[target.path] = HOSTILE_HEADERS + "\n".join(lines)
    return files, target.id


def grade_json(tree, work, extra):
    js = os.path.join(work, "box.json")
    if os.path.exists(js):
        os.remove(js)
    r = subprocess.run(tool("grade") + [tree, "--work", work, "--steps", first_step(), "--timeout", TIMEOUT,
                                        "--json", js, "--junit", os.path.join(work, "box.xml")] + extra,
                       capture_output=True, text=True, cwd=ROOT, timeout=900)
    print(r.stdout[-2000:], r.stderr[-2000:])
    doc = json.load(open(js)) if os.path.exists(js) else {}
    return r, doc


# Links in a tree -----------------------------------------------------------------------------


def scenario_links(work):
    w0 = os.path.join(work, "workers", "w0")
    base = outside()
    try:
        secret = os.path.join(base, "root-only.txt")
        with open(secret, "w") as f:
            f.write("ROOT-ONLY-SECRET\n")
        os.chmod(secret, 0o600)
        secrets = ["ROOT-ONLY-SECRET"]
        try:
            with open("/etc/shadow") as f:
                secrets += [line.strip() for line in f if len(line.strip()) > 8][:1]
        except OSError:
            pass
        target = [e for e in exercises(ROOT) if f"{e.step:02d}" == first_step()][0]
        folder = os.path.dirname(target.path)
        ids = step_ids()
        points = {e.id: e.points for e in exercises(ROOT)}
        for extra, how in (([], "bubblewrap"), (["--no-isolation"], "no isolation")):
            if not extra and not isolation_works():
                print("note: bubblewrap cannot run here: the links are graded without it only")
                continue
            # A tree whose exercise file links to the reference's solution: it is not read, so
            # the exercises are the kit's stubs (before: full points).
            shutil.rmtree(os.path.join(base, "solutions"), ignore_errors=True)
            tree = write_files(os.path.join(base, "solutions"), step_files([]))
            os.remove(os.path.join(tree, target.path))
            os.symlink(f"/proc/self/cwd/{target.path}", os.path.join(tree, target.path))
            r, doc = grade_json(tree, w0, extra)
            got = {x["exercise"]: x["points"] for x in doc.get("exercises", [])}
            check(r.returncode == 0 and got and all(got[i] == 0 for i in ids),
                  f"links, {how}: a link to the solutions scores nothing: {got}")
            check(any(target.path in n and "symbolic link" in n for n in doc.get("notes", [])),
                  f"links, {how}: a note names the link and why it was not read: {doc.get('notes')}")
            # A solved tree with hostile links and special files beside its regular sources:
            # the regular ones earn their points, the grader neither reads nor hangs on the rest.
            shutil.rmtree(os.path.join(base, "mixed"), ignore_errors=True)
            tree = write_files(os.path.join(base, "mixed"), step_files(ids))
            specials = {"shadow.hpp": "/etc/shadow", "secret.hpp": secret, "zero.hpp": "/dev/zero",
                        "up": "/"}
            for name, to in specials.items():
                os.symlink(to, os.path.join(tree, folder, name))
            os.mkfifo(os.path.join(tree, folder, "fifo.hpp"))
            if os.geteuid() == 0:
                os.mknod(os.path.join(tree, folder, "zero-device.hpp"), 0o600 | 0o020000, os.makedev(1, 5))
            started = time.monotonic()
            r, doc = grade_json(tree, w0, extra)
            got = {x["exercise"]: x["points"] for x in doc.get("exercises", [])}
            check(r.returncode == 0 and got == {i: points[i] for i in ids},
                  f"links, {how}: the regular sources earn their points ({time.monotonic() - started:.0f} s): {got}")
            notes = "\n".join(doc.get("notes", []))
            for name in list(specials) + ["fifo.hpp"] + (["zero-device.hpp"] if os.geteuid() == 0 else []):
                check(f"{folder}/{name}: " in notes and "not read" in notes,
                      f"links, {how}: {name} is refused with a reason")
            everything = r.stdout + r.stderr + json.dumps(doc) + open(os.path.join(w0, "box.xml")).read()
            check(not any(s in everything for s in secrets), f"links, {how}: no linked file's content in the report")
    finally:
        shutil.rmtree(base, ignore_errors=True)


# Bad archives and names in a class -------------------------------------------------------------


def zip_tree(path, files, extra=()):
    with zipfile.ZipFile(path, "w") as z:
        for rel, text in files.items():
            z.writestr("tree/" + rel, text)
        for name, text in extra:
            z.writestr(name, text)


def tar_bomb(path, files):
    """A small gzip'd tar: the step sources, then more empty members than MAX_MEMBERS."""
    with tarfile.open(path, "w:gz") as t:
        for rel, text in files.items():
            data = text.encode()
            info = tarfile.TarInfo("tree/" + rel)
            info.size = len(data)
            t.addfile(info, __import__("io").BytesIO(data))
        info = tarfile.TarInfo()
        for i in range(MAX_MEMBERS + 1):
            info.name = f"tree/junk/{i:07d}"
            t.addfile(info)


def class_run(subs, out, work, env=None, extra=()):
    cmd = tool("grade_class") + [subs, "--out", out, "--work", work, "--jobs", "2", "--steps", first_step(),
                                 "--timeout", TIMEOUT] + list(extra) + (["--no-sandbox"] if no_isolation() else [])
    r = subprocess.run(cmd, capture_output=True, cwd=ROOT, env=env, timeout=1800)
    err = r.stderr.decode(errors="replace")
    print(err[-3000:])
    return r, err


def scenario_archives(work):
    base = outside()
    try:
        subs, out = os.path.join(base, "submissions"), os.path.join(base, "out")
        os.makedirs(subs)
        ids = step_ids()
        points = {e.id: e.points for e in exercises(ROOT)}
        kit, solved = step_files([]), step_files(ids)
        target = [e for e in exercises(ROOT) if e.id == ids[0]][0].path
        zip_tree(os.path.join(subs, "a-file-and-folder.zip"), kit, [(f"tree/{target}/x.cpp", "int x;")])
        zip_tree(os.path.join(subs, "b-long-name.zip"), kit,
                 [(f"tree/{os.path.dirname(target)}/{'n' * 300}.cpp", "int n;")])
        tar_bomb(os.path.join(subs, "c-bomb.tar.gz"), kit)
        escapes = "d-\x1b]0;owned\x07\x1b[2J\x1b[31mred"
        write_files(os.path.join(subs, escapes), solved)
        write_files(os.path.join(subs, "e-new\nline"), kit)
        write_files(os.path.join(subs, "=HYPERLINK(\"x\")"), solved)
        write_files(os.path.join(subs, "f-reference"), solved)
        started = time.monotonic()
        r, err = class_run(subs, out, os.path.join(work, "workers"))
        check(r.returncode == 0, f"archives: the class run finishes ({time.monotonic() - started:.0f} s)")
        raw = r.stderr.decode("utf-8", errors="surrogateescape")
        check("\x1b" not in raw and "\x07" not in raw, "archives: no escape sequence reaches the terminal raw")
        check("\\x1b]0;owned\\x07\\x1b[2J" in err and "e-new\\nline" in err,
              "archives: the progress lines show the names escaped")
        with open(os.path.join(out, "class.csv"), newline="") as f:
            text = f.read()
        check(not any(c in text for c in "\x1b\x07\x00") and "e-new\nline" not in text,
              "archives: class.csv holds no control character")
        rows = {row[0]: row for row in csv.reader(text.splitlines())}
        build = {name: row[-2] for name, row in rows.items()}
        for name, why in (("a-file-and-folder", "both a file and a folder"), ("b-long-name", "longer than 255"),
                          ("c-bomb", f"more than {MAX_MEMBERS} files")):
            check(build.get(name, "").startswith("not graded") and why in build.get(name, ""),
                  f"archives: {name} is its own not-graded row: {build.get(name)!r}")
        full = str(sum(points[i] for i in ids))
        total = {name: row[len(ids) + 1] for name, row in rows.items()}
        check(total.get("f-reference") == full and total.get("e-new\\nline") == "0" and
              total.get(escapes.replace("\x1b", "\\x1b").replace("\x07", "\\x07")) == full,
              f"archives: the others are graded: {total}")
        check(total.get("'=HYPERLINK(\"x\")") == full, "archives: a name that is a formula is quoted text")
        page = open(os.path.join(out, "index.html"), encoding="utf-8").read()
        check("\x1b" not in page, "archives: index.html holds no escape character")
    finally:
        shutil.rmtree(base, ignore_errors=True)


# Neighbours: what one student's test can see and fill ------------------------------------------


def reader_body(paths):
    """Tries to open each path (a folder too) and throws "seen " + R (read) or - per path."""
    listing = ", ".join(json.dumps(p) for p in paths)
    return ["std::string seen = \"seen \";",
            f"for (const char* path : {{{listing}}}) {{",
            "    int fd = open(path, O_RDONLY);",
            "    seen += fd >= 0 ? 'R' : '-';",
            "    if (fd >= 0) close(fd);",
            "}",
            "throw std::runtime_error(seen);"]


FILL_LIMIT_MB = 512  # the filler stops there: a test must never fill the real disk, whatever the box


def filler_body(places):
    """Writes 8 MB files into every place it can (its folder, /tmp, /dev/shm, home and
    `places`) until each refuses, FILL_LIMIT_MB at most; throws "wrote N MB"."""
    listing = ", ".join(json.dumps(p) for p in places)
    return ["static char block[1 << 20];",
            "long total = 0;",
            "const char* home = std::getenv(\"HOME\");",
            "int place = 0;",
            f"for (const char* dir : {{\".\", \"/tmp\", \"/dev/shm\", home, {listing}}}) {{",
            "    ++place;  // new files only (O_EXCL): a place seen twice (home is .) counts once",
            f"    for (int n = 0; dir && total < {FILL_LIMIT_MB}; ++n) {{",
            "        std::string path = std::string(dir) + \"/fill\" + std::to_string(place) + \"-\" + std::to_string(n);",
            "        int fd = open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0600);",
            "        if (fd < 0) break;",
            "        int mb = 0;",
            "        while (mb < 8 && write(fd, block, sizeof block) == (ssize_t)sizeof block) ++mb;",
            "        total += mb;",
            "        close(fd);",
            "        if (mb < 8) break;",
            "    }",
            "}",
            "throw std::runtime_error(\"wrote \" + std::to_string(total) + \" MB\");"]


def scenario_neighbours(work):
    if not isolation_works():
        print("bubblewrap cannot run here: skipped (the class grader runs only trusted code without it)")
        return SKIPPED
    workers = os.path.join(work, "workers")
    base = outside()
    try:
        subs, out = os.path.join(base, "submissions"), os.path.join(base, "out")
        ids = step_ids()
        points = {e.id: e.points for e in exercises(ROOT)}
        honest = step_files(ids)
        target = [e for e in exercises(ROOT) if e.id == ids[0]][0].path
        # What a grader's folders hold while the class runs: a results file and a table from
        # an earlier run, the class list, the other students' sources and reports.
        os.makedirs(os.path.join(out, "students"))
        for name, text in (("cache.json", '{"config": "earlier", "results": {}}'), ("class.csv", "student\n")):
            with open(os.path.join(out, name), "w") as f:
                f.write(text)
        paths = ["/etc/os-release",  # the system: shown, so an R here proves the reads run
                 os.path.join(subs, "c-reference", target), subs, os.path.join(out, "cache.json"),
                 os.path.join(out, "class.csv"), os.path.join(out, "students"), "/etc/shadow",
                 os.path.join(ROOT, target), os.path.expanduser("~")]
        for w in ("w0", "w1"):
            paths += [os.path.join(workers, w, "src", "tests", f"step{first_step()}_triangle.cpp"),
                      os.path.join(workers, w, "src", target), os.path.join(workers, w, "primed"),
                      os.path.join(workers, w, "reference", "points.txt")]
        reader, hostile_id = hostile(reader_body(paths))
        filler, _ = hostile(filler_body([out, subs, os.path.join(workers, "w0", "build"),
                                         os.path.join(workers, "w1", "build")]))
        write_files(os.path.join(subs, "a-reader"), reader)
        write_files(os.path.join(subs, "b-filler"), filler)
        write_files(os.path.join(subs, "c-reference"), honest)
        write_files(os.path.join(subs, "d-kit"), step_files([]))
        write_files(os.path.join(subs, "e-one"), step_files(ids[:1]))
        r, err = class_run(subs, out, workers)
        check(r.returncode == 0, "neighbours: the class run finishes")
        results = json.load(open(os.path.join(out, "cache.json")))["results"]

        def reason(student):
            rows = results.get(student, {}).get("rows", [])
            return next((x["reason"] for x in rows if x["exercise"] == hostile_id), "")

        seen = reason("a-reader")
        check("seen R" + "-" * (len(paths) - 1) in seen,
              f"neighbours: the reader sees the system and nothing else of the machine: {seen!r} "
              f"(R: read, -: not there; paths {paths})")
        wrote = reason("b-filler")
        mb = int(wrote.split("wrote ")[1].split(" ")[0]) if "wrote " in wrote else None
        check(mb is not None and mb <= 64 + 16 + 16, f"neighbours: the filler wrote only its quota: {wrote!r}")
        full = sum(points[i] for i in ids)
        expected = {"c-reference": full, "d-kit": 0, "e-one": points[ids[0]],
                    "a-reader": full - points[hostile_id], "b-filler": full - points[hostile_id]}
        got = {s: results.get(s, {}).get("total") for s in expected}
        check(got == expected, f"neighbours: every student has exactly their points: {got}, expected {expected}")
        left = [os.path.join(d, n) for d in (out, subs) for n in os.listdir(d) if n.startswith("fill")]
        check(not left, f"neighbours: nothing written outside the test's own folder: {left}")
    finally:
        shutil.rmtree(base, ignore_errors=True)


# A full grading disk ---------------------------------------------------------------------------


def scenario_disk_full(work):
    base = outside()
    try:
        subs, out = os.path.join(base, "submissions"), os.path.join(base, "out")
        ids = step_ids()
        write_files(os.path.join(subs, "a-reference"), step_files(ids))
        write_files(os.path.join(subs, "b-kit"), step_files([]))
        env = dict(os.environ, BOXES_GRADE_MIN_FREE_MB=str(1 << 40))  # more than any disk has
        r, err = class_run(subs, out, os.path.join(work, "workers"), env=env)
        check(r.returncode == 0, "disk-full: the class run finishes")
        build = {row[0]: row[-1] for row in table(out)[1:]}
        for student in ("a-reference", "b-kit"):
            check(build.get(student, "").startswith("not graded: the grading disk is full") and
                  build[student].endswith(", retry"), f"disk-full: {student}: {build.get(student)!r}")
            check(table(out)[[row[0] for row in table(out)].index(student)][len(ids) + 1] == "0",
                  f"disk-full: {student} has no points, not zero points graded")
        r, err = class_run(subs, out, os.path.join(work, "workers"))
        run = json.load(open(os.path.join(out, "run.json")))
        total = {row[0]: row[len(ids) + 1] for row in table(out)[1:]}
        points = {e.id: e.points for e in exercises(ROOT)}
        check(r.returncode == 0 and run["graded"] == 2 and total == {"a-reference": str(sum(points[i] for i in ids)),
                                                                    "b-kit": "0"},
              f"disk-full: nothing was kept; with space again both are graded: {run}, {total}")
    finally:
        shutil.rmtree(base, ignore_errors=True)


def main():
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    scenario, work = sys.argv[1], os.path.abspath(sys.argv[2])
    scenarios = {"links": scenario_links, "archives": scenario_archives, "neighbours": scenario_neighbours,
                 "disk-full": scenario_disk_full}
    if scenario not in scenarios:
        print(__doc__, file=sys.stderr)
        return 2
    if not os.path.isdir(os.path.join(work, "workers", "w0", "build")):
        print(f"{work}/workers is not primed: run python3 -m tests.class_grading_test class {work} first")
        return 1
    started = time.monotonic()
    if scenarios[scenario](work) == SKIPPED:
        return SKIPPED
    print(f"{scenario}: {time.monotonic() - started:.0f} s")
    print(f"{len(failures)} failed" if failures else "all checks passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
