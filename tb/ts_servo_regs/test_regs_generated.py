"""The register map's generated artefacts (scripts/gen_regs.py from rtl/ts_servo_regs.rdl): committed
files up to date, the map as specified in the issue, flags and formats as the model's, the C header
consistent with the Python module, the generator's checks firing on bad input, the Verilog lint-clean
and its parameter check working.
"""
from __future__ import annotations

import importlib.util
import math
import re
import shutil
import subprocess
import sys

import pytest

from tensor_servo import regs

import tsbench

ROOT = tsbench.ROOT
RDL = ROOT / "rtl" / "ts_servo_regs.rdl"
VFILE = ROOT / "rtl" / "ts_servo_regs.v"
#: the joint read multiplexer the register block instantiates
SEL = ROOT / "rtl" / "ts_sel.v"
HEADER = ROOT / "rtl" / "generated" / "ts_servo_regs.h"


def _gen():
    spec = importlib.util.spec_from_file_location("gen_regs", ROOT / "scripts" / "gen_regs.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules["gen_regs"] = mod
    spec.loader.exec_module(mod)
    return mod


gen = _gen()


def test_generated_files_up_to_date():
    problems = gen.check()
    assert not problems, "run python scripts/gen_regs.py:\n" + "\n".join(problems)


# The map of the issue, written out independently of the RDL.
ISSUE_GLOBAL = {
    "CTRL": (0x000, {"RUN": (0, 1), "COMMIT": (1, 1), "CLEAR": (2, 1), "VIRTUAL": (3, 1)}),
    "STATUS": (0x004, {"BUSY": (0, 1), "CFG_OK": (1, 1), "CFG_ERR": (2, 1), "CFG_BUSY": (3, 1)}),
    "CFG_ERROR": (0x008, {"CODE": (0, 8), "JOINT": (8, 8)}),
    "FLAGS": (0x00C, {"OVF_ANGLE": (0, 1), "OVF_TURN": (1, 1), "OVF_TRIG": (2, 1), "OVF_QUAT": (3, 1),
                      "OVF_POS": (4, 1), "OVF_LEVER": (5, 1), "OVF_JAC": (6, 1), "OVF_CONST": (7, 1),
                      "OVF_SOLVER": (8, 1), "OVF_SERVO": (9, 1), "LIMIT_ACTIVE": (16, 1), "VLIMIT_ACTIVE": (17, 1)}),
    "TICK_COUNT": (0x010, None), "TICK_CYCLES": (0x014, None), "ID": (0x018, None),
    "HWCFG": (0x01C, {"NMAX": (0, 8), "CONFIG": (8, 4), "VERSION": (16, 16)}),
    "NJOINTS": (0x020, None),
    "MODE": (0x024, {"ERR_B": (0, 1), "ERROR_ONLY": (1, 1), "SWEEPS": (8, 8), "WARM_LEAK": (16, 4)}),
    "KP": (0x028, "gain_t"), "KO": (0x02C, "gain_t"), "LCHAR": (0x030, "lchar_t"), "KLIM": (0x034, "klim_t"),
    "DT": (0x038, "dt_t"),
    **{f"{b}_Q{c}": (base + 4 * i, "quat_t") for b, base in (("BASE", 0x40), ("TOOL", 0x60)) for i, c in enumerate("WXYZ")},
    **{f"{b}_P{c}": (base + 0x10 + 4 * i, "len_t") for b, base in (("BASE", 0x40), ("TOOL", 0x60)) for i, c in enumerate("XYZ")},
}
ISSUE_JOINT = {
    "JCFG": (0x00, {"PRISMATIC": (0, 1), "LIMITED": (1, 1), "VLIMITED": (2, 1)}),
    **{f"ORIGIN_Q{c}": (0x04 + 4 * i, "quat_t") for i, c in enumerate("WXYZ")},
    **{f"ORIGIN_P{c}": (0x14 + 4 * i, "len_t") for i, c in enumerate("XYZ")},
    **{f"AXIS_{c}": (0x20 + 4 * i, "quat_t") for i, c in enumerate("XYZ")},
    "SCALE": (0x2C, "scale_t"), "LOWER": (0x30, "angle_t"), "UPPER": (0x34, "angle_t"), "VMAX": (0x38, "qd_t"),
    "MU": (0x3C, "mu_t"),
}


@pytest.mark.parametrize("block", ["global", "joint"])
def test_map_matches_issue(block):
    want, got = (ISSUE_GLOBAL, regs.GLOBAL) if block == "global" else (ISSUE_JOINT, regs.JOINT)
    assert set(got) == set(want)
    for name, (off, spec) in want.items():
        r = got[name]
        assert r.offset == off, name
        if isinstance(spec, dict):
            assert {f.name: (f.lsb, f.width) for f in r.fields} == spec, name
        elif isinstance(spec, str):
            assert [(f.name, f.lsb, f.width, f.fmt, f.access) for f in r.fields] == [("VALUE", 0, 32, spec, "rw")], name
    assert regs.joint_addr(0, "JCFG") == 0x100 and regs.joint_addr(3, "MU") == 0x100 + 0xC0 + 0x3C


def test_access_kinds():
    kinds = {(r.name, f.name): f.access for r in regs.GLOBAL.values() for f in r.fields}
    assert kinds[("CTRL", "RUN")] == kinds[("CTRL", "VIRTUAL")] == "rw"
    assert kinds[("CTRL", "COMMIT")] == kinds[("CTRL", "CLEAR")] == "strobe"
    assert all(kinds[("FLAGS", f.name)] == "rw1c" for f in regs.GLOBAL["FLAGS"].fields)
    assert {r.name for r in regs.GLOBAL.values() if not r.writable} == {
        "STATUS", "CFG_ERROR", "TICK_COUNT", "TICK_CYCLES", "ID", "HWCFG"}
    assert regs.GLOBAL["ID"].fields[0].reset["default"] == 0x54535256
    assert all(f.access == "rw" for r in regs.JOINT.values() for f in r.fields)


def test_flags_are_the_model_status_bits():
    from tensor_servo.model import STATUS_BITS
    flags = {f.name: 1 << f.lsb for f in regs.GLOBAL["FLAGS"].fields}
    assert flags == {k.upper(): v for k, v in STATUS_BITS.items()}
    # and the C++ enum itself
    src = (ROOT / "model" / "include" / "tensor_servo" / "fixed.hpp").read_text()
    enum = {m.group(1): 1 << int(m.group(2)) for m in re.finditer(r"ST_(\w+)\s*=\s*1u\s*<<\s*(\d+)", src)}
    assert flags == enum


def test_config_error_codes_documented():
    """CFG_ERROR.CODE lists the model's ConfigError values (chain.hpp)."""
    src = (ROOT / "model" / "include" / "tensor_servo" / "chain.hpp").read_text()
    body = src[src.index("enum ConfigError"):]
    body = body[:body.index("};")]
    codes = [int(v) for v in re.findall(r"CFG_\w+\s*=\s*(\d+)", body)]
    rdl = " ".join(RDL.read_text().split())
    desc = rdl[rdl.index("ConfigError of the model"):][:300]
    assert codes == list(range(len(codes)))
    for c in codes[1:]:
        assert re.search(rf"\b{c} [a-z]", desc), f"CFG_ERROR.CODE desc misses code {c}"


def test_formats_are_the_models():
    from tensor_servo import _model
    for cfg in regs.CONFIGS:
        f = dict(_model.formats(cfg))
        for name, wi in regs.FORMATS[cfg].items():
            assert tuple(f[name]) == wi, (cfg, name)


#: the real values the non-zero fixed-point resets stand for (issue + docs/solver.md safe defaults)
RESET_REALS = {"KP": 300, "KO": 300, "LCHAR": 0.5, "KLIM": 500, "DT": 1e-3, "BASE_QW": 1, "TOOL_QW": 1,
               "ORIGIN_QW": 1, "AXIS_Z": 1, "SCALE": 1, "MU": 1.5}


def test_fixed_point_resets():
    for r in list(regs.GLOBAL.values()) + list(regs.JOINT.values()):
        f = r.fields[0]
        if f.fmt is None:
            continue
        for cfg in regs.CONFIGS:
            w, i = regs.FORMATS[cfg][f.fmt]
            real = regs.decode(f.reset[cfg], cfg, f.fmt)
            want = RESET_REALS.get(r.name, 0.0)
            assert abs(real - want) <= math.ldexp(0.5, i - w), (r.name, cfg, real, want)
            assert regs.stored(f.reset[cfg], cfg, f.fmt) == f.reset[cfg], (r.name, cfg)
    assert regs.encode(1.5, "default", "mu_t") == 0x18000
    assert regs.decode(regs.encode(-0.25, "compact", "quat_t"), "compact", "quat_t") == -0.25
    with pytest.raises(ValueError):
        regs.encode(4.0, "default", "quat_t")


def test_c_header_matches_python(tmp_path):
    """Compile a program against the PeakRDL header that prints every register's offset and every
    field's position; compare with tensor_servo.regs."""
    cc = shutil.which("gcc") or shutil.which("cc")
    assert cc, "a C compiler is needed"
    lines = ['#include <stdio.h>', '#include <stddef.h>', '#include "ts_servo_regs.h"', "int main(void) {"]
    for r in regs.GLOBAL.values():
        lines.append(f'  printf("G {r.name} %zu\\n", offsetof(ts_servo_regs_t, {r.name}));')
    for r in regs.JOINT.values():
        lines.append(f'  printf("J {r.name} %zu\\n", offsetof(ts_servo_regs_t, JOINT[1].{r.name}) - 0x{regs.JOINT_BASE + regs.JOINT_STRIDE:X});')
    for blk, rs in (("", regs.GLOBAL), ("JOINTX__", regs.JOINT)):
        for r in rs.values():
            for f in r.fields:
                m = f"TS_SERVO_REGS__{blk}{r.name}__{f.name}"
                lines.append(f'  printf("F {blk}{r.name}.{f.name} %d %d\\n", (int){m}_bp, (int){m}_bw);')
    lines += ["  return 0;", "}"]
    (tmp_path / "t.c").write_text("\n".join(lines) + "\n")
    subprocess.run([cc, "-std=c11", "-Wall", "-Werror", f"-I{HEADER.parent}", "-o", str(tmp_path / "t"),
                    str(tmp_path / "t.c")], check=True)
    out = subprocess.run([str(tmp_path / "t")], check=True, capture_output=True, text=True).stdout.split("\n")
    got = [ln.split() for ln in out if ln]
    for kind, name, *vals in got:
        if kind == "G":
            assert int(vals[0]) == regs.GLOBAL[name].offset, name
        elif kind == "J":
            assert int(vals[0]) == regs.JOINT[name].offset, name
        else:
            rn, fn = name.split(".")
            r = regs.JOINT[rn[len("JOINTX__"):]] if rn.startswith("JOINTX__") else regs.GLOBAL[rn]
            assert (r.field(fn).lsb, r.field(fn).width) == tuple(map(int, vals)), name
    assert len(got) == len(regs.GLOBAL) + len(regs.JOINT) + sum(len(r.fields) for r in list(regs.GLOBAL.values()) + list(regs.JOINT.values()))


# The generator refuses maps it cannot implement or that disagree with the model.
BAD_RDL = {
    "reset not the real": ("gain_r #(.RD(1228800), .RC(2400), .REAL(\"300\")) KP", "gain_r #(.RD(1228801), .RC(2400), .REAL(\"300\")) KP",
                           "is not 300"),
    "desc format": ("quat_t: default ap_fixed<27,2>", "quat_t: default ap_fixed<27,3>", "must state the model's format"),
    "access": ("field { sw = rw; hw = r; desc = \"Prismatic joint (0: revolute).\"; }",
               "field { sw = rw; hw = rw; desc = \"Prismatic joint (0: revolute).\"; }", "unsupported access"),
    "array size": ("joint_t JOINT[NMAX] @ 0x100 += 0x40;", "joint_t JOINT[8] @ 0x100 += 0x40;", "sized by the NMAX"),
    "reset too wide": ("quat_r #(.RD(33554432), .RC(65536), .REAL(\"1\")) BASE_QW", "quat_r #(.RD(134217728), .RC(65536), .REAL(\"1\")) BASE_QW",
                       "does not fit"),
}


@pytest.mark.parametrize("case", sorted(BAD_RDL))
def test_generator_rejects(case, tmp_path):
    old, new, msg = BAD_RDL[case]
    src = RDL.read_text()
    assert src.count(old) == 1, f"the test's anchor is stale: {old}"
    bad = tmp_path / "bad.rdl"
    bad.write_text(src.replace(old, new))
    formats = gen.model_formats()
    gen.describe(formats, RDL)  # the real map passes
    with pytest.raises(gen.GenError, match=re.escape(msg)):
        gen.describe(formats, bad)


def test_html_docs(tmp_path):
    assert gen.main(["--html", str(tmp_path / "html")]) == 0
    assert (tmp_path / "html" / "index.html").exists()
    text = "".join(p.read_text(errors="replace") for p in (tmp_path / "html").rglob("*") if p.suffix in (".json", ".html"))
    assert "TICK_CYCLES" in text and "WARM_LEAK" in text


@pytest.mark.parametrize("nmax,config", [(1, 0), (8, 0), (8, 1), (60, 1)])
def test_verilog_lint(nmax, config):
    """verilator --lint-only -Wall clean; Icarus (-g2005) compiles."""
    r = subprocess.run(["verilator", "--lint-only", "-Wall", "--top-module", "ts_servo_regs", f"-GNMAX={nmax}",
                        f"-GCONFIG={config}", str(VFILE), str(SEL)],
                       capture_output=True, text=True)
    assert r.returncode == 0 and not r.stderr.strip(), r.stderr
    r = subprocess.run(["iverilog", "-g2005", "-Wall", "-s", "ts_servo_regs", f"-Pts_servo_regs.NMAX={nmax}",
                        f"-Pts_servo_regs.CONFIG={config}", "-o", "/dev/null", str(VFILE), str(SEL)],
                       capture_output=True, text=True)
    assert r.returncode == 0 and not r.stderr.strip(), r.stderr


@pytest.mark.parametrize("params,ok", [({"NMAX": 60}, True), ({"NMAX": 61}, False), ({"CONFIG": 2}, False),
                                        ({"QUAT_W": 20}, False)])
def test_verilog_parameter_check(params, ok, tmp_path):
    """The module stops the simulation with an ERROR line on parameters outside its range."""
    args = [f"-Pts_servo_regs.{k}={v}" for k, v in params.items()]
    exe = tmp_path / "sim.vvp"
    subprocess.run(["iverilog", "-g2005", "-s", "ts_servo_regs", *args, "-o", str(exe), str(VFILE), str(SEL)], check=True,
                   capture_output=True)
    out = subprocess.run(["vvp", "-n", str(exe)], capture_output=True, text=True, timeout=60).stdout
    assert ("ERROR" in out) != ok, out
