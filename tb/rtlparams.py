"""Verilog parameters of the tensor-servo datapath modules, derived from the model's formats.

The C++ model (``tensor_servo._model.formats(cfg)``) is the single source of every width: this module
turns its ``(W, I)`` pairs (ap_fixed<W, I>, F = W - I) into the parameter sets of the RTL modules and
states each module's latency (the same formula as the module's ``LATENCY`` localparam; the benches
check it cycle by cycle).  Used by the cocotb benches, ``scripts/lint_rtl.sh``, ``scripts/synth.py``
and ``scripts/gen_rtl_data.py``.
"""
from __future__ import annotations

import math
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RTL = ROOT / "rtl"
SIM_MODELS = ROOT / "tb" / "sim"

CONFIGS = ("default", "compact")
TARGETS = ("GENERIC", "ECP5")
#: rotate kinds: (vector, tmp, out) formats, as in model/bindings/module.cpp prim_rotate
ROTATE_KINDS = {
    "axis": ("quat_t", "uvec_tmp_t", "quat_t"),
    "offset": ("len_t", "len_tmp_t", "pos_t"),
    "jw": ("jw_t", "jw_tmp_t", "jw_t"),
    "jv": ("jv_t", "jv_tmp_t", "jv_t"),
}

_FORMATS: dict[str, dict] = {}


def formats(cfg: str) -> dict:
    if cfg not in _FORMATS:
        from tensor_servo import _model
        _FORMATS[cfg] = dict(_model.formats(cfg))
    return _FORMATS[cfg]


def fmt(cfg: str, name: str) -> tuple[int, int]:
    """(W, F) of a model format."""
    w, i = formats(cfg)[name]
    return int(w), int(w - i)


def quantize_const(x: float, cfg: str, name: str) -> int:
    """Raw value of a constant exactly as fx<W,I>::from_double (floor(x 2^F + 1/2), then AP_SAT)."""
    w, f = fmt(cfg, name)
    r = math.floor(math.ldexp(x, f) + 0.5)
    return max(-(1 << (w - 1)), min((1 << (w - 1)) - 1, r))


def reset_joint(cfg: str) -> dict:
    """A joint block of the core's register map at its reset values (rtl/ts_servo_regs.rdl)."""
    one = quantize_const(1.0, cfg, "quat_t")
    return {"jcfg": 0, "qo": [one, 0, 0, 0], "po": [0, 0, 0], "axis": [0, 0, one],
            "scale": quantize_const(1.0, cfg, "scale_t"), "lower": 0, "upper": 0, "vmax": 0,
            "mu": quantize_const(1.5, cfg, "mu_t")}


def core_raw(chain, cfg: str, nmax: int, servo: dict, mode: int = 0, sweeps: int = 10, leak: int = 5) -> dict:
    """The register words software writes for a chain (every value rounded to its format, mu 1.5),
    the servo words ``servo`` (key -> (format, value)), ``nmax`` joint blocks (unused ones at reset).
    The words the core benches commit (tb/ts_core_commit, tb/ts_servo_core)."""
    qv = lambda v: [quantize_const(float(x), cfg, "quat_t") for x in v]  # noqa: E731
    lv = lambda v: [quantize_const(float(x), cfg, "len_t") for x in v]  # noqa: E731
    raw = {"n": chain.n, "mode": mode, "sweeps": sweeps, "warm_leak": leak,
           "base_q": qv(chain.base.quat_wxyz), "base_p": lv(chain.base.xyz),
           "tool_q": qv(chain.tool.quat_wxyz), "tool_p": lv(chain.tool.xyz), "joints": []}
    for k, (f, x) in servo.items():
        raw[k] = quantize_const(x, cfg, f)
    for j in chain.joints:
        lim = j.limits
        jcfg = (1 if j.prismatic else 0) | (2 if lim.bounded else 0) | (4 if lim.velocity is not None else 0)
        raw["joints"].append({
            "jcfg": jcfg, "qo": qv(j.origin.quat_wxyz), "po": lv(j.origin.xyz), "axis": qv(j.axis),
            "scale": quantize_const(j.scale, cfg, "scale_t"),
            "lower": quantize_const(lim.lower, cfg, "angle_t") if lim.bounded else 0,
            "upper": quantize_const(lim.upper, cfg, "angle_t") if lim.bounded else 0,
            "vmax": quantize_const(lim.velocity, cfg, "qd_t") if lim.velocity is not None else 0,
            "mu": quantize_const(1.5, cfg, "mu_t")})
    while len(raw["joints"]) < nmax:
        raw["joints"].append(reset_joint(cfg))
    return raw


def mul_lat(aw: int, bw: int) -> int:
    """ts_mul latency (rtl/ts_common.vh ts_mul_lat)."""
    return 3 + (aw > 18 or bw > 18) + (aw > 18) + (bw > 18)


#: ts_round_sat latency (rtl/ts_common.vh ts_round_lat)
ROUND_LAT = 2


def vstr(s: str) -> str:
    """A Verilog string parameter value for -G / -P / chparam."""
    return '"' + s + '"'


# ---- per-module parameter sets ------------------------------------------------------------------
def quat_mul(cfg: str, target: str = "GENERIC") -> dict:
    qw, qf = fmt(cfg, "quat_t")
    return {"Q_W": qw, "Q_F": qf, "TARGET": target}


def quat_rotate(cfg: str, kind: str = "axis", inverse: bool = False, target: str = "GENERIC") -> dict:
    vn, tn, on = ROTATE_KINDS[kind]
    qw, qf = fmt(cfg, "quat_t")
    vw, vf = fmt(cfg, vn)
    tw, tf = fmt(cfg, tn)
    ow, of = fmt(cfg, on)
    return {"Q_W": qw, "Q_F": qf, "V_W": vw, "V_F": vf, "T_W": tw, "T_F": tf, "O_W": ow, "O_F": of,
            "INV": int(bool(inverse)), "TARGET": target}


def rom_file(cfg: str) -> Path:
    return RTL / f"ts_trig_rom_{cfg}.mem"


def sincos(cfg: str, target: str = "GENERIC", rom_path: str | None = None) -> dict:
    fm = formats(cfg)
    uw, _ = fmt(cfg, "turn_t")
    p = {"U_W": uw, "T_BITS": int(fm["TRIG_TABLE_BITS"])}
    for key, name in (("TAB", "tab_t"), ("DELTA", "delta_t"), ("DSQ", "dsq_t"), ("ACC", "trig_acc_t"),
                      ("Q", "quat_t"), ("TWOPI", "twopi_t"), ("SIXTH", "sixth_t")):
        w, f = fmt(cfg, name)
        p[f"{key}_W"], p[f"{key}_F"] = w, f
    p["TWOPI"] = quantize_const(2.0 * math.pi, cfg, "twopi_t")
    p["SIXTH"] = quantize_const(1.0 / 6.0, cfg, "sixth_t")
    p["ROM_FILE"] = rom_path if rom_path is not None else rom_file(cfg).name
    p["TARGET"] = target
    return p


def joint_quat(cfg: str, target: str = "GENERIC", rom_path: str | None = None) -> dict:
    aw, af = fmt(cfg, "angle_t")
    kw, kf = fmt(cfg, "kturn_t")
    p = {"ANG_W": aw, "ANG_F": af, "KT_W": kw, "KT_F": kf}
    p.update(sincos(cfg, target, rom_path))
    return p


def screw_transport(cfg: str, target: str = "GENERIC") -> dict:
    p = {}
    for key, name in (("Q", "quat_t"), ("UT", "uvec_tmp_t"), ("S", "scale_t"), ("P", "pos_t"),
                      ("L", "lever_t"), ("JW", "jw_t"), ("JV", "jv_t")):
        w, f = fmt(cfg, name)
        p[f"{key}_W"], p[f"{key}_F"] = w, f
    p["TARGET"] = target
    return p


# ---- latencies (documented; the benches check them) -------------------------------------------------
def bank_lat(aw: int, bw: int, fold: int = 1) -> int:
    """Latency of ts_mul_bank (rtl/ts_common.vh ts_bank_lat)."""
    return mul_lat(aw, bw) + fold - 1


def latency(module: str, p: dict) -> int:
    """Latency of a datapath module for its parameters (FOLD, when given, as the module uses it)."""
    rl = ROUND_LAT
    f = p.get("FOLD", 1)
    if module == "ts_quat_mul":
        return bank_lat(p["Q_W"], p["Q_W"], f) + 2 + rl
    if module == "ts_quat_rotate":
        return bank_lat(p["Q_W"], p["V_W"], f) + bank_lat(p["Q_W"], p["T_W"], f) + 3 + 2 * rl   # ts_rotate_lat
    if module == "ts_sincos":
        return sincos_stages(p)["LATENCY"]
    if module == "ts_joint_quat":
        return (mul_lat(p["ANG_W"], p["KT_W"]) + rl + latency("ts_sincos", p)
                + mul_lat(p["Q_W"], p["Q_W"]) + rl)
    if module == "ts_screw_transport":
        lr = latency("ts_quat_rotate", {"Q_W": p["Q_W"], "V_W": p["Q_W"], "T_W": p["UT_W"], "FOLD": f})
        cw = lr + bank_lat(p["S_W"], p["Q_W"], f) + rl
        return cw + bank_lat(p["JW_W"], p["L_W"], f) + 1 + rl + 1
    raise KeyError(module)


def sincos_stages(p: dict) -> dict:
    """Cycle at which each ts_sincos signal is available (input u at cycle 0)."""
    rl = ROUND_LAT
    r = p["U_W"] - 2 - p["T_BITS"]
    c = {}
    c["d"] = mul_lat(r + 1, p["TWOPI_W"]) + rl
    c["d2"] = c["d"] + mul_lat(p["DELTA_W"], p["DELTA_W"]) + rl
    c["e"] = c["d2"] + mul_lat(p["DSQ_W"], p["SIXTH_W"]) + rl
    c["de"] = c["e"] + mul_lat(p["DELTA_W"], p["DSQ_W"]) + rl
    c["sd"] = c["de"] + rl
    c["acc"] = c["sd"] + max(mul_lat(p["TAB_W"], p["DSQ_W"]), mul_lat(p["TAB_W"], p["DELTA_W"])) + rl
    c["sc"] = c["acc"] + 2 + rl
    c["LATENCY"] = c["sc"] + 2
    return c


# ---- sources -----------------------------------------------------------------------------------------
DEPS = {
    "ts_resize": [],
    "ts_delay": [],
    "ts_round_sat": [],
    "ts_ecp5_mult18": [],
    "ts_sel": [],
    "ts_clamp": [],
    "ts_ram": [],
    "ts_mul": ["ts_resize", "ts_delay", "ts_ecp5_mult18"],
    "ts_mul_bank": ["ts_mul", "ts_sel", "ts_delay"],
    "ts_quat_mul": ["ts_mul_bank", "ts_mul", "ts_resize", "ts_delay", "ts_round_sat"],
    "ts_quat_rotate": ["ts_mul_bank", "ts_mul", "ts_resize", "ts_delay", "ts_round_sat"],
    "ts_sincos": ["ts_mul", "ts_resize", "ts_delay", "ts_round_sat", "ts_sel"],
    "ts_joint_quat": ["ts_sincos", "ts_mul", "ts_resize", "ts_delay", "ts_round_sat"],
    "ts_screw_transport": ["ts_quat_rotate", "ts_mul_bank", "ts_mul", "ts_resize", "ts_delay", "ts_round_sat"],
}
DEPS["ts_core_fk"] = ["ts_joint_quat", "ts_sincos", "ts_quat_mul", "ts_quat_rotate", "ts_screw_transport", "ts_mul",
                      "ts_resize", "ts_delay", "ts_round_sat", "ts_ram"]
DEPS["ts_core_commit"] = ["ts_mul", "ts_resize", "ts_delay", "ts_ecp5_mult18", "ts_sel"]
DEPS["ts_core_solve"] = ["ts_mul", "ts_resize", "ts_delay", "ts_round_sat", "ts_ecp5_mult18", "ts_ram", "ts_clamp"]
DEPS["ts_core_law"] = ["ts_quat_mul", "ts_quat_rotate", "ts_mul_bank", "ts_mul", "ts_resize", "ts_delay", "ts_round_sat"]
DEPS["ts_servo_core"] = ["ts_servo_regs", "ts_core_commit", "ts_core_fk", "ts_core_law", "ts_core_solve", "ts_sel"]
DEPS["ts_servo_regs"] = ["ts_sel"]
#: the datapath modules (documented, synthesised); the others are shared pieces
PRIMITIVES = ("ts_quat_mul", "ts_quat_rotate", "ts_sincos", "ts_joint_quat", "ts_screw_transport")
SHARED = ("ts_round_sat", "ts_mul", "ts_delay", "ts_resize")


def sources(module: str, target: str = "GENERIC", sim_models: bool = True) -> list[str]:
    """Verilog files of a module and everything it instantiates (closure of DEPS)."""
    seen: list[str] = []

    def add(m: str) -> None:
        if m in seen:
            return
        seen.append(m)
        for d in DEPS[m]:
            add(d)

    add(module)
    files = [str(RTL / f"{m}.v") for m in seen]
    if target == "ECP5" and "ts_ecp5_mult18" in seen and sim_models:
        files.append(str(SIM_MODELS / "MULT18X18D.v"))
    return files


def module_params(module: str, cfg: str, target: str = "GENERIC", **kw) -> dict:
    """Parameter set of a datapath module for a configuration (rotate: kind=..., inverse=...)."""
    if module == "ts_quat_mul":
        return quat_mul(cfg, target)
    if module == "ts_quat_rotate":
        return quat_rotate(cfg, kw.get("kind", "axis"), kw.get("inverse", False), target)
    if module == "ts_sincos":
        return sincos(cfg, target, kw.get("rom_path"))
    if module == "ts_joint_quat":
        return joint_quat(cfg, target, kw.get("rom_path"))
    if module == "ts_screw_transport":
        return screw_transport(cfg, target)
    if module == "ts_servo_core":
        return servo_core(cfg, target, kw.get("nmax", 8))
    raise KeyError(module)


def servo_core(cfg: str, target: str = "GENERIC", nmax: int = 8) -> dict:
    """Parameter set of the servo core top (rtl/ts_servo_core.v) for a configuration."""
    return {"NMAX": nmax, "CONFIG": CONFIGS.index(cfg), "TARGET": target, "TRIG_ROM": str(rom_file(cfg)),
            "RECIP_ROM": str(RTL / f"ts_recip_rom_{cfg}.mem"), "ROTVEC_ROM": str(RTL / f"ts_rotvec_rom_{cfg}.mem")}


# ---- parameter sets of the shared pieces (lint, benches) -------------------------------------------
def mul_shapes(cfg: str) -> list[tuple[int, int]]:
    """Operand widths of the multipliers of a configuration (distinct)."""
    w = lambda n: fmt(cfg, n)[0]  # noqa: E731
    r = w("turn_t") - 2 - int(formats(cfg)["TRIG_TABLE_BITS"])
    cand = [(w("quat_t"), w("quat_t")), (w("angle_t"), w("kturn_t")), (r + 1, w("twopi_t")),
            (w("dsq_t"), w("sixth_t")), (w("quat_t"), w("len_t")), (w("scale_t"), w("quat_t")),
            (w("jw_t"), w("lever_t"))]
    out = []
    for c in cand:
        if c not in out:
            out.append(c)
    return out


def round_sat_sets(cfg: str) -> list[tuple[int, int, int, int]]:
    """(IN_W, SHIFT, OUT_W, SAT) of eight ts_round_sat instances taken from the datapath of cfg, plus
    left shifts (with and without possible saturation)."""
    qw, qf = fmt(cfg, "quat_t")
    tw, tf = fmt(cfg, "uvec_tmp_t")
    dw, df = fmt(cfg, "delta_t")
    sw, sf = fmt(cfg, "dsq_t")
    aw, af = fmt(cfg, "angle_t")
    kw, kf = fmt(cfg, "kturn_t")
    uw, _ = fmt(cfg, "turn_t")
    xw, xf = fmt(cfg, "twopi_t")
    r = uw - 2 - int(formats(cfg)["TRIG_TABLE_BITS"])
    return [
        (2 * qw + 2, qf, qw, 1),                  # ts_quat_mul output
        (2 * qw + 1, 2 * qf - 1 - tf, tw, 1),     # ts_quat_rotate t (axis)
        (r + 1 + xw, uw + xf - df, dw, 1),        # ts_sincos d
        (dw + 1, 0, dw, 1),                       # ts_sincos sd (saturation only)
        (dw + sw, sf, dw, 1),                     # ts_sincos de (result narrower than the output)
        (aw + kw, af + kf - uw, uw, 0),           # ts_joint_quat wrap to turn_t
        (qw - 4, -3, qw, 1),                      # left shift with saturation
        (qw - 4, -2, qw + 3, 1),                  # left shift, no saturation possible
    ]


def lint_jobs() -> list[tuple[str, list[str], dict]]:
    """(top, files, parameters) of every module with every parameter set it is used with."""
    jobs = []
    for cfg in CONFIGS:
        for target in TARGETS:
            for m in PRIMITIVES:
                kw = {"kind": "axis"} if m == "ts_quat_rotate" else {}
                p = module_params(m, cfg, target, rom_path=str(rom_file(cfg)), **kw)
                jobs.append((m, sources(m, target), p))
            for kind in ROTATE_KINDS:
                for inv in (False, True):
                    if kind == "axis" and not inv:
                        continue
                    jobs.append(("ts_quat_rotate", sources("ts_quat_rotate", target), quat_rotate(cfg, kind, inv, target)))
            for aw, bw in mul_shapes(cfg):
                jobs.append(("ts_mul", sources("ts_mul", target), {"A_W": aw, "B_W": bw, "TARGET": target}))
                if target == "ECP5":
                    jobs.append(("ts_mul", sources("ts_mul", target), {"A_W": aw, "B_W": bw, "TARGET": target, "MUL3": 1}))
        for iw, sh, ow, sa in round_sat_sets(cfg):
            jobs.append(("ts_round_sat", sources("ts_round_sat"), {"IN_W": iw, "SHIFT": sh, "OUT_W": ow, "SAT": sa}))
    # the delay line: wire, register, shift register, rings in a memory (2, 16 and 24 words)
    for w, d, ram in ((1, 0, 0), (1, 1, 0), (8, 2, 0), (81, 40, 0), (8, 3, 1), (54, 17, 1), (108, 25, 1)):
        jobs.append(("ts_delay", sources("ts_delay"), {"W": w, "DEPTH": d, "RAM": ram}))
    # the per-joint memory: one and two read ports, one address bit
    for w, aw, r in ((18, 3, 1), (54, 3, 2), (8, 1, 1), (96, 5, 2)):
        jobs.append(("ts_ram", sources("ts_ram"), {"W": w, "AW": aw, "R": r}))
    for iw, l, ow in ((8, 0, 12), (8, 0, 8), (12, 0, 8), (8, 3, 14), (8, 3, 11), (8, 3, 9)):
        jobs.append(("ts_resize", sources("ts_resize"), {"IN_W": iw, "LSH": l, "OUT_W": ow}))
    jobs.append(("ts_ecp5_mult18", sources("ts_ecp5_mult18", "ECP5"), {}))
    # the multiplexer: the shapes of its bench (power of two, padded, index bits above the tree, one element)
    for w, n, iw in ((18, 8, 3), (32, 6, 3), (27, 20, 5), (18, 7, 3), (27, 9, 4), (5, 1, 1)):
        jobs.append(("ts_sel", sources("ts_sel"), {"W": w, "N": n, "IW": iw}))
    # the clamp: the solver's widths and a narrow one
    for w in (4, 32, 40):
        jobs.append(("ts_clamp", sources("ts_clamp"), {"W": w}))
    # the multiplier bank: parallel, folded with and without padding slots, one multiplier
    for n, fold in ((6, 1), (16, 4), (9, 7), (6, 6), (3, 7), (5, 2)):
        for target in TARGETS:
            for chain in ((0, 1) if fold > 1 else (0,)):
                jobs.append(("ts_mul_bank", sources("ts_mul_bank", target),
                             {"N": n, "FOLD": fold, "A_W": 18, "B_W": 27, "TARGET": target, "CHAIN": chain}))
    # the folded primitives (the servo core's FOLD), both forms of the held operands
    for cfg in CONFIGS:
        for m in ("ts_quat_mul", "ts_quat_rotate", "ts_screw_transport"):
            for chain in (0, 1):
                jobs.append((m, sources(m), dict(module_params(m, cfg), FOLD=7, CHAIN=chain)))
    # the generated register block (rtl/ts_servo_regs.rdl): joint counts at the extremes, both configurations
    for nmax in (1, 8, 60):
        for config in (0, 1):
            jobs.append(("ts_servo_regs", sources("ts_servo_regs"), {"NMAX": nmax, "CONFIG": config}))
    # the FK/Jacobian engine (rtl/ts_core_fk.v): both configurations and multiplier targets
    for config in (0, 1):
        for target in TARGETS:
            jobs.append(("ts_core_fk", sources("ts_core_fk", target),
                         {"NMAX": 8, "CONFIG": config, "ROM_FILE": str(rom_file(CONFIGS[config])), "TARGET": target}))
        for nmax in (1, 64):
            jobs.append(("ts_core_fk", sources("ts_core_fk"),
                         {"NMAX": nmax, "CONFIG": config, "ROM_FILE": str(rom_file(CONFIGS[config])), "TARGET": "GENERIC"}))
        jobs.append(("ts_core_fk", sources("ts_core_fk"),
                     {"NMAX": 8, "CONFIG": config, "ROM_FILE": str(rom_file(CONFIGS[config])), "TARGET": "GENERIC",
                      "FOLD": 7}))
    # the commit step (rtl/ts_core_commit.v): both configurations and multiplier targets, NMAX extremes
    for config in (0, 1):
        for target in TARGETS:
            for nmax in (1, 8, 60):
                jobs.append(("ts_core_commit", sources("ts_core_commit", target),
                             {"NMAX": nmax, "CONFIG": config, "TARGET": target}))
    # the solver / integration engine (rtl/ts_core_solve.v): both configurations and multiplier targets
    for config in (0, 1):
        for target in TARGETS:
            for nmax in (1, 8, 60):
                jobs.append(("ts_core_solve", sources("ts_core_solve", target),
                             {"NMAX": nmax, "CONFIG": config, "TARGET": target,
                              "ROM_FILE": str(RTL / f"ts_recip_rom_{CONFIGS[config]}.mem")}))
    # the servo law (rtl/ts_core_law.v): both configurations and multiplier targets
    for config in (0, 1):
        for target in TARGETS:
            for fold in (1, 7):
                jobs.append(("ts_core_law", sources("ts_core_law", target),
                             {"CONFIG": config, "TARGET": target, "FOLD": fold,
                              "ROM_FILE": str(RTL / f"ts_rotvec_rom_{CONFIGS[config]}.mem")}))
    # the servo core top (rtl/ts_servo_core.v): both configurations and targets, NMAX 8 and 20
    # (rtl/ts_common.vh waives one spurious Verilator 5.006 VARHIDDEN of the GENERIC elaboration)
    for config in (0, 1):
        for target in TARGETS:
            for nmax in (8, 20):
                jobs.append(("ts_servo_core", sources("ts_servo_core", target), servo_core(CONFIGS[config], target, nmax)))
        # fully parallel (FOLD 1), a fold above the column interval, the shift-chain banks
        for fold in (1, 9):
            jobs.append(("ts_servo_core", sources("ts_servo_core"), dict(servo_core(CONFIGS[config], "GENERIC", 8), FOLD=fold)))
        jobs.append(("ts_servo_core", sources("ts_servo_core", "ECP5"), dict(servo_core(CONFIGS[config], "ECP5", 8), CHAIN=1)))
        # three-multiplier wide products (ts_mul MUL3)
        jobs.append(("ts_servo_core", sources("ts_servo_core", "ECP5"), dict(servo_core(CONFIGS[config], "ECP5", 8), MUL3=1)))
    return jobs


if __name__ == "__main__":
    import sys
    if sys.argv[1:] == ["lint-jobs"]:
        # one line per job: top<TAB>files (space separated)<TAB>NAME=VALUE ... (strings in double quotes)
        for top, files, p in lint_jobs():
            ps = " ".join(f'{k}="{v}"' if isinstance(v, str) else f"{k}={v}" for k, v in p.items())
            print(f"{top}\t{' '.join(files)}\t{ps}")
    else:
        sys.exit("usage: rtlparams.py lint-jobs")


# ---- the engines' copies of the model's formats ------------------------------------------------------
# ts_core_fk / ts_core_law / ts_core_solve write the widths they need as localparams
# `TS_<FORMAT>_W/F = (CONFIG == 0) ? default : compact` and port widths as parameters of the same form;
# their benches check every copy against the model with this function.
def module_localparams(module: str, cfg: str) -> dict[str, int]:
    """The TS_* localparams of rtl/<module>.v evaluated for a configuration."""
    import re
    ci = CONFIGS.index(cfg)
    out = {}
    for line in (RTL / f"{module}.v").read_text().splitlines():
        m = re.match(r"\s*localparam (TS_\w+) = \(CONFIG == 0\) \? (\d+) : (\d+);", line)
        if m:
            out[m.group(1)] = int(m.group(2 + ci))
            continue
        m = re.match(r"\s*localparam (TS_\w+) = (\d+);", line)
        if m:
            out[m.group(1)] = int(m.group(2))
    return out


def check_module_formats(module: str, cfg: str, min_count: int, table_key: str,
                         port_params: list[tuple[str, str]]) -> None:
    """Assert that every TS_<FORMAT>_W/_F localparam of rtl/<module>.v (and TS_<table_key>, a table
    size) and the default of every port-width parameter (name, format) equal the model's formats."""
    import re
    lp = module_localparams(module, cfg)
    assert len(lp) > min_count, (module, cfg, len(lp))
    fm = formats(cfg)
    for key, val in lp.items():
        if key == f"TS_{table_key}":
            assert val == int(fm[table_key]), key
            continue
        name, suf = key[3:-2].lower() + "_t", key[-1]
        w, f = fmt(cfg, name)
        assert val == (w if suf == "W" else f), (cfg, key, val, w, f)
    text = (RTL / f"{module}.v").read_text()
    ci = CONFIGS.index(cfg)
    for par, name in port_params:
        m = re.search(rf"parameter {par} = \(CONFIG == 0\) \? (\d+) : (\d+)", text)
        assert m and int(m.group(1 + ci)) == fmt(cfg, name)[0], (cfg, par)
