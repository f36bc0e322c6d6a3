"""The checker's and the worker's generated C++: one proxy and one server stub per exercise.

From each exercise marker (exercises.py) the function's declaration is read (its template
parameters, return type, name, parameters, const), and three pieces are written:
  - the checker's copy of the exercise's file: the function's body replaced by a call of
    judge_calls::ex_N_M, declared just after the marker (checker_text);
  - the checker's proxies, one C++ file per step library: ex_N_M sends the arguments to the
    worker and returns its answer (proxies_source);
  - the worker's server, one program per step: reads a call, calls the student's function,
    answers (worker_source).
The declarative part is the table below: which template parameters are numbers (served for
float and double) and which are callbacks, with their signatures. Everything else comes from
the reference's declarations, so a new exercise of plain types needs no entry here, only its
types in judge/types_NN.hpp.
"""
import os
import re
from dataclasses import dataclass

# Template parameters that stand for a callable: {exercise: {parameter name: signature}}.
CALLBACKS = {
    "4.4": {"intersect": "bool(uint32_t, float&)"},
    "4.5": {"intersect": "bool(uint32_t, float)"},
    "5.4": {"blocks": "bool(size_t)"},
}
# A template parameter T of a number type: the exercise is served for each type its file
# instantiates (a line BOXES_INSTANTIATE(long double), say), else for these.
NUMBER_VARIANTS = ("float", "double")


def instantiated_types(text):
    """The types a file instantiates its templates for: BOXES_INSTANTIATE(T) lines."""
    found = []
    for m in re.finditer(r"^BOXES_INSTANTIATE\(([^)]*)\)", text, re.M):
        t = " ".join(m.group(1).split())
        if t not in found:
            found.append(t)
    return tuple(found) or NUMBER_VARIANTS


class StubError(Exception):
    """An exercise's declaration the generator cannot read (one line)."""


@dataclass
class Param:
    type: str  # as declared: "const RayT<T>&"
    name: str
    callback: str = ""  # its signature when it is a callback: "bool(uint32_t, float&)"


@dataclass
class Signature:
    id: str  # "1.4"
    path: str  # relative to the tree's root
    number_params: list  # template parameters served per number type: ["T"]
    ret: str  # "std::optional<TriangleHit<T>>"
    name: str  # "intersectMollerTrumbore" or "SinTable::sinNearest"
    params: list  # [Param]
    const_method: bool = False
    body: tuple = (0, 0)  # [start, end) of the body's braces in the file's text
    after_marker: int = 0  # offset just after the marker's line
    number_types: tuple = NUMBER_VARIANTS  # what a number template parameter is served for

    @property
    def symbol(self):
        return "ex_" + self.id.replace(".", "_")

    @property
    def cls(self):
        return self.name.rsplit("::", 1)[0] if "::" in self.name else ""

    @property
    def method(self):
        return self.name.rsplit("::", 1)[-1]

    def variants(self):
        """[(variant name, {template parameter: type})]: one per served instantiation."""
        if not self.number_params:
            return [("", {})]
        return [(v, {p: v for p in self.number_params}) for v in self.number_types]

    def self_param(self):
        if not self.cls:
            return []
        return [Param(("const " if self.const_method else "") + self.cls + "&", "self")]

    def proxy_params(self):
        """The proxy's parameters: the object first for a member, callbacks type-erased."""
        out = self.self_param()
        for p in self.params:
            if p.callback:
                out.append(Param(f"::boxes::judge::Callback<{p.callback}>", p.name, p.callback))
            else:
                out.append(p)
        return out

    def proxy_declaration(self):
        template = ("template <" + ", ".join(f"typename {t}" for t in self.number_params) + ">\n"
                    if self.number_params else "")
        params = ", ".join(f"{p.type} {p.name}" for p in self.proxy_params())
        return f"{template}{self.ret} {self.symbol}({params})"


def substitute(text, types):
    for name, value in types.items():
        text = re.sub(rf"\b{re.escape(name)}\b", value, text)
    return text


# Reading C++ just enough: comments, string and character literals skipped ---------------


def _code_mask(text):
    """A list of booleans: True where text[i] is code (not in a comment or a literal)."""
    mask = [True] * len(text)
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            mask[i:j] = [False] * (j - i)
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            mask[i:j] = [False] * (j - i)
            i = j
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            j = min(n, j + 1)
            mask[i:j] = [False] * (j - i)
            i = j
        else:
            i += 1
    return mask


def _split_top(text, sep):
    # exercises._split_top_level's loop, but an empty last part is kept: parse_signature takes
    # the part after the last ';', which is empty when the text ends with one.
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
    parts.append(part)
    return parts


def _matching(text, mask, start, open_="{", close="}"):
    depth = 0
    for i in range(start, len(text)):
        if not mask[i]:
            continue
        if text[i] == open_:
            depth += 1
        elif text[i] == close:
            depth -= 1
            if depth == 0:
                return i
    raise StubError("no closing brace")


def parse_signature(exercise, text):
    """The Signature of `exercise` (exercises.Exercise) in its file's text."""
    mask = _code_mask(text)
    lines = text.split("\n")
    after_marker = sum(len(line) + 1 for line in lines[:exercise.marker_line + 1])
    # The body's brace: the first '{' in code, outside parentheses, after the marker.
    depth, body_start = 0, -1
    for i in range(after_marker, len(text)):
        if not mask[i]:
            continue
        if text[i] == "(":
            depth += 1
        elif text[i] == ")":
            depth -= 1
        elif text[i] == "{" and depth == 0:
            body_start = i
            break
    if body_start < 0:
        raise StubError(f"exercise {exercise.id}: no function body after its marker")
    body_end = _matching(text, mask, body_start) + 1
    head = "".join(ch if mask[after_marker + k] else " "
                   for k, ch in enumerate(text[after_marker:body_start]))
    decl = " ".join(_split_top(head, ";")[-1].split())
    template_params = []
    m = re.match(r"template\s*<(.*?)>\s*(.*)$", decl)
    if m:
        for p in _split_top(m.group(1), ","):
            words = p.replace("=", " = ").split()
            if len(words) >= 2 and words[0] in ("typename", "class"):
                template_params.append(words[1])
        decl = m.group(2)
    decl = re.sub(r"\[\[[^\]]*\]\]\s*", "", decl)
    while True:
        m = re.match(r"(inline|static|constexpr|extern)\s+(.*)$", decl)
        if not m:
            break
        decl = m.group(2)
    close = decl.rfind(")")
    depth, open_ = 0, -1
    for i in range(close, -1, -1):
        if decl[i] == ")":
            depth += 1
        elif decl[i] == "(":
            depth -= 1
            if depth == 0:
                open_ = i
                break
    if open_ < 0:
        raise StubError(f"exercise {exercise.id}: cannot read its declaration: {decl!r}")
    before, inside, after = decl[:open_].rstrip(), decl[open_ + 1:close], decl[close + 1:]
    m = re.search(r"((?:\w+\s*::\s*)*~?\w+)$", before)
    if not m:
        raise StubError(f"exercise {exercise.id}: no function name in {decl!r}")
    name = re.sub(r"\s+", "", m.group(1))
    ret = before[:m.start()].strip()
    params = []
    for p in _split_top(inside, ","):
        p = p.split("=")[0].strip()
        if not p or p == "void":
            continue
        pm = re.search(r"(\w+)\s*$", p)
        if not pm:
            raise StubError(f"exercise {exercise.id}: a parameter without a name: {p!r}")
        params.append(Param(p[:pm.start()].strip(), pm.group(1)))
    callbacks = CALLBACKS.get(exercise.id, {})
    number_params = []
    for t in template_params:
        callback_params = [p for p in params if re.fullmatch(rf"{t}\s*&&?", p.type)]
        if callback_params:
            for p in callback_params:
                if p.name not in callbacks:
                    raise StubError(f"exercise {exercise.id}: parameter {p.name} is a callable "
                                    "with no signature in judge/stubs.py's CALLBACKS")
                p.callback = callbacks[p.name]
        else:
            number_params.append(t)
    if not ret:
        raise StubError(f"exercise {exercise.id}: no return type in {decl!r}")
    return Signature(exercise.id, exercise.path, number_params, ret, name, params,
                     const_method=bool(re.search(r"\bconst\b", after)),
                     body=(body_start, body_end), after_marker=after_marker,
                     number_types=instantiated_types(text))


# The generated pieces --------------------------------------------------------------------

GENERATED = "// Generated by tools/grading/judge/stubs.py for the grader; not for editing.\n"


def checker_text(text, signatures):
    """The checker's copy of one exercise file: each exercise's body calls its proxy."""
    out, pos = [], 0
    for s in sorted(signatures, key=lambda s: s.after_marker):
        args = (["*this"] if s.cls else []) + [p.name for p in s.params]
        call = (f"::boxes::judge_calls::{s.symbol}"
                + (f"<{', '.join(s.number_params)}>" if s.number_params else "")
                + f"({', '.join(args)})")
        out.append(text[pos:s.after_marker])
        out.append(f"namespace judge_calls {{\n{s.proxy_declaration()};\n}}  // namespace judge_calls\n")
        out.append(text[s.after_marker:s.body[0]])
        out.append(f"{{\n    return {call};\n}}")
        pos = s.body[1]
    out.append(text[pos:])
    result = "".join(out)
    # The callback type, before the file's first line of code.
    m = re.search(r"^#pragma once[^\n]*\n", result, re.M) or re.search(r"^#include[^\n]*\n", result, re.M)
    at = m.end() if m else 0
    return result[:at] + '#include "judge/callback.hpp"\n' + result[at:]


def proxies_source(signatures, headers):
    """The checker's proxies of one step library's exercises."""
    out = [GENERATED, '#include "judge/checker.hpp"\n']
    out += [f'#include "{h}"\n' for h in headers]
    out.append("\nnamespace boxes::judge_calls {\n")
    for s in signatures:
        params = s.proxy_params()
        types = ", ".join(f"decltype({p.name})" for p in params)
        variant = (f"::boxes::judge::variantOf<{s.number_params[0]}>()" if s.number_params else '""')
        out.append(f"\n{s.proxy_declaration()} {{\n    return ::boxes::judge::remote<{s.ret}"
                   f"{', ' + types if types else ''}>(\"{s.id}\", {variant}"
                   f"{''.join(', ' + p.name for p in params)});\n}}\n")
        for variant, types_of in (s.variants() if s.number_params else []):
            sig = ", ".join(substitute(p.type, types_of) for p in params)
            out.append(f"template {substitute(s.ret, types_of)} {s.symbol}<"
                       f"{', '.join(types_of[t] for t in s.number_params)}>({sig});\n")
    out.append("\n}  // namespace boxes::judge_calls\n")
    return "".join(out)


def worker_source(signatures, headers):
    """The worker's server: a handler per exercise and variant, and main()."""
    out = [GENERATED, '#include "judge/worker.hpp"\n']
    out += [f'#include "{h}"\n' for h in headers]
    out.append("\nnamespace boxes::judge_worker {\n")
    entries = []
    for s in signatures:
        for variant, types_of in s.variants():
            fn = f"{s.symbol}{'_' + variant.replace(' ', '_') if variant else ''}"
            params = s.proxy_params()
            body = [f"    ::boxes::judge::Slot<{substitute(p.type, types_of)}> a{i}(r);"
                    for i, p in enumerate(params)]
            body.append("    r.expectEnd();")
            args = [f"a{i}.arg()" for i in range(len(params))]
            if s.cls:
                callee = f"a0.arg().{s.method}"
                args = args[1:]
            else:
                callee = f"::boxes::{s.name}" + (
                    f"<{', '.join(types_of[t] for t in s.number_params)}>" if s.number_params else "")
            call = f"{callee}({', '.join(args)})"
            ret = substitute(s.ret, types_of)
            if ret == "void":
                body.append(f"    {call};")
            else:
                body.append(f"    {ret} result = {call};")
                body.append("    ::boxes::judge::put(w, result);")
            body += [f"    a{i}.back(w);" for i in range(len(params))]
            out.append(f"\nvoid {fn}(::boxes::judge::Reader& r, ::boxes::judge::Writer& w) {{\n"
                       + "\n".join(body) + "\n}\n")
            entries.append(f'    {{"{s.id}", "{variant}", {fn}}},')
    out.append("\nconst ::boxes::judge::Entry kTable[] = {\n" + "\n".join(entries) + "\n};\n")
    out.append("\n}  // namespace boxes::judge_worker\n\n"
               "int main() {\n    return ::boxes::judge::serve(::boxes::judge_worker::kTable);\n}\n")
    return "".join(out)


def step_of(path):
    """'04' for steps/04_bvh/traverse.hpp."""
    m = re.match(r"steps/(\d\d)_", path.replace(os.sep, "/"))
    return m.group(1) if m else None
