"""scripts/lint_rtl.sh: every RTL module, with every parameter set it is used with, is clean under
verilator --lint-only -Wall and iverilog -g2005 -Wall."""
import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("shard", [0, 1])
def test_lint_rtl(shard):
    """Half of the jobs each (every other job), so that the two halves can run side by side."""
    p = subprocess.run(["bash", str(ROOT / "scripts" / "lint_rtl.sh"), "-j", "1", "-s", f"{shard}/2"], cwd=ROOT,
                       capture_output=True, text=True, timeout=900)
    assert p.returncode == 0, p.stdout[-6000:] + p.stderr[-2000:]
    m = re.search(r"lint_rtl\.sh: (\d+) jobs clean .*shard (\d) of 2, (\d+) jobs in all", p.stdout)
    assert m, p.stdout[-2000:]
    n, k, total = map(int, m.groups())
    assert k == shard and n == len(range(shard, total, 2)) and total > 100


@pytest.mark.parametrize("args,field", [(["-s", "2/2"], "-s K/M"), (["-s", "a/b"], "-s K/M"), (["-s", "0/0"], "-s K/M"),
                                        (["-j", "0"], "-j N"), (["--fast"], "--fast")])
def test_lint_rtl_bad_arguments(args, field):
    """A shard that would select no job, a zero job count or an unknown option: one line naming it, exit 2."""
    p = subprocess.run(["bash", str(ROOT / "scripts" / "lint_rtl.sh"), *args], cwd=ROOT, capture_output=True,
                       text=True, timeout=60)
    assert p.returncode == 2 and p.stdout == ""
    assert len(p.stderr.strip().splitlines()) == 1 and field in p.stderr, p.stderr


def _process_bodies(text: str) -> list[str]:
    """The bodies of a Verilog file's `always` processes (comments stripped; a body is the statement
    after the event control, `begin ... end` matched by nesting)."""
    text = re.sub(r"/\*.*?\*/", " ", re.sub(r"//[^\n]*", "", text), flags=re.S)
    bodies = []
    for m in re.finditer(r"\balways\b\s*(@\s*(\*|\([^)]*\)))?", text):
        rest = text[m.end():]
        b = re.match(r"\s*begin\b", rest)
        if not b:
            bodies.append(rest.split(";", 1)[0])
            continue
        depth, pos = 0, 0
        for t in re.finditer(r"\b(begin|end)\b", rest):
            depth += 1 if t.group(1) == "begin" else -1
            if depth == 0:
                pos = t.end()
                break
        assert pos, f"unbalanced begin/end after `always` at offset {m.start()}"
        bodies.append(rest[:pos])
    return bodies


def test_rtl_loop_variables_one_process():
    """No module-level `integer` is a loop variable of two processes: each such variable is a
    register of every process that assigns it, so sharing one gives a register with two drivers
    (yosys 0.70: "multiple conflicting drivers"; a dead one, but not a clean netlist)."""
    shared = []
    for f in sorted((ROOT / "rtl").glob("*.v")):
        text = f.read_text()
        ints = {v.strip() for d in re.findall(r"\binteger\s+([\w\s,]+);", text) for v in d.split(",")}
        bodies = _process_bodies(text)
        assert bodies or "always" not in text, f
        for v in sorted(ints):
            n = sum(bool(re.search(rf"\bfor\s*\(\s*{v}\s*=", b)) for b in bodies)
            if n > 1:
                shared.append(f"{f.name}: `{v}` in {n} processes")
    assert not shared, shared
