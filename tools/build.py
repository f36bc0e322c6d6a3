"""Configuring and building a tree with CMake and Ninja: the one place for it, used by
./workbook check (tools/check.py), the grader and the mutants.

A Tree is a source folder, its build folder and how that is configured: a preset of
CMakePresets.json, or none (the grader's tree: plain -D settings), with -D settings on top.
The commands are lists, so a caller that runs them its own way (the grader, in its sandbox,
as the student's user) takes them from configure_command(), regenerate_command() and
build_command() and reads the output with first_error(); the others call configure() and
build(), which run them here and say how far the build has got.

The compiler cache (ccache) is the CMake files' business: the top CMakeLists.txt uses it
where it is installed (BOXES_CCACHE), so every preset, the grader's tree and a plain
`cmake -B` get it alike.
"""
import json
import os
import re
import subprocess
import sys
import time
from dataclasses import dataclass, field


@dataclass
class Tree:
    source: str  # the tree's root (its CMakeLists.txt)
    build: str  # the build folder
    preset: str = None  # a configure preset of the source's CMakePresets.json, or None
    cache: dict = field(default_factory=dict)  # -D settings, on top of the preset's

    @classmethod
    def of_preset(cls, source, preset, **cache):
        """The tree a preset configures, in the preset's own folder (build/NAME)."""
        return cls(source, os.path.join(source, "build", preset), preset, dict(cache))


def configure_command(tree):
    """The cmake command that configures the tree (from any working folder)."""
    cmd = ["cmake", "-S", tree.source, "-B", tree.build]
    if tree.preset:
        cmd += ["--preset", tree.preset]
    else:
        cmd += ["-G", "Ninja"]
    return cmd + [f"-D{k}={v}" for k, v in tree.cache.items()]


def regenerate_command(tree):
    """Regenerates the build files if a CMake file changed, building nothing else."""
    return ["cmake", "--build", tree.build, "--target", "build.ninja"]


def build_command(tree, targets, jobs=None):
    """Builds the targets (names, or object files by their path in the build folder). In a
    configured Ninja tree (every preset's, the grader's) ninja itself: `cmake --build` only
    finds and runs it, a tenth of a second on each check."""
    ninja = cached_settings(tree.build).get("CMAKE_MAKE_PROGRAM", "")
    if (os.path.basename(ninja).startswith("ninja") and os.access(ninja, os.X_OK)
            and os.path.exists(os.path.join(tree.build, "build.ninja"))):
        return [ninja, "-C", tree.build, *targets] + ([f"-j{jobs}"] if jobs else [])
    cmd = ["cmake", "--build", tree.build]
    if targets:
        cmd += ["--target", *targets]
    return cmd + (["--", f"-j{jobs}"] if jobs else [])


def cached_settings(build):
    """{name: value} of a build folder's CMakeCache.txt ({} when there is none)."""
    path = os.path.join(build, "CMakeCache.txt")
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            lines = f.read().splitlines()
    except OSError:
        return {}
    return {line.split("=", 1)[0].split(":")[0]: line.split("=", 1)[1] for line in lines
            if "=" in line and not line.startswith(("//", "#"))}


def preset_settings(source, preset):
    """{name: value} of a configure preset's cacheVariables (with those it inherits), as
    CMakeCache.txt holds them; not the compiler, which CMake stores as the path it found."""
    try:
        with open(os.path.join(source, "CMakePresets.json"), encoding="utf-8") as f:
            presets = {p["name"]: p for p in json.load(f).get("configurePresets", [])}
    except (OSError, ValueError):
        return {}
    settings, seen = {}, set()

    def add(name):
        p = presets.get(name)
        if p is None or name in seen:
            return
        seen.add(name)
        inherits = p.get("inherits", [])
        for parent in reversed([inherits] if isinstance(inherits, str) else inherits):
            add(parent)
        for k, v in p.get("cacheVariables", {}).items():
            settings[k] = str(v.get("value", "") if isinstance(v, dict) else v)

    add(preset)
    return {k: v for k, v in settings.items() if not k.endswith("_COMPILER")}


def configured(tree):
    """Whether the build folder is configured with the settings wanted: its preset's (a
    folder configured before the preset gained a setting is configured again, so an old
    build/student gets the precompiled header) and the tree's -D settings on top."""
    if not os.path.exists(os.path.join(tree.build, "build.ninja")):
        return False
    have = cached_settings(tree.build)
    wanted = preset_settings(tree.source, tree.preset) if tree.preset else {}
    wanted.update({k: str(v) for k, v in tree.cache.items()})
    return all(have.get(k) == v for k, v in wanted.items())


# What a failed build says --------------------------------------------------------------------

_COMPILER_ERROR = re.compile(r"(.+?):(\d+):(?:\d+:)?\s*(?:fatal )?error:\s*(.*)")


def relative(path, source):
    """A path the compiler printed (absolute, or relative to a build folder inside the
    tree) relative to the source tree when it is inside it."""
    if os.path.isabs(path):
        rel = os.path.relpath(path, source)
        return path if rel.startswith("..") else rel
    return re.sub(r"^(\.\./)+", "", path)


def first_error(output, source, brief=False):
    """The first error of a failed configure or build, one line of at most 400 characters,
    paths relative to the tree: the compiler's error line, else the linker's, else the
    first line that says error, else ninja's FAILED line, else "the build failed". brief:
    the compiler's error as "file:line: message" (for a student's terminal)."""
    lines = output.splitlines()
    for pattern in (r": (fatal )?error:", r"undefined reference|ld returned", r"\berror\b"):
        for line in lines:
            if re.search(pattern, line) and not line.startswith(("ninja:", "FAILED:")):
                m = _COMPILER_ERROR.match(line)
                if brief and m:
                    line = f"{relative(m.group(1), source)}:{m.group(2)}: {m.group(3)}"
                elif m:
                    line = relative(m.group(1), source) + line[len(m.group(1)):]
                return " ".join(line.replace(source + "/", "").split())[:400]
    for line in lines:
        if line.startswith("FAILED:"):
            return line[:400]
    return "the build failed"


# Running them here ---------------------------------------------------------------------------


@dataclass
class Outcome:
    ok: bool
    output: str  # everything cmake and the compilers printed
    error: str = ""  # first_error() when it failed
    steps: int = 0  # build steps done (compiles and links)
    seconds: float = 0.0


_STEP = re.compile(r"^\[(\d+)/(\d+)\] (.*)")


class Progress:
    """How far a build has got, on the terminal: one line rewritten (a terminal) or a line
    every `every` seconds (a log)."""

    def __init__(self, prefix, stream=None, every=10.0):
        self.prefix, self.stream, self.every = prefix, stream or sys.stderr, every
        self.tty = self.stream.isatty()
        self.shown = time.monotonic()
        self.written = False

    def step(self, done, total, what):
        if self.tty:
            what = re.sub(r"^(Building CXX object|Linking CXX \w+) ", "", what)
            self.stream.write(f"\r\033[K{self.prefix}   {done}/{total} {what[:60]}")
            self.written = True
        elif time.monotonic() - self.shown >= self.every:
            self.shown = time.monotonic()
            self.stream.write(f"{self.prefix}   {done}/{total} built\n")
        self.stream.flush()

    def end(self):
        if self.written:
            self.stream.write("\r\033[K")
            self.stream.flush()
            self.written = False


def run(cmd, progress=None, log=None, env=None, cwd=None):
    """Runs a configure or build command, its output read as it comes (ninja's [k/n] lines
    to `progress`, everything to `log` when given). Returns an Outcome."""
    started = time.monotonic()
    output, steps = [], 0
    p = subprocess.Popen(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                         text=True, errors="replace", env=env)
    try:
        for line in p.stdout:
            output.append(line)
            if log:
                log.write(line)
            m = _STEP.match(line)
            if m and re.match(r"(Building|Linking)", m.group(3)):
                steps += 1
                if progress:
                    progress.step(int(m.group(1)), int(m.group(2)), m.group(3).strip())
        p.wait()
    except BaseException:
        p.kill()
        p.wait()
        raise
    finally:
        if progress:
            progress.end()
    text = "".join(output)
    ok = p.returncode == 0
    return Outcome(ok, text, "" if ok else first_error(text, _source_of(cmd), brief=True), steps,
                   time.monotonic() - started)


def _source_of(cmd):
    return cmd[cmd.index("-S") + 1] if "-S" in cmd else os.getcwd()


def configure(tree, say=None, log=None, env=None):
    """Configures the tree unless it already is, with its settings. Outcome (ok, nothing run
    when it was)."""
    if configured(tree):
        return Outcome(True, "")
    if say:
        say(f"configuring {os.path.relpath(tree.build, tree.source)} "
            f"({'cmake --preset ' + tree.preset if tree.preset else 'cmake'}; once)")
    return run(configure_command(tree), log=log, env=env)


def build(tree, targets, jobs=None, progress=None, log=None, env=None):
    """Builds the targets of a configured tree. Outcome; its error is relative to the tree."""
    r = run(build_command(tree, targets, jobs), progress=progress, log=log, env=env)
    if not r.ok:
        r.error = first_error(r.output, tree.source, brief=True)
    return r

