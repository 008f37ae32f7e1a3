#!/usr/bin/env python3
"""Lint of the HLS sources: only the synthesisable subset may be reachable from the top functions.

The translation unit of the top functions is compiled with g++ -O0 -fcallgraph-info (GCC >= 10),
which writes the call graph with every callee, including external ones (malloc, operator new,
sin, __cxa_guard_acquire for a run-time-initialised static, __indirect_call for a function pointer
or virtual call).  From the top functions, every function reachable in the project's own sources
(hls/, model/include/) is checked; Xilinx's ap_types and hls_stream headers are the library Vitis
implements natively and are not entered.  Violations:

    dynamic-memory   operator new/delete, malloc, calloc, realloc, free
    std-library      any function of the C++ standard library (std::vector, std::string, ...)
    math-library     sin, cos, sqrt, ... (any external call outside the allow-list is reported)
    external-call    any other external function (printf, exceptions, ...)
    runtime-static   a static initialised at run time (__cxa_guard_acquire), or a namespace-scope
                     initialiser that runs project code
    indirect-call    a call through a function pointer or a virtual function
    recursion        a cycle in the call graph
    loop-bound       a while/do loop, or a for loop whose bound is not a compile-time constant
                     (literals, ALL_CAPS or template-parameter names, constexpr members), in the
                     body of a reachable project function
    source-token     new, malloc, free, std::vector, std::string, virtual, throw, try in the HLS
                     sources themselves (hls/ts_*.h, hls/ts_*.cpp)

    python scripts/hls_lint.py                 lint hls/ts_servo_top.cpp (all six top functions)
    python scripts/hls_lint.py --source F --top NAME [--top NAME...]   lint another file
Exit status 0: clean; 1: violations (listed); 2: the compiler failed.  The call graph is cached
in build/hls/ by a hash of the compiler, flags and every header, so an unchanged tree lints in ~1 s.
"""
from __future__ import annotations

import argparse
import hashlib
import importlib.util
import os
import re
import subprocess
import sys
import tempfile
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CACHE = ROOT / "build" / "hls"
TOPS = ["ts_kin_top", "ts_kin_top_compact", "ts_solve_top", "ts_solve_top_compact", "ts_servo_top",
        "ts_servo_top_compact"]
ALLOWED_EXTERNAL = {"memcpy", "memset", "memmove"}
DYNAMIC = re.compile(r"^(_Znw|_Zna|_Zdl|_Zda|malloc$|calloc$|realloc$|free$|aligned_alloc$|posix_memalign$)")
MATH = {"sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sqrt", "exp", "log", "log2", "log10", "pow",
        "ldexp", "frexp", "floor", "ceil", "round", "fmod", "hypot", "sinf", "cosf", "sqrtf", "fabs", "cbrt"}
# Loop bounds accepted as compile-time constants: literals, ALL_CAPS names, one-letter template
# parameters (M, N, W, ...), qualified constants (Fmt::SWEEPS_MAX, CONFIG_T::nmax), arithmetic.
CONST_BOUND = re.compile(r"^[\sA-Z0-9_+\-*/()<>]*$|^[\w\s]*::\s*\w+[\s+\-*/0-9()]*$")


def ap_types_dir() -> str:
    spec = importlib.util.find_spec("hls4ml")
    if spec is None or not spec.submodule_search_locations:
        sys.exit("hls_lint: the hls4ml package (Xilinx ap_types headers) is not installed")
    return os.path.join(spec.submodule_search_locations[0], "templates", "vivado", "ap_types")


def parse_ci(path: Path):
    nodes: dict[str, tuple[str, str, bool]] = {}  # title -> (name, location, external)
    edges: dict[str, list[tuple[str, str]]] = defaultdict(list)  # source -> [(target, call site)]
    node_re = re.compile(r'^node: \{ title: "([^"]*)" label: "(.*?)\\n(.*?)"( shape : ellipse)? \}$')
    node_plain = re.compile(r'^node: \{ title: "([^"]*)" label: "([^"]*)"( shape : ellipse)? \}$')
    edge_re = re.compile(r'^edge: \{ sourcename: "([^"]*)" targetname: "([^"]*)"(?: label: "([^"]*)")? \}$')
    for line in path.read_text().splitlines():
        m = node_re.match(line)
        if m:
            nodes[m.group(1)] = (m.group(2), m.group(3), bool(m.group(4)))
            continue
        m = node_plain.match(line)
        if m:
            nodes[m.group(1)] = (m.group(2), "", bool(m.group(3)))
            continue
        m = edge_re.match(line)
        if m:
            edges[m.group(1)].append((m.group(2), m.group(3) or ""))
    return nodes, edges


def resolve(title: str, nodes: dict) -> str:
    """Complete-object constructors/destructors (C1/D1) alias the base-object ones (C2/D2)."""
    if title in nodes:
        return title
    for a, b in (("C1E", "C2E"), ("D1E", "D2E"), ("C1I", "C2I"), ("D0E", "D2E")):
        t = title.replace(a, b)
        if t in nodes:
            return t
    return title


def external_name(title: str) -> str:
    return title.split(":")[-1]


def strip_comments(src: str) -> str:
    src = re.sub(r"/\*.*?\*/", lambda m: "\n" * m.group(0).count("\n"), src, flags=re.S)
    src = re.sub(r"//[^\n]*", "", src)
    return re.sub(r'"(?:\\.|[^"\\])*"', '""', src)


def function_body(path: Path, line: int, col: int, cache: dict) -> tuple[str, int] | None:
    """The text of the function defined at path:line:col (from its first '{' to the match)."""
    if path not in cache:
        try:
            cache[path] = strip_comments(path.read_text()).splitlines(keepends=True)
        except OSError:
            cache[path] = None
    lines = cache[path]
    if lines is None or line > len(lines):
        return None
    text = "".join(lines[line - 1:])
    start = text.find("{", max(col - 1, 0))
    semi = text.find(";", max(col - 1, 0))
    if start < 0 or (0 <= semi < start and "(" not in text[:semi]):
        return None
    depth = 0
    for i in range(start, len(text)):
        if text[i] == "{":
            depth += 1
        elif text[i] == "}":
            depth -= 1
            if depth == 0:
                return text[start:i + 1], line
    return None


STATS = {"functions": 0, "loops": 0}


def loop_violations(body: str, first_line: int, where: str) -> list[tuple[str, str]]:
    out = []
    STATS["functions"] += 1
    STATS["loops"] += len(re.findall(r"\b(for|while|do)\b", body))
    for m in re.finditer(r"\b(while|do)\b", body):
        ln = first_line + body[:m.start()].count("\n")
        out.append(("loop-bound", f"{where}:{ln}: '{m.group(1)}' loop (use a for loop to a compile-time bound)"))
    for m in re.finditer(r"\bfor\s*\(([^;]*);([^;]*);", body):
        cond = m.group(2).strip()
        ln = first_line + body[:m.start()].count("\n")
        cm = re.match(r"^\w+\s*(<=|<|>=|>|!=)\s*(.+)$", cond)
        if not cm or not CONST_BOUND.match(cm.group(2).strip()):
            out.append(("loop-bound", f"{where}:{ln}: loop bound '{cond}' is not a compile-time constant"))
    return out


SOURCE_TOKENS = [
    (r"\bnew\b", "new"), (r"\bdelete\b", "delete"), (r"\bmalloc\s*\(", "malloc"), (r"\bfree\s*\(", "free"),
    (r"\bstd::vector\b", "std::vector"), (r"\bstd::string\b", "std::string"), (r"\bstd::map\b", "std::map"),
    (r"\bvirtual\b", "virtual"), (r"\bthrow\b", "throw"), (r"\btry\b", "try"),
    (r"\bstd::(sin|cos|tan|sqrt|atan2|acos|asin|exp|log|pow)\b", "std:: math function"),
]


def source_violations(files: list[Path]) -> list[tuple[str, str]]:
    out = []
    for f in files:
        text = strip_comments(f.read_text())
        for pat, what in SOURCE_TOKENS:
            for m in re.finditer(pat, text):
                ln = text[:m.start()].count("\n") + 1
                out.append(("source-token", f"{f.relative_to(ROOT) if f.is_relative_to(ROOT) else f}:{ln}: {what}"))
    return out


def lint(source: Path, tops: list[str], include_dirs: list[Path], extra_sources: list[Path],
         cxx: str = "g++", defines: list[str] | None = None) -> list[tuple[str, str]]:
    ap = ap_types_dir()
    flags = ["-std=c++17", "-O0", "-fno-exceptions", "-fcallgraph-info", "-w", "-isystem", ap] + \
        [f"-I{d}" for d in include_dirs] + [f"-D{d}" for d in (defines or [])]
    # The call graph is cached by a hash of the compiler, flags and every project source.
    h = hashlib.sha256(" ".join([cxx, str(source)] + flags).encode())
    for f in sorted({source, *(p for d in include_dirs for p in Path(d).rglob("*") if p.suffix in (".h", ".hpp"))}):
        h.update(str(f).encode() + f.read_bytes())
    cached = CACHE / f"lint_{source.stem}_{h.hexdigest()[:16]}.ci"
    if not cached.exists():
        with tempfile.TemporaryDirectory() as tmp:
            obj = Path(tmp) / "lint.o"
            r = subprocess.run([cxx, *flags, "-c", str(source), "-o", str(obj)], capture_output=True, text=True)
            if r.returncode != 0:
                sys.stderr.write(r.stderr)
                raise SystemExit(2)
            CACHE.mkdir(parents=True, exist_ok=True)
            for old in CACHE.glob(f"lint_{source.stem}_*.ci"):
                old.unlink(missing_ok=True)
            os.replace(Path(tmp) / "lint.ci", cached)
    nodes, edges = parse_ci(cached)

    project = [str(ROOT / "hls"), str(ROOT / "model" / "include"), str(source.parent)] + [str(d) for d in include_dirs]
    ap_dir = os.path.realpath(ap)

    def loc_file(loc: str) -> str:
        f = loc.rsplit(":", 2)[0] if loc.count(":") >= 2 else loc
        return os.path.realpath(f) if f and not f.startswith("<") else f

    def is_library(title: str) -> bool:
        name, loc, ext = nodes.get(title, ("", "", True))
        return loc_file(loc).startswith(ap_dir)

    def is_project(title: str) -> bool:
        name, loc, ext = nodes.get(title, ("", "", True))
        f = loc_file(loc)
        return not ext and any(f.startswith(os.path.realpath(p)) for p in project)

    roots = [t for t, (name, loc, ext) in nodes.items() if not ext and re.match(r"^\S.*?\b(" + "|".join(map(re.escape, tops)) + r")\(", name)]
    found = {re.search(r"\b(" + "|".join(map(re.escape, tops)) + r")\(", nodes[t][0]).group(1) for t in roots}
    violations: list[tuple[str, str]] = []
    for t in tops:
        if t not in found:
            violations.append(("missing-top", f"top function {t} not defined in {source}"))

    # Reachability: project functions are entered; everything they call is classified, and
    # nothing outside the project is entered (ap_types / hls_stream are Vitis' own library).
    seen: set[str] = set()
    order = list(roots)
    callees: dict[str, str] = {}  # non-project callee -> first project caller
    while order:
        t = order.pop()
        if t in seen:
            continue
        seen.add(t)
        for tgt, _site in edges.get(t, []):
            r = resolve(tgt, nodes)
            if is_project(r):
                order.append(r)
            else:
                callees.setdefault(r, t)

    for t, caller in sorted(callees.items()):
        name, loc, ext = nodes.get(t, (external_name(t), "", True))
        via = nodes[caller][0]
        if is_library(t):
            continue
        ename = external_name(t)
        if ext or t not in nodes:
            if ename in ALLOWED_EXTERNAL:
                continue
            if DYNAMIC.match(ename):
                violations.append(("dynamic-memory", f"{name} called from {via}"))
            elif ename.startswith("__cxa_guard"):
                violations.append(("runtime-static", f"static initialised at run time in {via} ({loc})"))
            elif ename == "__indirect_call":
                violations.append(("indirect-call", f"call through a pointer / virtual function in {via}"))
            elif ename in MATH or ename.rstrip("f") in MATH:
                violations.append(("math-library", f"{name} called from {via}"))
            else:
                violations.append(("external-call", f"{name} called from {via}"))
        elif re.search(r"\bstd::(" + "|".join(sorted(MATH)) + r")\b", name):
            violations.append(("math-library", f"{name} called from {via}"))
        else:
            violations.append(("std-library", f"{name} ({loc}) called from {via}"))

    # Namespace-scope initialisers that run project code.
    for t, (name, loc, ext) in nodes.items():
        if "static_initialization" in t or t.startswith("_GLOBAL__sub_I") or "static_initialization" in name:
            for tgt, site in edges.get(t, []):
                tr = resolve(tgt, nodes)
                if is_project(tr) or any(site.startswith(p) for p in project):
                    violations.append(("runtime-static", f"namespace-scope initialiser runs {nodes.get(tr, (tgt,))[0]} ({site})"))

    # Recursion: a cycle among reachable project functions.
    proj = {t for t in seen if is_project(t)}
    graph = {t: {resolve(x, nodes) for x, _ in edges.get(t, [])} & proj for t in proj}
    color: dict[str, int] = {}
    for start in proj:
        if start in color:
            continue
        stack = [(start, iter(graph[start]))]
        color[start] = 1
        while stack:
            node, it = stack[-1]
            nxt = next(it, None)
            if nxt is None:
                color[node] = 2
                stack.pop()
            elif color.get(nxt) == 1:
                violations.append(("recursion", f"{nodes[nxt][0]} is reached again from {nodes[node][0]}"))
            elif nxt not in color:
                color[nxt] = 1
                stack.append((nxt, iter(graph[nxt])))

    # Loop bounds in the bodies of reachable project functions.
    cache: dict = {}
    checked: set[tuple[str, int]] = set()
    for t in sorted(proj):
        name, loc, _ = nodes[t]
        m = re.match(r"^(.*):(\d+):(\d+)$", loc)
        if not m:
            continue
        key = (m.group(1), int(m.group(2)))
        if key in checked:
            continue
        checked.add(key)
        path = Path(m.group(1))
        fb = function_body(path if path.is_absolute() else ROOT / path, int(m.group(2)), int(m.group(3)), cache)
        if fb:
            rel = os.path.relpath(os.path.realpath(path if path.is_absolute() else ROOT / path), ROOT)
            violations += loop_violations(fb[0], fb[1], rel)

    violations += source_violations(extra_sources)
    # de-duplicate, keep order
    out, seen_v = [], set()
    for v in violations:
        if v not in seen_v:
            seen_v.add(v)
            out.append(v)
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--source", type=Path, default=ROOT / "hls" / "ts_servo_top.cpp")
    ap.add_argument("--top", action="append", help="top function name (repeatable)")
    ap.add_argument("-D", dest="defines", action="append", default=[], help="preprocessor definition")
    args = ap.parse_args(argv)
    tops = args.top or TOPS
    default = args.source.resolve() == (ROOT / "hls" / "ts_servo_top.cpp").resolve()
    extra = sorted((ROOT / "hls").glob("ts_*.h")) + sorted((ROOT / "hls").glob("ts_*.cpp")) if default else [args.source]
    v = lint(args.source.resolve(), tops, [ROOT / "model" / "include", ROOT / "hls"], extra,
             os.environ.get("CXX", "g++"), args.defines)
    kinds = sorted({k for k, _ in v})
    for k, msg in v:
        print(f"{k}: {msg}")
    if v:
        print(f"hls_lint: {len(v)} violation(s) ({', '.join(kinds)})")
        return 1
    print(f"hls_lint: clean ({', '.join(tops)}; {STATS['functions']} project functions reachable, "
          f"{STATS['loops']} loops checked)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
