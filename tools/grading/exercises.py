"""The exercise markers and doctest's XML results, shared by the tour's report
(tools/report.py), the starter kit (kit.py) and grading (grade.py).

A marker, as in steps/01_triangle/triangle.cpp:

    // EXERCISE 1.4: Moller-Trumbore ray/triangle intersection (2 points)
    template <typename T>
    std::optional<TriangleHit<T>> intersectMollerTrumbore(const RayT<T>& ray, const TriangleT<T>& tri) {
        // BEGIN SOLUTION
        ...
        // END SOLUTION
    }
"""
import glob
import os
import re
import stat
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field

EXERCISE = re.compile(r"//\s*EXERCISE\s+(\d+\.\d+):\s*(.*?)\s*\((\d+)\s+points?\)")
BEGIN = re.compile(r"^\s*//\s*BEGIN SOLUTION\s*$")
END = re.compile(r"^\s*//\s*END SOLUTION\s*$")
SOURCE_SUFFIXES = (".cpp", ".hpp", ".h", ".cc", ".inl")


@dataclass
class Exercise:
    id: str  # "1.4"
    title: str
    points: int
    path: str  # relative to the tree's root
    marker_line: int = 0  # 0-based index of the EXERCISE line
    begin: int = -1  # 0-based index of the BEGIN SOLUTION line (-1: none found)
    end: int = -1  # 0-based index of the END SOLUTION line
    parameters: list = field(default_factory=list)  # parameter names of the function

    @property
    def key(self):
        return tuple(int(x) for x in self.id.split("."))

    @property
    def step(self):
        return int(self.id.split(".")[0])


def step_dirs(root):
    """The step folders steps/NN_name that exist, in order."""
    return sorted(d for d in glob.glob(os.path.join(root, "steps", "[0-9][0-9]_*")) if os.path.isdir(d))


def step_sources(root, step_dir=None):
    """Every C++ source or header under the steps (or under one step folder)."""
    dirs = [step_dir] if step_dir else step_dirs(root)
    found = []
    for d in dirs:
        for base, _, files in os.walk(d):
            found += [os.path.join(base, f) for f in files if f.endswith(SOURCE_SUFFIXES)]
    return sorted(found)


def _split_top_level(text, sep=","):
    depth, part, parts = 0, "", []
    for ch in text:
        if ch in "(<[{":
            depth += 1
        elif ch in ")>]}":
            depth -= 1
        if ch == sep and depth == 0:
            parts.append(part)
            part = ""
        else:
            part += ch
    if part.strip():
        parts.append(part)
    return parts


def parameter_names(signature):
    """Names of the parameters in a function signature text ("... f(const A& a, int b) {")."""
    close = signature.rfind(")")
    if close < 0:
        return []
    depth, open_ = 0, -1
    for i in range(close, -1, -1):
        if signature[i] == ")":
            depth += 1
        elif signature[i] == "(":
            depth -= 1
            if depth == 0:
                open_ = i
                break
    names = []
    for p in _split_top_level(signature[open_ + 1 : close]):
        p = p.split("=")[0].strip()
        m = re.search(r"([A-Za-z_]\w*)\s*(\[[^\]]*\])?$", p)
        # A name follows a type: "const Ray& ray", "float u"; "int" or "const Ray&" has none.
        if m and re.search(r"[\w&*>]\s*[&*]?\s*[A-Za-z_]\w*\s*(\[[^\]]*\])?$", p) and len(re.findall(r"\w+", p)) > 1:
            names.append(m.group(1))
    return names


def parse_file(path, root):
    """The exercises marked in one file, with their solution blocks' line numbers."""
    with open(path, encoding="utf-8") as f:
        lines = f.read().split("\n")
    found = []
    for i, line in enumerate(lines):
        m = EXERCISE.search(line)
        if not m:
            continue
        ex = Exercise(m.group(1), m.group(2), int(m.group(3)), os.path.relpath(path, root), i)
        for j in range(i + 1, len(lines)):
            if EXERCISE.search(lines[j]):
                break
            if BEGIN.match(lines[j]):
                ex.begin = j
                ex.parameters = parameter_names("\n".join(lines[i + 1 : j]).rsplit("{", 1)[0])
                for k in range(j + 1, len(lines)):
                    if END.match(lines[k]):
                        ex.end = k
                        break
                    if BEGIN.match(lines[k]) or EXERCISE.search(lines[k]):
                        break
                break
        found.append(ex)
    return found


def exercises(root):
    """Every exercise marked in the steps' sources, sorted by number."""
    found = []
    for path in step_sources(root):
        found += parse_file(path, root)
    return sorted(found, key=lambda e: e.key)


# doctest XML (--reporters=xml) -------------------------------------------------------------


@dataclass
class CaseResult:
    suite: str
    name: str
    passed: bool
    message: str = ""  # the first failure, one line


# The largest results file read (bytes): one test program's results are far smaller, and a
# student's code, which writes into the same process, must not make the grader parse
# gigabytes.
MAX_RESULT_BYTES = 64 << 20


def _case_elements(case):
    """The elements of a <TestCase> in document order, without descending into a nested
    <TestSuite> or <TestCase> (doctest writes none; a forged file may nest thousands,
    which walking every subtree made quadratic)."""
    stack = list(reversed(case))
    while stack:
        el = stack.pop()
        if el.tag in ("TestSuite", "TestCase"):
            continue
        yield el
        stack.extend(reversed(el))


def _first_failure(case):
    """The first failed assertion or exception of a <TestCase>, as one line."""
    for el in _case_elements(case):
        if el.tag == "Expression" and el.get("success") == "false":
            orig = (el.findtext("Original") or "").strip()
            exp = (el.findtext("Expanded") or "").strip()
            exc = (el.findtext("Exception") or "").strip()
            where = f"{os.path.basename(el.get('filename', ''))}:{el.get('line', '')}"
            text = f"{el.get('type', 'CHECK')}( {orig} )"
            if exc:
                text += f" threw: {exc}"
            elif exp and exp != orig:
                text += f" is {exp}"
            infos = [i.text.strip() for i in el.findall("Info") if i.text]
            if infos:
                text += " [" + "; ".join(infos) + "]"
            return f"{where}: {text}"
        if el.tag == "Exception":
            return f"threw: {(el.text or '').strip()}"
        if el.tag == "Message" and el.get("type", "").upper() in ("FAIL", "FAIL_CHECK", "ERROR"):
            return (el.findtext("Text") or "").strip()
    return ""


def _parse_results(path_or_text):
    """The root element, or None when the input cannot be read as XML."""
    try:
        if isinstance(path_or_text, bytes) or (isinstance(path_or_text, str)
                                                and path_or_text.lstrip().startswith("<")):
            if len(path_or_text) > MAX_RESULT_BYTES:
                return None
            return ET.fromstring(path_or_text)
        # A FIFO or device would block or never end: regular files only, of bounded size.
        info = os.stat(path_or_text)
        if not stat.S_ISREG(info.st_mode) or info.st_size > MAX_RESULT_BYTES:
            return None
        with open(path_or_text, "rb") as f:
            data = f.read(MAX_RESULT_BYTES + 1)
        if len(data) > MAX_RESULT_BYTES:
            return None
        return ET.fromstring(data)
    # ParseError: malformed (also expat's refusal of entity expansion bombs); LookupError: an
    # unknown encoding="..." in the declaration; ValueError: a NUL in a path.
    except (ET.ParseError, OSError, LookupError, ValueError):
        return None


def case_results(path_or_text):
    """Every <TestCase> in one doctest XML file (or string starting with "<", or bytes): suite, name,
    passed, message (one line; empty when passed).

    Never raises for what the file holds: a missing, unreadable, non-regular, truncated,
    malformed or oversized (over MAX_RESULT_BYTES) input gives [], XML that is not
    doctest's gives the test cases it has (none, or failed ones when their results are
    missing). Time and memory are linear in the input's size."""
    root = _parse_results(path_or_text)
    if root is None:
        return []
    results = []
    for suite in root.iter("TestSuite"):
        for case in suite.findall("TestCase"):  # doctest writes them as the suite's children
            if case.get("skipped") == "true":  # filtered out of this run
                continue
            res = case.find("OverallResultsAsserts")
            ok = res is not None and res.get("failures", "0") == "0"
            ok = ok and res.get("test_case_success", "true") == "true"
            if case.find("Exception") is not None:
                ok = False
            results.append(CaseResult(suite.get("name", ""), case.get("name", ""), ok,
                                      "" if ok else " ".join(_first_failure(case).split())))
    return results


def suite_results(out):
    """{suite name: (passed, failed)} over the test_*.xml files in a folder."""
    results = {}
    for path in glob.glob(os.path.join(out, "test_*.xml")):
        for r in case_results(path):
            passed, failed = results.get(r.suite, (0, 0))
            results[r.suite] = (passed + 1, failed) if r.passed else (passed, failed + 1)
    return results
