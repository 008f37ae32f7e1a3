"""The Verilated servo core in the closed loop (``tservo track --model rtl``, tensor_servo.rtl_core).

Per configuration (default, compact) and chain -- PUMA 560 (error choice A), UR5 (error-only),
Panda (choice B), the Stanford arm (a prismatic joint) and a fresh random chain at the core's NMAX
(8 joints, arbitrary axes and origins, mixed joint types and scales, velocity limits) -- the plant
tracks a task-space circle with rocking orientation, once with the bit-accurate model
(``--model fixed``) and once with the Verilated core driven over AXI4-Lite and AXI4-Stream
(``--model rtl``): every output of the two runs must be identical (plant q, commands, errors,
flags).  PUMA 560 and Panda, from their benchmark start poses, are also compared with the float
model: the core's tool path within 4 LSB of the position-error format of the float one over the
second half of the run (docs/numerics.md, tracking).

Ticks per run: TS_RTL_TICKS (default 100 at 10 sweeps); ``make soak`` runs 10,000 ticks per chain
and configuration at 2 sweeps (TS_RTL_TICKS=10000 TS_RTL_SWEEPS=2); TS_SEED replays the random
chain.  The 20-joint chain runs through the core built with NMAX = 20 in ``make soak`` (or with
TS_RTL_WIDE=1); UR5 through the core built with NMAX = 6 (``--nmax``) in every run.  The CLI
test checks ``tservo track --model rtl`` output files against ``--model fixed`` and its one-line
errors.
"""
from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

from tensor_servo import robots
from tensor_servo.bench_tracking import HOME, lsb
from tensor_servo.errors import InputError
from tensor_servo.pathgen import circle
from tensor_servo.plant import Plant
from tensor_servo.randchain import random_chain
from tensor_servo.rtl_core import core_nmax
from tensor_servo.track import make_tick, relative_poses, run_model

NT = int(os.environ.get("TS_RTL_TICKS", "100"))
SWEEPS = int(os.environ.get("TS_RTL_SWEEPS", "10"))
SEED = int(os.environ.get("TS_SEED", str(np.random.SeedSequence().entropy % 2**31)))
CHAINS = {"puma560": {"mode": "A"}, "ur5": {"feedforward": False}, "panda": {"mode": "B"},
          "stanford": {"mode": "A"}, "random8": {"mode": "A"}}
DT = 1e-3


def load_chain(name: str, cfg: str):
    """An embedded robot, or the random NMAX chain (redrawn until the configuration accepts it:
    its reach must fit the position formats)."""
    if name != "random8":
        return robots.load(name)
    rng = np.random.default_rng(SEED)
    for _ in range(100):
        ch = random_chain(rng, core_nmax(1), velocity=4.0, scales=(0.5, 1.5), offset=(0.03, 0.15))
        try:
            make_tick("fixed", ch, config=cfg, dt=DT)
            return ch
        except InputError:
            continue
    raise AssertionError(f"no random chain accepted by {cfg} (seed {SEED})")


def start(ch, name: str, rng) -> np.ndarray:
    if name in HOME:
        return HOME[name].copy()
    lo, hi = np.where(np.isfinite(ch.lower), ch.lower, -1.0), np.where(np.isfinite(ch.upper), ch.upper, 1.0)
    return lo + (hi - lo) * rng.uniform(0.35, 0.65, ch.n)


def path_for(ch, q0: np.ndarray, nt: int):
    """A circle of 1 cm radius in 1 s through the start tool pose, orientation rocking by 0.1 rad."""
    T0 = relative_poses(ch, q0[None])[0]
    return circle(T0, 0.01, 1.0, DT, nt * DT, plane=((0, 1, 0), (0, 0, 1)), tilt=0.1, axis=(1.0, 1.0, 0.0))


def run(model: str, ch, cfg: str, q0, T, V, params):
    res, tick, _ = run_model(model, ch, T, V, q0, Plant(q0, DT), config=cfg, dt=DT, sweeps=SWEEPS, **params)
    return res, tick


@pytest.mark.parametrize("cfg", ["default", "compact"])
@pytest.mark.parametrize("name", list(CHAINS))
def test_rtl_core_tracks_bit_identical_to_the_model(name, cfg):
    ch = load_chain(name, cfg)
    q0 = start(ch, name, np.random.default_rng(SEED + 1))
    T, V = path_for(ch, q0, NT)
    fx, _ = run("fixed", ch, cfg, q0, T, V, CHAINS[name])
    rt, tick = run("rtl", ch, cfg, q0, T, V, CHAINS[name])
    for k in ("q", "qd", "flags", "pos_err", "rot_err", "q_meas"):
        a, b = getattr(fx, k), getattr(rt, k)
        if not np.array_equal(a, b):
            bad = np.argwhere(a != b)[0]
            pytest.fail(f"{name} {cfg} (seed {SEED}): {k} differs first at {tuple(bad)}: fixed {a[tuple(bad)]} rtl {b[tuple(bad)]}")
    cyc = tick.core.cycles
    assert len(cyc) == NT and min(cyc) > 0
    print(f"[rtl track] {name} {cfg} n={ch.n} NMAX={tick.core.nmax} (seed {SEED}): {NT} ticks identical to the model; "
          f"{SWEEPS} sweeps: {min(cyc)}-{max(cyc)} cycles per tick; flags {int(np.bitwise_or.reduce(rt.flags)):#x}")


#: the NMAX = 20 core takes about 2 minutes to Verilate: run by ``make soak`` (or TS_RTL_WIDE=1),
#: not by ``make test``, which must stay under 20 minutes on 2 cores
WIDE = os.environ.get("TS_RTL_WIDE", "0") == "1" or NT >= 1000


def _compact_core_matches_model(name: str, nt: int, seed: int, **rtl) -> object:
    """``name`` tracking its circle for nt ticks in the compact configuration at 2 sweeps, with the
    model and through the core (rtl: RtlServo options, e.g. nmax): every output identical.
    Returns the rtl tick model (``.core``: nmax, cycles)."""
    ch = robots.load(name)
    q0 = start(ch, name, np.random.default_rng(seed))
    T, V = path_for(ch, q0, nt)
    res, _, _ = run_model("fixed", ch, T, V, q0, Plant(q0, DT), config="compact", dt=DT, sweeps=2)
    rt, tick, _ = run_model("rtl", ch, T, V, q0, Plant(q0, DT), config="compact", dt=DT, sweeps=2, **rtl)
    for k in ("q", "qd", "flags", "pos_err", "rot_err"):
        assert np.array_equal(getattr(res, k), getattr(rt, k)), (name, k, SEED)
    return tick


@pytest.mark.skipif(not WIDE, reason="make soak runs it (TS_RTL_WIDE=1): the NMAX = 20 core build is slow")
def test_rtl_core_above_nmax_8_tracks_bit_identical():
    """The 20-joint chain through the whole core built with NMAX = 20 (compact, 2 sweeps,
    max(30, TS_RTL_TICKS / 5) ticks): every output identical to the model."""
    nt = max(30, NT // 5)
    tick = _compact_core_matches_model("chain20", nt, SEED + 2)
    assert tick.core.nmax == 20
    print(f"[rtl track] chain20 compact NMAX=20: {nt} ticks identical; {min(tick.core.cycles)} cycles per tick")


def test_rtl_core_built_for_six_joints_tracks_bit_identical():
    """UR5 through the core built with NMAX = 6, the smallest core for a 6-joint arm (the tests
    above build NMAX 8): compact, 2 sweeps, 40 ticks, every output identical to the model."""
    tick = _compact_core_matches_model("ur5", 40, SEED + 3, nmax=6)
    assert tick.core.nmax == 6
    print(f"[rtl track] ur5 compact NMAX=6: 40 ticks identical; {min(tick.core.cycles)} cycles per tick")


@pytest.mark.parametrize("cfg", ["default", "compact"])
@pytest.mark.parametrize("name", ["puma560", "panda"])
def test_rtl_core_within_tolerance_of_float(name, cfg):
    """The core's tool path against the float servo's (the C++ servo on double), second half."""
    ch = robots.load(name)
    q0 = HOME[name]
    nt = max(NT, 200)
    T, V = path_for(ch, q0, nt)
    fl, _ = run("float", ch, cfg, q0, T, V, CHAINS[name])
    rt, _ = run("rtl", ch, cfg, q0, T, V, CHAINS[name])
    half = nt // 2
    P_fl = relative_poses(ch, fl.q[half:-1])[:, :3, 3]
    P_rt = relative_poses(ch, rt.q[half:-1])[:, :3, 3]
    d = float(np.linalg.norm(P_rt - P_fl, axis=1).max())
    n_lsb = d / lsb(cfg, "perr_t")
    print(f"[rtl vs float] {name} {cfg}: worst tool distance {d:.3g} m = {n_lsb:.2f} LSB of perr_t")
    assert n_lsb <= 4, (name, cfg, d, n_lsb)


def _tservo(*args, cwd):
    return subprocess.run([sys.executable, "-m", "tensor_servo.cli", *args], capture_output=True, text=True, cwd=cwd)


def test_tservo_track_model_rtl_cli(tmp_path):
    """``tservo track --model rtl`` writes the same file contents as ``--model fixed``; errors are
    one line, exit status 2, nothing written."""
    ch = robots.load("puma560")
    q0 = HOME["puma560"]
    T, V = path_for(ch, q0, 40)
    np.savez(tmp_path / "p.npz", T=T, V=V, dt=DT)
    np.save(tmp_path / "q0.npy", q0)
    outs = {}
    for m in ("fixed", "rtl"):
        r = _tservo("track", "puma560", "--path", "p.npz", "--q0", "q0.npy", "--model", m, "--config", "compact",
                    "--sweeps", "2", "-o", f"{m}.npz", cwd=tmp_path)
        assert r.returncode == 0, r.stderr
        outs[m] = dict(np.load(tmp_path / f"{m}.npz"))
    assert outs["fixed"].keys() == outs["rtl"].keys()
    for k in outs["fixed"]:
        assert np.array_equal(outs["fixed"][k], outs["rtl"][k]), k
    # what the core cannot do is refused before anything runs
    for model, extra, field in (("rtl", ["--setpoint-frame", "2"], "--setpoint-frame"),
                                ("rtl", ["--sweeps", "300"], "--sweeps"), ("rtl", ["--warm", "18"], "--warm"),
                                ("rtl", ["--nmax", "5"], "--nmax"), ("rtl", ["--nmax", "61"], "--nmax"),
                                ("fixed", ["--nmax", "8"], "--nmax")):
        r = _tservo("track", "puma560", "--path", "p.npz", "--q0", "q0.npy", "--model", model, *extra, "-o", "bad.npz",
                    cwd=tmp_path)
        assert r.returncode == 2, (extra, r.returncode, r.stderr)
        lines = r.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith(f"tservo: error: {field}"), (extra, r.stderr)
        assert not (tmp_path / "bad.npz").exists()


def test_rtl_core_refuses_a_warm_start_it_does_not_keep():
    """The core keeps its own warm start; a loop handing it another one is told so."""
    ch = robots.load("puma560")
    tick = make_tick("rtl", ch, config="compact", dt=DT, sweeps=2)
    try:
        q0 = HOME["puma560"]
        T0 = relative_poses(ch, q0[None])[0]
        o = tick(q0, T0, np.zeros(6), np.zeros(6))
        assert np.all(np.isfinite(o.qd))
        with pytest.raises(InputError, match="qd_warm"):
            tick(q0, T0, np.zeros(6), np.full(6, 0.5))
    finally:
        tick.core.close()



def test_rtl_core_refusal_names_the_code_and_the_field():
    """A configuration the core refuses (an axis made non-unit after quantisation) raises one
    InputError with CFG_ERROR's code and joint and the model's field for the same words."""
    from tensor_servo.rtl_core import RtlServo

    core = RtlServo(robots.load("puma560"), "compact", dt=DT, sweeps=2)
    try:
        core.raw["joints"][2]["axis"][0] += 1 << 12
        with pytest.raises(InputError) as e:
            core.commit()
        msg = str(e.value)
        assert "CFG_ERROR 2 at joint 2" in msg and "joints[2]" in msg and "\n" not in msg, msg
    finally:
        core.close()


def test_rtl_core_refuses_the_offline_refinement():
    """The conjugate-direction refinement (cg) is an offline IK option of the model; the core has
    none, so asking the rtl back end for it is refused with one line naming the field."""
    from tensor_servo.rtl_core import RtlServo

    with pytest.raises(InputError, match="^cg: .*no conjugate-direction refinement") as e:
        RtlServo(robots.load("puma560"), "compact", dt=DT, sweeps=2, cg=4)
    assert "\n" not in str(e.value)
