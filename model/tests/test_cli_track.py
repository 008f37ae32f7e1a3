"""``tservo track`` and ``tservo path`` through the real console script: results checked against
float64 kinematics, and bad input (one line naming the field, exit 2, nothing written)."""
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tensor_servo import cli, reference, robots
from tensor_servo.pathgen import circle

TSERVO = str(Path(sys.executable).with_name("tservo"))
PUMA_Q = np.array([0.2, 1.0, -2.8, 0.3, 0.8, 0.2])


def run(*args):
    return subprocess.run([TSERVO, *map(str, args)], capture_output=True, text=True)


def one_line_error(r, *words):
    assert r.returncode == 2, (r.returncode, r.stderr)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("tservo: error:"), r.stderr
    assert "Traceback" not in r.stderr
    for w in words:
        assert w in lines[0], (w, lines[0])


def main_ok(*args) -> int:
    return cli.main([str(a) for a in args])


def main_error(capsys, *args, words=()):
    """The same command in-process (cli.main, as the console script calls it): faster for the many
    bad-input cases; a few cases above go through the real console script."""
    rc = cli.main([str(a) for a in args])
    err = capsys.readouterr().err
    assert rc == 2, (rc, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("tservo: error:"), err
    for w in words:
        assert w in lines[0], (w, lines[0])


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("track")
    ch = robots.load("puma560")
    T0 = reference.fk_frames(ch, PUMA_Q)[-1]
    T, V = circle(T0, 0.03, 1.0, 1e-3, 0.12, plane=((0, 1, 0), (0, 0, 1)), tilt=0.1)
    np.savez(d / "path.npz", T=T, V=V, dt=1e-3)
    np.save(d / "q0.npy", PUMA_Q)
    return d, T, V


@pytest.mark.parametrize("model", ["float", "fixed"])
def test_track_outputs_and_true_errors(files, model):
    d, T, V = files
    out = d / f"out_{model}.npz"
    r = run("track", "puma560", "--path", d / "path.npz", "--q0", d / "q0.npy", "--model", model, "-o", out)
    assert r.returncode == 0, r.stderr
    o = np.load(out)
    K, n = len(T), 6
    assert o["q"].shape == (K + 1, n) and o["qd"].shape == (K, n)
    assert o["pos_err"].shape == (K,) and o["rot_err"].shape == (K,) and o["flags"].shape == (K,)
    assert np.array_equal(o["q"][0], PUMA_Q)
    assert np.allclose(np.diff(o["q"], axis=0), 1e-3 * o["qd"], atol=1e-15)   # ideal plant
    ch = robots.load("puma560")
    for k in (0, 37, K - 1):
        Tq = reference.fk_frames(ch, o["q"][k])[-1]
        assert abs(o["pos_err"][k] - np.linalg.norm(T[k, :3, 3] - Tq[:3, 3])) < 1e-12
        ang = np.linalg.norm(reference.rotvec(T[k, :3, :3] @ Tq[:3, :3].T))
        assert abs(o["rot_err"][k] - ang) < 1e-12
    assert o["pos_err"][K // 2:].max() < 2e-5 and not (np.bitwise_or.reduce(o["flags"]) & 0xFFFF)


def test_track_options_change_the_run(files):
    d, T, V = files
    base = d / "a.npz"
    assert main_ok("track", "puma560", "--path", d / "path.npz", "--q0", d / "q0.npy", "--model", "float",
                   "-o", base) == 0
    a = np.load(base)
    # error-only mode lags (no feed-forward): much larger error while moving
    eo = d / "eo.npz"
    assert main_ok("track", "puma560", "--path", d / "path.npz", "--q0", d / "q0.npy", "--model", "float",
                   "--error-only", "-o", eo) == 0
    assert np.load(eo)["pos_err"][60:].min() > 10 * a["pos_err"][60:].max()
    # encoder quantisation: what the core saw is on the count grid
    qz = d / "qz.npz"
    assert main_ok("track", "puma560", "--path", d / "path.npz", "--q0", d / "q0.npy", "--model", "fixed",
                   "--counts", "10000", "--lag", "0.002", "--mode", "B", "--sweeps", "4", "--mu", "1.2",
                   "--warm", "prev", "-o", qz) == 0
    m = np.load(qz)["q_meas"]
    assert np.allclose(m * 1e4, np.round(m * 1e4), atol=1e-6)
    assert np.abs(np.load(qz)["q"][:-1] - m).max() <= 0.5e-4 + 1e-12


def test_track_setpoint_frame(tmp_path):
    ch = robots.load("puma560")
    F = reference.fk_frames(ch, PUMA_Q + np.array([0, 0, 0.01, 0.01, -0.01, 0.02]))
    U = reference.pose_inv(F[2]) @ F[-1]
    np.savez(tmp_path / "p.npz", T=np.repeat(U[None], 200, 0), V=np.zeros((200, 6)), dt=1e-3)
    np.save(tmp_path / "q0.npy", PUMA_Q)
    out = tmp_path / "o.npz"
    assert main_ok("track", "puma560", "--path", tmp_path / "p.npz", "--q0", tmp_path / "q0.npy", "--model",
                   "float", "--setpoint-frame", "2", "-o", out) == 0
    o = np.load(out)
    Fq = reference.fk_frames(ch, o["q"][199])
    rel = reference.pose_inv(Fq[2]) @ Fq[-1]
    assert np.linalg.norm(rel[:3, 3] - U[:3, 3]) < 1e-9
    assert abs(o["pos_err"][199] - np.linalg.norm(rel[:3, 3] - U[:3, 3])) < 1e-12


def _bad_path(d, name, **over):
    ch = robots.load("puma560")
    T0 = reference.fk_frames(ch, PUMA_Q)[-1]
    arrs = dict(T=np.repeat(T0[None], 5, 0), V=np.zeros((5, 6)), dt=1e-3)
    arrs.update(over)
    arrs = {k: v for k, v in arrs.items() if v is not None}
    np.savez(d / name, **arrs)
    return d / name


def test_track_bad_inputs(tmp_path, files, capsys):
    d, T, V = files
    out = tmp_path / "never.npz"
    q0 = d / "q0.npy"
    base = ["track", "puma560", "--q0", q0, "-o", out]
    nanV = np.zeros((5, 6))
    nanV[2, 4] = np.nan
    skew = np.repeat(reference.fk_frames(robots.load("puma560"), PUMA_Q)[-1][None], 5, 0)
    skew[3, 0, 1] += 0.01
    far = skew.copy()
    far[:, :3, :3] = np.eye(3)
    far[:, 0, 3] = 20.0
    cases = [
        (_bad_path(tmp_path, "noT.npz", T=None), ("--path: T", "missing")),
        (_bad_path(tmp_path, "nanV.npz", V=nanV), ("--path: V", "non-finite")),
        (_bad_path(tmp_path, "shapeV.npz", V=np.zeros((4, 6))), ("--path: V", "shape")),
        (_bad_path(tmp_path, "skew.npz", T=skew), ("--path: T", "pose 3")),
        (_bad_path(tmp_path, "dt0.npz", dt=0.0), ("--path: dt",)),
        (_bad_path(tmp_path, "dtbig.npz", dt=0.1), ("--path: dt", "format")),
        (_bad_path(tmp_path, "dtvec.npz", dt=np.array([1e-3, 1e-3])), ("--path: dt", "scalar")),
        (_bad_path(tmp_path, "far.npz", T=far), ("--path: T", "position format")),
        (tmp_path / "missing.npz", ("--path", "no such file")),
    ]
    one_line_error(run(*base, "--path", cases[0][0]), *cases[0][1])          # console script
    for path, words in cases[1:]:
        main_error(capsys, *base, "--path", path, words=words)
    good = _bad_path(tmp_path, "good.npz")
    bad_q = tmp_path / "badq.npy"
    np.save(bad_q, np.array([0.0, 4.5, 0, 0, 0, 0]))
    one_line_error(run("track", "puma560", "--path", good, "--q0", bad_q, "-o", out), "--q0", "joint 1", "limits")
    np.save(bad_q, np.zeros(5))
    main_error(capsys, "track", "puma560", "--path", good, "--q0", bad_q, "-o", out, words=("--q0", "shape"))
    np.save(bad_q, np.array([0.0, np.inf, 0, 0, 0, 0]))
    main_error(capsys, "track", "puma560", "--path", good, "--q0", bad_q, "-o", out, words=("--q0", "non-finite"))
    for opts, words in [(("--mu", "2.5"), ("--mu",)), (("--mu", "1,1"), ("--mu", "6")),
                        (("--klim", "2000"), ("--klim", "1/dt")), (("--kp", "-3"), ("--kp",)),
                        (("--kp", "20000"), ("--kp", "format")), (("--sweeps", "0"), ("--sweeps",)),
                        (("--setpoint-frame", "7"), ("--setpoint-frame",)), (("--lag", "-1"), ("--lag",)),
                        (("--counts", "0"), ("--counts",)), (("--warm", "maybe"), ("--warm",)),
                        (("--L", "5"), ("--L",))]:
        main_error(capsys, "track", "puma560", "--path", good, "--q0", q0, *opts, "-o", out, words=words)
    assert not out.exists()


def test_path_line_and_poses(tmp_path, files):
    d, _, _ = files
    ch = robots.load("puma560")
    out = tmp_path / "line.npz"
    r = run("path", "puma560", "--line", "0.02", "-0.01", "0.03", "0.05", "0", "0.1", "--q0", d / "q0.npy",
            "--step", "0.005", "-o", out)
    assert r.returncode == 0, r.stderr
    o = np.load(out)
    T0 = reference.fk_frames(ch, PUMA_Q)[-1]
    last = reference.fk_frames(ch, o["q"][-1])[-1]
    assert np.linalg.norm(last[:3, 3] - (T0[:3, 3] + [0.02, -0.01, 0.03])) < 2e-6
    assert np.linalg.norm(o["T"][1, :3, 3] - o["T"][0, :3, 3]) <= 0.005 + 1e-12
    assert o["converged"].all() and np.all(o["q"] >= ch.lower) and np.all(o["q"] <= ch.upper)
    # the same end pose given as a waypoint file reproduces the same samples
    np.save(tmp_path / "w.npy", o["T"][-1][None])
    out2 = tmp_path / "poses.npz"
    assert main_ok("path", "puma560", "--poses", tmp_path / "w.npy", "--q0", d / "q0.npy", "--step", "0.005",
                   "--model", "float", "-o", out2) == 0
    assert np.allclose(np.load(out2)["T"], o["T"], atol=1e-12)


def test_path_unreachable_exits_1_with_output(tmp_path, files, capsys):
    d, _, _ = files
    out = tmp_path / "far.npz"
    rc = main_ok("path", "puma560", "--line", "1.0", "0", "0", "--q0", d / "q0.npy", "--step", "0.05", "--iters", "5",
                 "-o", out)
    err = capsys.readouterr().err
    assert rc == 1 and out.exists()
    assert err.count("\n") == 1 and "not within tolerance" in err
    assert not np.load(out)["converged"].all()


def test_path_bad_inputs(tmp_path, files, capsys):
    d, _, _ = files
    out = tmp_path / "never.npz"
    q0 = d / "q0.npy"
    one_line_error(run("path", "puma560", "--line", "0.1", "0", "--q0", q0, "-o", out), "--line")
    main_error(capsys, "path", "puma560", "--line", "0.1", "0", "0", "--q0", q0, "--step", "0", "-o", out,
               words=("--step",))
    np.save(tmp_path / "bad.npy", np.zeros((2, 3, 4)))
    main_error(capsys, "path", "puma560", "--poses", tmp_path / "bad.npy", "--q0", q0, "-o", out,
               words=("--poses", "shape"))
    main_error(capsys, "path", "puma560", "--line", "0", "0", "0", "0", "0", "4", "--q0", q0, "-o", out,
               words=("--line", "pi"))
    main_error(capsys, "path", "puma560", "--line", "0", "0", "0", "--q0", q0, "--iters", "0", "-o", out,
               words=("--iters",))
    with pytest.raises(SystemExit) as e:       # argparse: one of --poses / --line is required
        cli.main(["path", "puma560", "--q0", str(q0), "-o", str(out)])
    assert e.value.code == 2 and "--poses" in capsys.readouterr().err
    assert not out.exists()
