"""``tservo chain`` through the real console script: results, and bad input handling.

Every bad input must give exit status 2, exactly one line on stderr (``tservo: error: ...``) that
names the offending field or element, no traceback, nothing on stdout, and no output file (an
existing output file is left untouched).
"""
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from tensor_servo import robots

TSERVO = Path(sys.executable).parent / "tservo"
DATA = Path(__file__).parent / "data"
DH_DIR = robots.HERE / "dh"

GOOD_CHAIN = {
    "name": "cli_test",
    "joints": [
        {"name": "a", "type": "revolute", "origin": {"xyz": [0, 0, 0.1], "quat_wxyz": [1, 0, 0, 0]},
         "axis": [0, 0, 1], "limits": {"lower": -1, "upper": 1}},
        {"name": "b", "type": "prismatic", "origin": {"xyz": [0.2, 0, 0], "quat_wxyz": [1, 0, 0, 0]},
         "axis": [1, 0, 0], "limits": {"lower": 0, "upper": 0.3}},
    ],
}
GOOD_CHAIN_TEXT = json.dumps(GOOD_CHAIN)


def run(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    assert TSERVO.is_file(), f"console script not installed: {TSERVO}"
    env = {k: v for k, v in os.environ.items() if k != "TSERVO_DEBUG"}
    return subprocess.run([str(TSERVO), *args], cwd=cwd, env=env, capture_output=True, text=True, timeout=120)


def chain_text(**joint0) -> str:
    d = json.loads(json.dumps(GOOD_CHAIN))
    for k, v in joint0.items():
        if v is None:
            del d["joints"][0][k]
        else:
            d["joints"][0][k] = v
    return json.dumps(d)


# ---- successful commands -------------------------------------------------------------------------

@pytest.mark.parametrize("name", ["puma560", "ur5", "panda", "stanford", "chain20"])
def test_validate_examples(name, tmp_path):
    r = run("chain", "validate", name, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert r.stderr == ""
    assert f"chain '{name}'" in r.stdout and "reach:" in r.stdout
    for cfg in ("double", "default", "compact"):
        assert any(line.split()[:2] == [cfg, "fits"] for line in r.stdout.splitlines()), r.stdout


def test_validate_file_reports_configurations(tmp_path):
    d = json.loads(GOOD_CHAIN_TEXT)
    d["joints"][1]["origin"]["xyz"] = [3.5, 0, 0]
    d["joints"][1]["limits"]["upper"] = 0.8  # reach 0.1 + 3.5 + 0.8 = 4.4 m: beyond compact's +-4 m lever arm
    (tmp_path / "long.json").write_text(json.dumps(d))
    r = run("chain", "validate", "long.json", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert "reach: 4.4000 m" in r.stdout
    assert any(line.split()[:2] == ["default", "fits"] for line in lines)
    assert any(line.split()[:4] == ["compact", "does", "not", "fit:"] for line in lines), r.stdout


def test_validate_normalises_quaternion_within_tolerance(tmp_path):
    d = json.loads(GOOD_CHAIN_TEXT)
    d["joints"][0]["origin"]["quat_wxyz"] = [1.0008, 0, 0, 0]
    (tmp_path / "q.json").write_text(json.dumps(d))
    r = run("chain", "validate", "q.json", cwd=tmp_path)
    assert r.returncode == 0 and r.stderr == ""


@pytest.mark.parametrize("name", ["puma560", "chain20"])
def test_export(name, tmp_path):
    r = run("chain", "export", name, "-o", "out.json", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "out.json").read_bytes() == robots.path(name).read_bytes()
    r = run("chain", "export", name, "-o", "-", cwd=tmp_path)
    assert r.returncode == 0 and r.stdout == robots.path(name).read_text()


@pytest.mark.parametrize("name", ["puma560", "ur5", "panda", "stanford"])
def test_from_dh_regenerates_the_examples(name, tmp_path):
    r = run("chain", "from-dh", str(DH_DIR / f"{name}.json"), "-o", "out.json", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "out.json").read_bytes() == robots.path(name).read_bytes()


def test_from_urdf(tmp_path):
    r = run("chain", "from-urdf", str(DATA / "serial_fixed.urdf"), "--base", "world", "--tip", "tcp",
            "--name", "arm", "-o", "arm.json", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    d = json.loads((tmp_path / "arm.json").read_text())
    assert d["name"] == "arm" and [j["name"] for j in d["joints"]] == ["j1", "j2", "j3", "j4"]
    r = run("chain", "validate", "arm.json", cwd=tmp_path)
    assert r.returncode == 0, r.stderr


# ---- bad input -----------------------------------------------------------------------------------

BAD_DH = json.loads((DH_DIR / "stanford.json").read_text())


def dh_text(edit) -> str:
    d = json.loads(json.dumps(BAD_DH))
    edit(d)
    return json.dumps(d)


# id -> (command args after "tservo chain", {file: content}, text the error line must contain)
BAD = {
    # chain files (validate)
    "chain-malformed-json": (["validate", "c.json"], {"c.json": '{"name": "x", "joints": ['},
                             "c.json: malformed JSON at line 1"),
    "chain-missing-file": (["validate", "nothing.json"], {}, "nothing.json: no such file"),
    "chain-missing-axis": (["validate", "c.json"], {"c.json": chain_text(axis=None)}, "joints[0].axis: missing"),
    "chain-missing-name": (["validate", "c.json"], {"c.json": GOOD_CHAIN_TEXT.replace('"name": "cli_test", ', "")},
                           "name: missing"),
    "chain-zero-axis": (["validate", "c.json"], {"c.json": chain_text(axis=[0, 0, 0])}, "joints[0].axis: zero vector"),
    "chain-nan-axis": (["validate", "c.json"], {"c.json": chain_text(axis=[float("nan"), 0, 1])},
                       "joints[0].axis: not finite"),
    "chain-inf-axis": (["validate", "c.json"], {"c.json": chain_text(axis=[0, 1e999, 1])}, "joints[0].axis: not finite"),
    "chain-quat-norm": (["validate", "c.json"],
                        {"c.json": chain_text(origin={"xyz": [0, 0, 0], "quat_wxyz": [1.01, 0, 0, 0]})},
                        "joints[0].origin.quat_wxyz: quaternion norm 1.01 is not 1"),
    "chain-lower-gt-upper": (["validate", "c.json"], {"c.json": chain_text(limits={"lower": 1, "upper": -1})},
                             "joints[0].limits: lower 1 > upper -1"),
    "chain-bad-type": (["validate", "c.json"], {"c.json": chain_text(type="ball")}, "joints[0].type: must be one of"),
    # DH tables (from-dh, with an output file)
    "dh-malformed-json": (["from-dh", "t.json", "-o", "out.json"], {"t.json": "{\n  'name': 1}"},
                          "t.json: malformed JSON at line 2"),
    "dh-missing-alpha": (["from-dh", "t.json", "-o", "out.json"],
                         {"t.json": dh_text(lambda d: d["joints"][3].pop("alpha"))}, "joints[3].alpha: missing"),
    "dh-base-quat": (["from-dh", "t.json", "-o", "out.json"],
                     {"t.json": dh_text(lambda d: d.update(base={"xyz": [0, 0, 0], "quat_wxyz": [0.9, 0, 0, 0]}))},
                     "base.quat_wxyz: quaternion norm 0.9"),
    "dh-lower-gt-upper": (["from-dh", "t.json", "-o", "out.json"],
                          {"t.json": dh_text(lambda d: d["joints"][2].update(limits={"lower": 1.0, "upper": 0.5}))},
                          "joints[2].limits: lower 1 > upper 0.5"),
    "dh-nan": (["from-dh", "t.json", "-o", "out.json"],
               {"t.json": dh_text(lambda d: d["joints"][0].update(a=float("inf")))}, "joints[0].a: not finite"),
    # URDF (from-urdf, with an output file)
    "urdf-malformed": (["from-urdf", str(DATA / "malformed.urdf"), "-o", "out.json"], {},
                       "malformed.urdf: malformed XML at line 10 column 9"),
    "urdf-floating": (["from-urdf", str(DATA / "floating.urdf"), "--base", "world", "--tip", "arm", "-o", "out.json"],
                      {}, "joint 'free_flyer': type 'floating' is not supported"),
    "urdf-planar": (["from-urdf", str(DATA / "planar.urdf"), "--base", "floor", "--tip", "arm", "-o", "out.json"],
                    {}, "joint 'cart_plane': type 'planar' is not supported"),
    "urdf-no-path": (["from-urdf", str(DATA / "disconnected.urdf"), "--base", "a", "--tip", "d", "-o", "out.json"],
                     {}, "--base: link 'a' is not an ancestor of link 'd'"),
    "urdf-unknown-link": (["from-urdf", str(DATA / "disconnected.urdf"), "--base", "a", "--tip", "hand", "-o",
                           "out.json"], {}, "--tip: no link named 'hand' in disconnected.urdf"),
    # examples
    "export-unknown": (["export", "puma", "-o", "out.json"], {}, "NAME: unknown example 'puma'"),
}


def check_bad(r: subprocess.CompletedProcess, expected: str) -> None:
    assert r.returncode == 2, (r.returncode, r.stdout, r.stderr)
    assert "Traceback" not in r.stderr and "Traceback" not in r.stdout
    assert r.stdout == ""
    lines = r.stderr.splitlines()
    assert len(lines) == 1 and r.stderr.endswith("\n"), r.stderr
    assert lines[0].startswith("tservo: error: "), lines[0]
    assert expected in lines[0], lines[0]


@pytest.mark.parametrize("case", list(BAD))
def test_bad_input(case, tmp_path):
    args, files, expected = BAD[case]
    for name, content in files.items():
        (tmp_path / name).write_text(content)
    before = sorted(os.listdir(tmp_path))
    r = run("chain", *args, cwd=tmp_path)
    check_bad(r, expected)
    assert sorted(os.listdir(tmp_path)) == before  # no output, no temporary file left behind


@pytest.mark.parametrize("case", ["dh-missing-alpha", "urdf-floating", "export-unknown"])
def test_bad_input_leaves_existing_output_untouched(case, tmp_path):
    args, files, expected = BAD[case]
    for name, content in files.items():
        (tmp_path / name).write_text(content)
    out = tmp_path / "out.json"
    out.write_text("previous content\n")
    os.utime(out, (1_000_000_000, 1_000_000_000))
    before = sorted(os.listdir(tmp_path))
    r = run("chain", *args, cwd=tmp_path)
    check_bad(r, expected)
    assert out.read_text() == "previous content\n" and out.stat().st_mtime == 1_000_000_000
    assert sorted(os.listdir(tmp_path)) == before


def test_usage_errors_are_one_line(tmp_path):
    r = run("chain", "from-dh", "t.json", cwd=tmp_path)  # -o missing
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert r.stderr.count("\n") == 1 and r.stderr.startswith("tservo chain from-dh: error:"), r.stderr
