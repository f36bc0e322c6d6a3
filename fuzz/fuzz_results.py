#!/usr/bin/python3
"""Fuzzes the grader's reading of test results (Python, so not libFuzzer: Hypothesis).

usage: python3 -m fuzz.fuzz_results SECONDS [--artifacts DIR]   fuzz for SECONDS (fuzz/fuzz.sh)
       python3 -m fuzz.fuzz_results --replay PATH...             every corpus file once (ctest)

The functions: tools/grading/exercises.py case_results (doctest's XML results, from a file as
the grader and the tour's report read them, and from a string), and tools/grading/judge
listed_cases (the XML of a checker's --list-test-cases, from its stdout as raw bytes).

Inputs: Hypothesis draws a seed (a file of fuzz/corpus/results/: real doctest output and
the malformed ones found, or a built-in generated one) and mutates it (truncation, spliced
bytes, attribute values of any text or type, repeated and nested elements, entities,
encodings), or writes doctest-like XML from scratch.

Promises, whatever the input: case_results returns a list of CaseResult (str suite and
name, bool passed, a one-line message, empty when passed) within 30 s; listed_cases returns
[(suite, name, file)] or raises JudgeError (its documented error). A broken promise is saved
as DIR/crash-SHA1 (a hang as timeout-SHA1) and the exit status is 1; copy it into the
corpus with the fix. Before each input the input is also written to DIR/current, so a
crash of the interpreter itself leaves it behind (fuzz/fuzz.sh keeps it).
"""
import hashlib
import os
import signal
import sys
import tempfile
import time

from tools import ROOT
from tools.grading import exercises

try:
    from tools.grading import judge
except Exception as e:  # a starter kit has no grader: fuzz what exists
    judge = None
    print(f"fuzz_results: tools/grading/judge not imported ({e}); listed_cases not fuzzed", file=sys.stderr)

CORPUS = os.path.join(ROOT, "fuzz", "corpus", "results")
TIME_LIMIT = 30.0  # seconds per input: longer is a hang, as in fuzz/fuzz.sh


OPEN_FINDINGS = set()  # known findings owned elsewhere, reported without failing (none open)


class BrokenPromise(AssertionError):
    pass


class Hang(Exception):
    pass


def _on_alarm(signum, frame):
    raise Hang(f"no answer within {TIME_LIMIT:g} s")


# Generated seeds: too large (or too repetitive) to commit, made the same every run.
def generated_seeds():
    case = ('<TestCase name="c{i}" filename="t.cpp" line="1"><Expression success="false" type="CHECK"'
            ' filename="t.cpp" line="2"><Original>x</Original><Expanded>1 == 2</Expanded>'
            '<Info>i={i}</Info></Expression><OverallResultsAsserts successes="0" failures="1"'
            ' test_case_success="false"/></TestCase>')
    nested_suites = ('<doctest>' + '<TestSuite name="s"><TestCase name="c">'
                     '<OverallResultsAsserts failures="1"/>' * 3000 + '</TestCase></TestSuite>' * 3000 +
                     '</doctest>')
    nested_expressions = ('<doctest><TestSuite name="s"><TestCase name="c">' +
                          '<SubCase name="a"><Expression success="true">' * 20000 +
                          '</Expression></SubCase>' * 20000 +
                          '<OverallResultsAsserts failures="1"/></TestCase></TestSuite></doctest>')
    many_cases = ('<doctest><TestSuite name="exercise 1.1">' +
                  "".join(case.format(i=i) for i in range(5000)) + '</TestSuite></doctest>')
    long_text = ('<doctest><TestSuite name="s"><TestCase name="c"><Exception>' + "x\n" * 2000000 +
                 '</Exception><OverallResultsAsserts failures="1"/></TestCase></TestSuite></doctest>')
    # Entities: expat refuses the billion laughs (amplification limit); one 100 kB entity
    # used 1000 times (100 MB) is refused the same way.
    laughs = ('<?xml version="1.0"?><!DOCTYPE d [<!ENTITY l0 "lol">' +
              "".join(f'<!ENTITY l{i} "{("&l%d;" % (i - 1)) * 10}">' for i in range(1, 10)) +
              ']><doctest><TestSuite name="&l9;"/></doctest>')
    quadratic = ('<?xml version="1.0"?><!DOCTYPE d [<!ENTITY a "' + "a" * 100000 + '">]><doctest>'
                 '<TestSuite name="s"><TestCase name="c"><Exception>' + "&a;" * 1000 +
                 '</Exception></TestCase></TestSuite></doctest>')
    return {
        "generated:nested_suites": nested_suites.encode(),
        "generated:nested_expressions": nested_expressions.encode(),
        "generated:many_cases": many_cases.encode(),
        "generated:long_text": long_text.encode(),
        "generated:billion_laughs": laughs.encode(),
        "generated:quadratic_entity": quadratic.encode(),
        # One byte over the limit: refused without parsing.
        "generated:oversized": b"<doctest>" + b" " * (exercises.MAX_RESULT_BYTES - 18) + b"</doctest>",
    }


def _check_cases(results, how):
    if not isinstance(results, list):
        raise BrokenPromise(f"case_results({how}) returned {type(results).__name__}, not a list")
    for r in results:
        if not isinstance(r, exercises.CaseResult):
            raise BrokenPromise(f"case_results({how}) gave a {type(r).__name__}")
        if not (isinstance(r.suite, str) and isinstance(r.name, str) and isinstance(r.passed, bool)
                and isinstance(r.message, str)):
            raise BrokenPromise(f"case_results({how}) gave wrong field types: {r!r}"[:300])
        if "\n" in r.message or "\r" in r.message:
            raise BrokenPromise(f"case_results({how}): a message of several lines")
        if r.passed and r.message:
            raise BrokenPromise(f"case_results({how}): a passed case with a message")


def _check_list(data, workdir):
    if judge is None:
        return
    try:
        cases = judge.listed_cases(data)
    except judge.JudgeError:
        return
    if not isinstance(cases, list) or not all(
            isinstance(c, tuple) and len(c) == 3 and all(isinstance(x, str) for x in c) for c in cases):
        raise BrokenPromise("listed_cases returned something else than [(suite, name, file)]")


def check(data, workdir):
    """Runs one input through every reader; raises BrokenPromise or Hang. listed_cases reads
    a trusted checker's output without a size limit, so it gets only inputs under
    case_results' limit."""
    path = os.path.join(workdir, "result.xml")
    with open(path, "wb") as f:
        f.write(data)
    old = signal.signal(signal.SIGALRM, _on_alarm)
    signal.setitimer(signal.ITIMER_REAL, TIME_LIMIT)
    try:
        _check_cases(exercises.case_results(path), "file")
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError:
            text = None
        # Only text that is XML: other strings are paths, and the fuzzer opens no paths.
        if text is not None and text.lstrip().startswith("<"):
            _check_cases(exercises.case_results(text), "string")
        if len(data) <= exercises.MAX_RESULT_BYTES:
            _check_list(data, workdir)
    except (BrokenPromise, Hang):
        raise
    except Exception as e:  # any other exception escaping is a crash of the grader
        raise BrokenPromise(f"{type(e).__name__}: {e}"[:300]) from e
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def corpus_files(paths):
    files = []
    for p in paths:
        if os.path.isdir(p):
            files += sorted(os.path.join(p, f) for f in os.listdir(p) if os.path.isfile(os.path.join(p, f)))
        else:
            files.append(p)
    return files


def replay(paths):
    seeds = [(os.path.basename(f), open(f, "rb").read()) for f in corpus_files(paths)]
    if not seeds:
        print("fuzz_results: no corpus files given", file=sys.stderr)
        return 2
    seeds += sorted(generated_seeds().items())
    failed = 0
    with tempfile.TemporaryDirectory(prefix="boxes-fuzz-results-") as work:
        for name, data in seeds:
            started = time.monotonic()
            try:
                check(data, work)
                status = "ok"
            except (BrokenPromise, Hang) as e:
                status = f"BROKEN: {e}"
                failed += 1
            print(f"replay {name} ({len(data)} bytes, {time.monotonic() - started:.2f} s): {status}",
                  file=sys.stderr)
    print(f"replayed {len(seeds)} inputs, {failed} broken promises")
    for finding in sorted(OPEN_FINDINGS):
        print(f"open finding (not ours to fix): {finding}")
    return 1 if failed else 0


def fuzz(seconds, artifacts):
    # Hypothesis keeps a cache (unicode data) in .hypothesis/ of the current folder: not
    # in the source tree.
    os.environ.setdefault("HYPOTHESIS_STORAGE_DIRECTORY", os.path.join(ROOT, "build", "fuzz", "hypothesis"))
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st

    os.makedirs(artifacts, exist_ok=True)
    seeds = [open(f, "rb").read() for f in corpus_files([CORPUS])]
    # The small generated seeds mutate quickly; the large ones are the replay's business.
    seeds += [d for d in generated_seeds().values() if len(d) < 20000]
    names = ["doctest", "TestSuite", "TestCase", "SubCase", "Expression", "Original", "Expanded",
             "Exception", "Info", "Message", "Text", "OverallResultsAsserts", "Options"]
    attrs = ["name", "success", "type", "filename", "line", "failures", "test_case_success",
             "skipped", "testsuite", "crash"]
    attr_value = st.one_of(st.text(max_size=20), st.sampled_from(["true", "false", "0", "1", "-1", "",
                                                                  "1e999", "nan", "&#10;", "&lt;"]))

    def escape(s):
        return s.replace("&", "&amp;").replace("<", "&lt;").replace('"', "&quot;")

    @st.composite
    def element(draw, depth=0):
        tag = draw(st.sampled_from(names))
        at = draw(st.dictionaries(st.sampled_from(attrs), attr_value, max_size=4))
        text = "".join(f' {k}="{escape(v)}"' for k, v in at.items())
        kids = []
        if depth < 4:
            kids = draw(st.lists(element(depth + 1), max_size=3))
        body = escape(draw(st.text(max_size=10))) + "".join(kids)
        return f"<{tag}{text}>{body}</{tag}>"

    @st.composite
    def mutated(draw):
        if draw(st.integers(0, 9)) == 0:
            return ("<doctest>" + draw(element()) + "</doctest>").encode(
                draw(st.sampled_from(["utf-8", "utf-16", "latin-1"])), errors="replace")
        data = bytearray(draw(st.sampled_from(seeds)))
        for _ in range(draw(st.integers(1, 4))):
            op = draw(st.integers(0, 6))
            pos = draw(st.integers(0, len(data)))
            if op == 0:  # truncated
                del data[pos:]
            elif op == 1:  # bytes spliced in
                data[pos:pos] = draw(st.binary(max_size=16))
            elif op == 2:  # a stretch removed
                del data[pos:pos + draw(st.integers(0, 64))]
            elif op == 3:  # a piece of markup inserted
                data[pos:pos] = draw(st.sampled_from(
                    [b"<TestCase>", b"</TestCase>", b"<TestSuite name='x'>", b"<Exception/>",
                     b'<Expression success="false">', b"&amp;", b"&undefined;", b"<!--", b"]]>",
                     b"<![CDATA[", b'<?xml version="1.0" encoding="latin-1"?>', b"\x00", b"\xff\xfe",
                     b'<!DOCTYPE d [<!ENTITY e "&e;">]>', b'<!ENTITY x SYSTEM "/etc/passwd">']))
            elif op == 4:  # an attribute value of any text or type
                eq = data.find(b'="', pos)
                if eq >= 0:
                    end = data.find(b'"', eq + 2)
                    if end >= 0:
                        data[eq + 2:end] = escape(draw(attr_value)).encode("utf-8", "surrogatepass")
            elif op == 5:  # a stretch repeated (many cases, deep nesting)
                n = draw(st.integers(0, 64))
                data[pos:pos] = bytes(data[pos:pos + n]) * draw(st.integers(2, 200))
            else:  # an element written from scratch
                data[pos:pos] = draw(element()).encode("utf-8", "surrogatepass")
        return bytes(data[:1 << 20])

    failing = []
    # Removed when this object goes or the interpreter exits (also after Ctrl-C; SIGTERM
    # exits through main's handler).
    scratch = tempfile.TemporaryDirectory(prefix="boxes-fuzz-results-")
    work = scratch.name
    current = os.path.join(artifacts, "current")

    @settings(max_examples=200, database=None, deadline=None, derandomize=False,
              suppress_health_check=list(HealthCheck), print_blob=False)
    @given(mutated())
    def one(data):
        with open(current, "wb") as f:
            f.write(data)
        try:
            check(data, work)
        except (BrokenPromise, Hang) as e:
            failing[:] = [data, e]
            raise
        runs[0] += 1

    runs = [0]
    started = time.monotonic()
    status = 0
    while time.monotonic() - started < seconds:
        try:
            one()
        except (BrokenPromise, Hang):
            data, e = failing
            kind = "timeout" if isinstance(e, Hang) else "crash"
            out = os.path.join(artifacts, f"{kind}-{hashlib.sha1(data).hexdigest()}")
            with open(out, "wb") as f:
                f.write(data)
            print(f"fuzz_results: broken promise: {e}\n  input ({len(data)} bytes) written to {out}")
            status = 1
            break
    if os.path.exists(current):
        os.remove(current)
    elapsed = time.monotonic() - started
    for finding in sorted(OPEN_FINDINGS):
        print(f"open finding (not ours to fix): {finding}")
    print(f"stat::number_of_executed_runs: {runs[0]}")
    print(f"#{runs[0]} DONE in {elapsed:.0f} s ({runs[0] / max(elapsed, 1e-9):.0f} exec/s), "
          f"{len(seeds)} seeds")
    return status


def main(argv):
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))  # exit, so the scratch folders go
    if len(argv) >= 2 and argv[0] == "--replay":
        return replay(argv[1:])
    if len(argv) in (1, 3) and argv[0].isdigit() and (len(argv) == 1 or argv[1] == "--artifacts"):
        artifacts = argv[2] if len(argv) == 3 else os.path.join(ROOT, "build", "fuzz", "artifacts", "results")
        return fuzz(int(argv[0]), artifacts)
    print(__doc__.split("\n\n")[1], file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
