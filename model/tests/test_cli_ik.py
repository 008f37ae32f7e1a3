"""tservo ik through the real console script."""
import subprocess
import sys
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from tensor_servo import robots
from tensor_servo.oracle import PinChain

TSERVO = str(Path(sys.executable).with_name("tservo"))


def run(*args):
    return subprocess.run([TSERVO, *map(str, args)], capture_output=True, text=True)


def one_line_error(r, *words):
    assert r.returncode == 2, (r.returncode, r.stdout, r.stderr)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("tservo: error:"), r.stderr
    assert "Traceback" not in r.stderr
    for w in words:
        assert w in lines[0], (w, lines[0])


@pytest.fixture
def files(tmp_path):
    ch = robots.load("puma560")
    pc = PinChain(ch)
    rng = np.random.default_rng(21)
    qt = ch.random_q(rng, 8)
    T = np.array([pc.tool_pose(q) for q in qt])
    q0 = np.clip(qt + rng.uniform(-0.1, 0.1, qt.shape), ch.lower, ch.upper)
    np.save(tmp_path / "T.npy", T)
    np.save(tmp_path / "q0.npy", q0)
    return ch, pc, T, q0, tmp_path


def check_output(ch, pc, T, out, tol_pos=1e-6, tol_rot=1e-5):
    d = np.load(out)
    N, n = len(T), ch.n
    assert d["q"].shape == (N, n) and d["ok"].shape == (N,) and d["ticks"].shape == (N,)
    assert d["pos_err"].shape == (N,) and d["rot_err"].shape == (N,) and d["ok"].dtype == bool
    q = d["q"]
    assert np.all(np.isfinite(q)) and np.all((q >= ch.lower) & (q <= ch.upper))
    pe = np.array([np.linalg.norm(pc.tool_pose(a)[:3, 3] - b[:3, 3]) for a, b in zip(q, T)])
    re = np.array([np.linalg.norm(pin.log3(b[:3, :3].T @ pc.tool_pose(a)[:3, :3])) for a, b in zip(q, T)])
    np.testing.assert_allclose(d["pos_err"], pe, rtol=1e-6, atol=1e-12)
    np.testing.assert_allclose(d["rot_err"], re, rtol=1e-6, atol=1e-12)
    assert np.array_equal(d["ok"], (pe <= tol_pos) & (re <= tol_rot))
    return d


@pytest.mark.parametrize("args", [[], ["--model", "float"], ["--config", "compact", "--tol-pos", "1e-4", "--tol-rot", "1e-3"],
                                  ["--model", "float", "--solver", "pinv"], ["--model", "float", "--solver", "dls"],
                                  ["--limits", "clip"], ["--limits", "wrap", "--restarts", "2", "--seed", "3"]])
def test_ik_runs_and_is_honest(files, args):
    ch, pc, T, q0, tmp = files
    out = tmp / "out.npz"
    tol = (1e-4, 1e-3) if "--tol-pos" in args else (1e-6, 1e-5)
    r = run("ik", "puma560", "--targets", tmp / "T.npy", "--q0", tmp / "q0.npy", *args, "-o", out)
    assert r.returncode == 0, r.stderr
    d = check_output(ch, pc, T, out, *tol)
    assert d["ok"].mean() >= 0.75


def test_single_seed_and_chain_file(files, tmp_path):
    ch, pc, T, q0, tmp = files
    cfile = tmp_path / "puma.json"
    ch.save(cfile)
    np.save(tmp / "one.npy", q0[0])
    out = tmp / "o.npz"
    r = run("ik", cfile, "--targets", tmp / "T.npy", "--q0", tmp / "one.npy", "--max-ticks", "300", "-o", out)
    assert r.returncode == 0, r.stderr
    check_output(ch, pc, T, out)


def test_unreachable_gives_ok_false_within_limits(files):
    ch, pc, T, q0, tmp = files
    Tu = T.copy()
    Tu[:, :3, 3] += np.array([2.0, 2.0, 2.0])
    np.save(tmp / "Tu.npy", Tu)
    out = tmp / "u.npz"
    r = run("ik", "puma560", "--targets", tmp / "Tu.npy", "--q0", tmp / "q0.npy", "--max-ticks", "200", "-o", out)
    assert r.returncode == 0, r.stderr
    d = check_output(ch, pc, Tu, out)
    assert not d["ok"].any()


def _bad(tmp, name, arr):
    p = tmp / name
    np.save(p, arr)
    return p


@pytest.mark.parametrize("case", ["nan_target", "inf_target", "nan_q0", "inf_q0", "target_shape", "q0_shape",
                                  "not_rigid", "reflection", "last_row", "pinv_fixed", "tol", "ticks", "missing",
                                  "text_dtype"])
def test_bad_input_one_line(files, case):
    ch, pc, T, q0, tmp = files
    Tp, qp = tmp / "T.npy", tmp / "q0.npy"
    extra = []
    words = []
    if case == "nan_target":
        a = T.copy(); a[3, 1, 2] = np.nan; Tp = _bad(tmp, "t.npy", a); words = ["--targets", "non-finite"]
    elif case == "inf_target":
        a = T.copy(); a[0, 0, 3] = np.inf; Tp = _bad(tmp, "t.npy", a); words = ["--targets", "non-finite"]
    elif case == "nan_q0":
        a = q0.copy(); a[2, 2] = np.nan; qp = _bad(tmp, "q.npy", a); words = ["--q0", "non-finite"]
    elif case == "inf_q0":
        a = q0.copy(); a[0, 0] = -np.inf; qp = _bad(tmp, "q.npy", a); words = ["--q0", "non-finite"]
    elif case == "target_shape":
        Tp = _bad(tmp, "t.npy", T[:, :3, :]); words = ["--targets", "shape"]
    elif case == "q0_shape":
        qp = _bad(tmp, "q.npy", q0[:, :5]); words = ["--q0", "shape"]
    elif case == "not_rigid":
        a = T.copy(); a[1, :3, :3] *= 1.01; Tp = _bad(tmp, "t.npy", a); words = ["--targets", "target 1", "rigid"]
    elif case == "reflection":
        a = T.copy(); a[4, :3, 2] *= -1; Tp = _bad(tmp, "t.npy", a); words = ["--targets", "target 4", "rigid"]
    elif case == "last_row":
        a = T.copy(); a[2, 3, 3] = 2.0; Tp = _bad(tmp, "t.npy", a); words = ["--targets", "last row"]
    elif case == "pinv_fixed":
        extra = ["--solver", "pinv"]; words = ["--solver"]
    elif case == "tol":
        extra = ["--tol-rot", "-1"]; words = ["--tol-rot"]
    elif case == "ticks":
        extra = ["--max-ticks", "-5"]; words = ["--max-ticks"]
    elif case == "missing":
        Tp = tmp / "nope.npy"; words = ["--targets", "no such file"]
    elif case == "text_dtype":
        Tp = _bad(tmp, "t.npy", np.array([["a"] * 4] * 4)); words = ["--targets"]
    out = tmp / "bad.npz"
    r = run("ik", "puma560", "--targets", Tp, "--q0", qp, *extra, "-o", out)
    one_line_error(r, *words)
    assert not out.exists()
