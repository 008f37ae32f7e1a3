// SPDX-License-Identifier: Apache-2.0
// tensor-servo: the back half of the servo tick (one task), bit-exact with the model's
// ts::servo_back (model/include/tensor_servo/servo.hpp) and the division-free coordinate-descent
// solver (solver.hpp: solver_target, solver_columns, solver_steps, warm_leak, solver_run):
//   vs    = (cvt<tw_t>(L V_w); cvt<tw_t>(V_v))                 scaled target
//   Js_i  = (cvt<jsc_t>(L w_i); cvt<jsc_t>(v_i))                scaled columns
//   d_i   = |Js_i|^2 (exact), k_i = floor(log2 d_i), m_i = d_i 2^-k_i (truncated to mant_t)
//   y0    = ROM[6 fraction bits of m_i], e = cvt(1 - m y0), y = cvt(y0 + y0 e), c_i = cvt(mu_i y)
//   bounds: [-vmax, vmax], position bounds klim (lo - q), klim (hi - q) clamped into it
//   q'    = clamp(warm - (warm >> leak)),  racc = Vs - sum Js_i q'_i (exact, tacc_t)
//   sweeps x joints: g = <Js_i, cvt<tw_t>(racc)>, gk = cvt_shr<gk_t>(g, k_i),
//                    qn = clamp(cvt(q'_i + gk c_i)), dq = cvt(qn - q'_i), racc -= Js_i dq
//   r = cvt<tw_t>(racc), flags (limit / velocity limit active), q_next = clamp(cvt(q + q' dt))
// One shared registered multiplier (ts_mul) under a sequencer that issues a product whenever it
// can: each product carries a tag {valid, sink, joint, row} through delay lines as long as the
// multiplier and a rounder, and the tag says where its result goes.  The per-joint preparation
// runs as streams over all joints (columns, |Js_j|^2 with the normalisation behind it, e, y, c,
// the bounds, warm start and racc), the coordinate steps overlap a step's residual update with
// the next step's dot, and the integration is a stream too; cycles per solve
// 50 + 9 MLAT + 24 n + sweeps n (3 MLAT + 24), whatever the data (docs/rtl/ts_core_solve.md).
// Every narrowing is a ts_round_sat (the model's cvt: AP_RND + AP_SAT with the flag).
//
// Configuration (raw words of the model's formats in the low bits of in_cfg_data; write while
// idle): address {global, joint[JI_W-1:0], field[3:0]}
//   global = 0, joint j: field 0 lo (angle_t), 1 hi (angle_t), 2 vmax (qd_t), 3 mu (mu_t),
//                        4 bit 0: limited
//   global = 1:          field 0 L (lchar_t), 1 klim (klim_t), 2 dt (dt_t), 3 sweeps (unsigned,
//                        SW_W bits), 4 warm_leak (shift 0..31)
// Per-solve inputs (in_x_we / in_x_addr / in_x_data, same address layout):
//   global = 0, joint j: field 0-2 J omega rows x y z (jw_t), 3-5 J v rows (jv_t),
//                        6 q (angle_t), 7 warm start q'_warm (qd_t)
//   global = 1:          field 0-5 V (omega x y z: vel_t; v x y z: vel_t)
// in_start (while idle) with in_n (1..NMAX joints) runs one solve: out_busy until out_done (one
// cycle pulse); then out_qd (qd_t per joint), out_q_next (angle_t), out_r (tw_t, rows omega; v)
// and out_flags (the model's Status bits: 0 ST_OVF_ANGLE, 8 ST_OVF_SOLVER, 16 ST_LIMIT_ACTIVE,
// 17 ST_VLIMIT_ACTIVE) hold until the next start.  Joint j of a flat bus: bits [j*W +: W].
// Widths: every *_W parameter below is derived from CONFIG (0 default, 1 compact); do not override.
// Language: Verilog 2005
`resetall
`timescale 1ns / 1ps
`default_nettype none

module ts_core_solve #(
  // Largest joint count
  parameter NMAX = 8,
  // Number configuration: 0 default, 1 compact
  parameter CONFIG = 0,
  // Reciprocal seed table memory file (rtl/ts_recip_rom_<config>.mem)
  parameter ROM_FILE = "ts_recip_rom_default.mem",
  // Multiplier implementation: "GENERIC" or "ECP5" (see ts_mul)
  parameter TARGET = "GENERIC",
  // ECP5 wide products on three MULT18X18D (see ts_mul)
  parameter MUL3 = 0,
  // Sweep count width
  parameter SW_W = 16,
  // Joint index width: derived from NMAX, do not override
  parameter JI_W = (NMAX > 1) ? $clog2(NMAX) : 1,
  // Width of angle_t: derived from CONFIG, do not override
  parameter ANG_W = (CONFIG == 0) ? 32 : 18,
  // Width of qd_t: derived from CONFIG, do not override
  parameter QD_W = (CONFIG == 0) ? 27 : 18,
  // Width of tw_t: derived from CONFIG, do not override
  parameter TW_W = (CONFIG == 0) ? 27 : 18,
  // Data bus width of both write ports (widest format of the configuration): derived, do not override
  parameter CD_W = (CONFIG == 0) ? 32 : 18
) (
  input  wire                      clk,
  input  wire                      rst,
  // configuration write port
  input  wire                      in_cfg_we,
  input  wire [JI_W+4:0]           in_cfg_addr,
  input  wire [CD_W-1:0]           in_cfg_data,
  // per-solve inputs (J, V, q, warm start)
  input  wire                      in_x_we,
  input  wire [JI_W+4:0]           in_x_addr,
  input  wire [CD_W-1:0]           in_x_data,
  // control
  input  wire                      in_start,
  input  wire [JI_W:0]             in_n,
  output reg                       out_busy,
  output reg                       out_done,
  // results
  output wire [NMAX*QD_W-1:0]      out_qd,
  output wire [NMAX*ANG_W-1:0]     out_q_next,
  output reg  [6*TW_W-1:0]         out_r,
  output reg  [31:0]               out_flags
);

  `include "ts_common.vh"

  // ---- formats of the model (tensor_servo._model.formats; tb/ts_core_solve checks them) -------
  localparam TS_ANGLE_W = (CONFIG == 0) ? 32 : 18;
  localparam TS_ANGLE_F = (CONFIG == 0) ? 28 : 14;
  localparam TS_JW_W = (CONFIG == 0) ? 27 : 18;
  localparam TS_JW_F = (CONFIG == 0) ? 24 : 15;
  localparam TS_JV_W = (CONFIG == 0) ? 27 : 18;
  localparam TS_JV_F = (CONFIG == 0) ? 22 : 14;
  localparam TS_VEL_W = (CONFIG == 0) ? 27 : 18;
  localparam TS_VEL_F = (CONFIG == 0) ? 21 : 12;
  localparam TS_LCHAR_W = (CONFIG == 0) ? 18 : 18;
  localparam TS_LCHAR_F = (CONFIG == 0) ? 15 : 15;
  localparam TS_JSC_W = (CONFIG == 0) ? 27 : 18;
  localparam TS_JSC_F = (CONFIG == 0) ? 22 : 13;
  localparam TS_TW_W = (CONFIG == 0) ? 27 : 18;
  localparam TS_TW_F = (CONFIG == 0) ? 21 : 12;
  localparam TS_QD_W = (CONFIG == 0) ? 27 : 18;
  localparam TS_QD_F = (CONFIG == 0) ? 21 : 12;
  localparam TS_GK_W = (CONFIG == 0) ? 27 : 18;
  localparam TS_GK_F = (CONFIG == 0) ? 20 : 11;
  localparam TS_MANT_W = (CONFIG == 0) ? 18 : 18;
  localparam TS_MANT_F = (CONFIG == 0) ? 16 : 16;
  localparam TS_RECIP_W = (CONFIG == 0) ? 18 : 18;
  localparam TS_RECIP_F = (CONFIG == 0) ? 16 : 16;
  localparam TS_MU_W = (CONFIG == 0) ? 18 : 18;
  localparam TS_MU_F = (CONFIG == 0) ? 16 : 16;
  localparam TS_STEP_W = (CONFIG == 0) ? 18 : 18;
  localparam TS_STEP_F = (CONFIG == 0) ? 16 : 16;
  localparam TS_KLIM_W = (CONFIG == 0) ? 27 : 18;
  localparam TS_KLIM_F = (CONFIG == 0) ? 12 : 3;
  localparam TS_QDIFF_W = (CONFIG == 0) ? 33 : 18;
  localparam TS_QDIFF_F = (CONFIG == 0) ? 28 : 13;
  localparam TS_DT_W = (CONFIG == 0) ? 32 : 18;
  localparam TS_DT_F = (CONFIG == 0) ? 35 : 21;
  localparam TS_TACC_W = (CONFIG == 0) ? 60 : 42;
  localparam TS_TACC_F = (CONFIG == 0) ? 43 : 25;
  localparam TS_RECIP_TABLE_BITS = (CONFIG == 0) ? 6 : 6;

  localparam T = TS_RECIP_TABLE_BITS;
  localparam AF = TS_ANGLE_F;
  localparam JWW = TS_JW_W;
  localparam JVW = TS_JV_W;
  localparam VLW = TS_VEL_W;
  localparam LCW = TS_LCHAR_W;
  localparam JSW = TS_JSC_W;
  localparam JSF = TS_JSC_F;
  localparam QDF = TS_QD_F;
  localparam TWF = TS_TW_F;
  localparam GKW = TS_GK_W;
  localparam GKF = TS_GK_F;
  localparam MNW = TS_MANT_W;
  localparam MNF = TS_MANT_F;
  localparam RCW = TS_RECIP_W;
  localparam RCF = TS_RECIP_F;
  localparam MUW = TS_MU_W;
  localparam STW = TS_STEP_W;
  localparam KLW = TS_KLIM_W;
  localparam QFW = TS_QDIFF_W;
  localparam DTW = TS_DT_W;
  localparam TAW = TS_TACC_W;
  localparam TAF = TS_TACC_F;
  localparam RL = ts_round_lat(1);

  // e_t = num<recip_t::W, recip_t::I - T>
  localparam EW = RCW;
  localparam EF = RCF + T;
  // |Js_i|^2 and <Js_i, r>: exact sums of six products, 5 more integer bits than one product
  localparam DPF = 2 * JSF;
  localparam DW = 2 * JSW + 5;
  localparam GPF = JSF + TWF;
  localparam GW = JSW + TW_W + 5;
  localparam ACW = ts_max(DW, GW);
  localparam KW = 8;
  // shared multiplier: a in {L, Js, m, y0, mu, klim, gk, q'}, b in {jw, vel, Js, y0, e, y, qdiff,
  // q'/dq, ro, c, dt}
  localparam MAW = ts_max(ts_max(ts_max(LCW, JSW), ts_max(MNW, RCW)), ts_max(ts_max(MUW, KLW), ts_max(GKW, QD_W)));
  localparam MBW = ts_max(ts_max(ts_max(JWW, VLW), ts_max(JSW, EW)), ts_max(ts_max(QFW, QD_W), ts_max(TW_W, ts_max(STW, DTW))));
  localparam PW = MAW + MBW;
  localparam MLAT = ts_mul_lat(MAW, MBW);
  // klim (limit - q)
  localparam PLW = KLW + QFW;
  localparam PLF = TS_KLIM_F + TS_QDIFF_F;
  localparam CMW = ts_max(PLW, QD_W + PLF - QDF) + 1;
  // racc - Js_i dq (exact) before cvt<tacc_t>
  localparam RPF = JSF + QDF;
  localparam RSF = ts_max(TAF, RPF);
  localparam RIW = ts_max(TAW - TAF, JSW + QD_W - RPF) + 1 + RSF;
  // q' + gk c before cvt<qd_t>
  localparam QPF = GKF + TS_STEP_F;
  localparam QSF = ts_max(QDF, QPF);
  localparam QIW = ts_max(QD_W - QDF, GKW + STW - QPF) + 1 + QSF;
  // q + q' dt before cvt<angle_t>
  localparam NPF = QDF + TS_DT_F;
  localparam NSF = ts_max(AF, NPF);
  localparam NIW = ts_max(ANG_W - AF, QD_W + DTW - NPF) + 1 + NSF;
  // 1 - m y0 and y0 + y0 e
  localparam EIW = MNW + RCW + 1;
  localparam YIW = RCW + ts_max(EF, EW) + 1;
  // cvt_shr<gk_t>(g, k): right shift s = GPF + k - GKF, k >= -DPF; left-aligned by GLS so the
  // variable shift t = s + GLS is never negative
  localparam GS_MIN = GPF - DPF - GKF;
  localparam GLS = (GS_MIN < 0) ? -GS_MIN : 0;
  localparam GXW = GW + GLS + 1;
  localparam TOFF = GPF - GKF + GLS;
  localparam [9:0] TOFF10 = TOFF;
  localparam [KW-1:0] DPF_K = DPF;
  localparam [7:0] ML8 = MLAT[7:0];

  generate
    if ((ANG_W != TS_ANGLE_W) || (QD_W != TS_QD_W) || (TW_W != TS_TW_W)) begin : g_bad_width
      // Elaboration error: a port width parameter was overridden.
      ts_core_solve_port_width_parameters_must_not_be_overridden u_error ();
    end
  endgenerate

  // ---- storage ---------------------------------------------------------------------------------
  // configuration
  // (per joint, read at col: lower, upper, vmax and mu in ts_ram memories, below, as are q, the warm
  // start and the state c, k and the bounds; every word a tick reads is written before)
  reg                    cfg_lim   [0:NMAX-1];
  reg signed [LCW-1:0]   cfg_L;
  reg signed [KLW-1:0]   cfg_klim;
  reg signed [DTW-1:0]   cfg_dt;
  reg [SW_W-1:0]         cfg_sweeps;
  reg [4:0]              cfg_leak;
  // per-solve inputs: J rows (omega at {j, 0..2}, v at {j, 4..6}), q, warm start, V
  reg signed [JWW-1:0]   x_jw      [0:(4 << JI_W)-1];   // {joint, row}; not reset (RAM)
  reg signed [JVW-1:0]   x_jv      [0:(4 << JI_W)-1];
  reg signed [VLW-1:0]   x_vw      [0:3];
  reg signed [VLW-1:0]   x_vv      [0:3];
  // solver state
  reg signed [JSW-1:0]   js        [0:(8 << JI_W)-1];   // {joint, row}; not reset (RAM)
  reg signed [TW_W-1:0]  vs        [0:5];
  reg                    blo_pos   [0:NMAX-1];
  reg                    bhi_pos   [0:NMAX-1];
  reg signed [QD_W-1:0]  qd        [0:NMAX-1];
  reg signed [ANG_W-1:0] qnext     [0:NMAX-1];
  reg signed [TAW-1:0]   racc      [0:5];

  // ---- configuration and input write ports ------------------------------------------------------
  wire            cfg_g = in_cfg_addr[JI_W+4];
  wire [JI_W-1:0] cfg_j = in_cfg_addr[JI_W+3:4];
  wire [3:0]      cfg_f = in_cfg_addr[3:0];
  wire            x_g = in_x_addr[JI_W+4];
  wire [JI_W-1:0] x_j = in_x_addr[JI_W+3:4];
  wire [3:0]      x_f = in_x_addr[3:0];
  wire [1:0]      x_f3 = x_f[1:0] - 2'd3;   // v row of fields 3-5 (self-determined 2-bit index)
  integer ci, xi, ri;

  always @(posedge clk) begin
    if (rst) begin
      for (ci = 0; ci < NMAX; ci = ci + 1) cfg_lim[ci] <= 1'b0;
      cfg_L <= {LCW{1'b0}};
      cfg_klim <= {KLW{1'b0}};
      cfg_dt <= {DTW{1'b0}};
      cfg_sweeps <= {SW_W{1'b0}};
      cfg_leak <= 5'd0;
    end else if (in_cfg_we) begin
      if (!cfg_g) begin
        case (cfg_f)
          4'd4: cfg_lim[cfg_j] <= in_cfg_data[0];
          default: ;
        endcase
      end else begin
        case (cfg_f)
          4'd0: cfg_L <= in_cfg_data[LCW-1:0];
          4'd1: cfg_klim <= in_cfg_data[KLW-1:0];
          4'd2: cfg_dt <= in_cfg_data[DTW-1:0];
          4'd3: cfg_sweeps <= in_cfg_data[SW_W-1:0];
          4'd4: cfg_leak <= in_cfg_data[4:0];
          default: ;
        endcase
      end
    end
  end

  always @(posedge clk) begin
    if (rst) begin
      for (xi = 0; xi < 4; xi = xi + 1) begin
        x_vw[xi] <= {VLW{1'b0}};
        x_vv[xi] <= {VLW{1'b0}};
      end
    end else if (in_x_we) begin
      if (!x_g) begin
        if (x_f < 4'd3)       x_jw[{x_j, x_f[1:0]}] <= in_x_data[JWW-1:0];
        else if (x_f < 4'd6)  x_jv[{x_j, x_f3}] <= in_x_data[JVW-1:0];
      end else begin
        if (x_f < 4'd3)       x_vw[x_f[1:0]] <= in_x_data[VLW-1:0];
        else if (x_f < 4'd6)  x_vv[x_f3] <= in_x_data[VLW-1:0];
      end
    end
  end

  // per-joint words of joint col (ts_ram instances before the sequencer)
  wire signed [ANG_W-1:0] cl_lo, cl_hi, xc_q;
  wire signed [QD_W-1:0]  cl_vmax, xc_warm, blo_c, bhi_c;
  wire signed [MUW-1:0]   cl_mu;
  wire signed [STW-1:0]   cst_c;
  wire signed [KW-1:0]    kst_c;
  // preparation streams: per joint the normalised |Js_j|^2 ({zero, k, m, y0}) read at col (the
  // issue), at the product's joint and at the rounded product's joint; e_j, then y_j, at col; the
  // position differences and vmin at col and at the bound decision's joint; vmax there
  localparam NRW = 1 + KW + MNF + 1 + RCW;
  localparam DDW = QD_W + 2 * QFW;
  wire [NRW-1:0]          nrm_c, nrm_p, nrm_r;
  wire [MNF:0]            mr_c = nrm_c[RCW +: MNF + 1];
  wire signed [RCW-1:0]   y0_c = nrm_c[RCW-1:0];
  wire signed [RCW-1:0]   y0_p = nrm_p[RCW-1:0];
  wire signed [KW-1:0]    k_r = nrm_r[RCW + MNF + 1 +: KW];
  wire                    dz_r = nrm_r[NRW-1];
  wire unused_nrm = ^{nrm_c[NRW-1:RCW + MNF + 1], nrm_p[NRW-1:RCW], nrm_r[RCW + MNF:0]};
  wire signed [RCW-1:0]   ey_c;
  wire [DDW-1:0]          dd_c, dd_b;
  wire signed [QFW-1:0]   dlo_c = dd_c[QFW-1:0];
  wire signed [QFW-1:0]   dhi_c = dd_c[QFW +: QFW];
  wire signed [QD_W-1:0]  vmin_b = dd_b[2 * QFW +: QD_W];
  wire unused_dd = ^{dd_c[DDW-1:2 * QFW], dd_b[2 * QFW - 1:0]};
  wire signed [QD_W-1:0]  vmax_b;
  // the integration stream: q at the product's joint, the limits, bounds and vmax at the rounded one
  wire signed [ANG_W-1:0] xq_p, lo_r1, hi_r1;
  wire signed [QD_W-1:0]  blo_r, bhi_r, vmax_r;

  // ---- sequencer state ---------------------------------------------------------------------------
  localparam [4:0] S_IDLE = 5'd0, S_WAIT = 5'd1, S_ISSUE = 5'd2, S_RINIT = 5'd3, S_STREAM = 5'd4,
                   S_PD = 5'd6, S_PE = 5'd7, S_PY = 5'd8, S_PC = 5'd9, S_PB = 5'd10,
                   S_PW0 = 5'd11, S_PW1 = 5'd12, S_PW2 = 5'd14, S_PW = 5'd13,
                   S_SWEEP = 5'd16, S_GSH = 5'd17, S_GK = 5'd18, S_QN = 5'd19, S_DQ = 5'd20,
                   S_NEXTJ = 5'd21, S_QNX = 5'd22, S_DONE = 5'd24;
  // product sinks: bursts of six products of one joint (target or columns, sweep dot, residual
  // update) and the streams of the preparation over all joints (|Js_j|^2, e_j, y_j, c_j, bounds)
  // (the target V: M_T; the integration stream: M_X).  Each product carries its sink in its tag,
  // so a burst or stream can start while the one before still drains.
  localparam [3:0] M_COL = 4'd0, M_DOT = 4'd1, M_RUPD = 4'd2, M_D = 4'd3, M_E = 4'd4, M_Y = 4'd5,
                   M_C = 4'd6, M_B = 4'd7, M_T = 4'd8, M_X = 4'd9;
  // multiplier operand selects
  localparam [3:0] A_L = 4'd0, A_JS = 4'd1, A_M = 4'd2, A_Y0 = 4'd3, A_MU = 4'd4, A_KLIM = 4'd5,
                   A_GK = 4'd6, A_QD = 4'd7;
  localparam [3:0] B_JW = 4'd0, B_VW = 4'd1, B_JS = 4'd2, B_E = 4'd3, B_Y = 4'd4, B_DLO = 4'd5,
                   B_DHI = 4'd6, B_RB = 4'd7, B_RO = 4'd8, B_C = 4'd9, B_DT = 4'd10, B_Y0 = 4'd11;

  reg [4:0]       state, ret, bret;
  reg [7:0]       wt;
  reg [3:0]       mode;
  reg [2:0]       rpj;           // stream: products per joint minus one (rows 0..rpj)
  reg [4:0]       snext;         // stream: state after its drain
  reg [7:0]       sdrain;        // stream: drain cycles after the last product is issued
  reg [2:0]       bi;            // burst row
  reg [7:0]       bdrain;
  reg [JI_W-1:0]  col;
  reg [JI_W:0]    n_q;
  reg [JI_W:0]    pj;            // warm-start stream: the joint issued (col leads it)
  reg [SW_W-1:0]  sweep;
  reg [3:0]       asel, bsel;
  localparam TGW = 8 + JI_W;
  reg [TGW-1:0]   tag_q;         // {valid, sink, joint, row} of the product issued this cycle
  reg signed [ACW-1:0] acc;
  reg signed [PLW-1:0] plo_q, phi_q;
  reg signed [QD_W-1:0] rb_q;    // residual-update multiplier (q'_i at init, dq in the sweeps)
  reg signed [GXW-1:0] gsh_q;
  reg signed [GKW-1:0] gk_q;
  reg signed [QD_W-1:0] qnc_q;
  reg [31:0]      flags;

  wire [1:0] jrow = (bi < 3'd3) ? bi[1:0] : 2'd0;

  // ---- shared multiplier -------------------------------------------------------------------------
  // a operands sign-extended to MAW bits
  wire signed [MAW-1:0] a_L, a_js, a_m, a_y0, a_mu, a_klim, a_gk, a_qd;
  // (the warm-start stream reads its joint's column at pj: col runs ahead there)
  wire [JI_W-1:0] js_j = (state == S_PW) ? pj[JI_W-1:0] : col;
  wire signed [JSW-1:0] js_bi = js[{js_j, bi}];
  ts_resize #(.IN_W(LCW), .LSH(0), .OUT_W(MAW)) u_aL (.in(cfg_L), .out(a_L));
  ts_resize #(.IN_W(JSW), .LSH(0), .OUT_W(MAW)) u_ajs (.in(js_bi), .out(a_js));
  ts_resize #(.IN_W(MNF + 2), .LSH(0), .OUT_W(MAW)) u_am (.in({1'b0, mr_c}), .out(a_m));
  ts_resize #(.IN_W(RCW), .LSH(0), .OUT_W(MAW)) u_ay0 (.in(y0_c), .out(a_y0));
  ts_resize #(.IN_W(MUW), .LSH(0), .OUT_W(MAW)) u_amu (.in(cl_mu), .out(a_mu));
  ts_resize #(.IN_W(KLW), .LSH(0), .OUT_W(MAW)) u_akl (.in(cfg_klim), .out(a_klim));
  ts_resize #(.IN_W(GKW), .LSH(0), .OUT_W(MAW)) u_agk (.in(gk_q), .out(a_gk));
  ts_resize #(.IN_W(QD_W), .LSH(0), .OUT_W(MAW)) u_aqd (.in(qd[col]), .out(a_qd));
  // b operands sign-extended to MBW bits
  wire signed [QFW-1:0] dlo, dhi;        // cvt<qdiff_t>(lo - q), cvt<qdiff_t>(hi - q)
  wire [6*TW_W-1:0] ro_f;               // cvt<tw_t>(racc), row a at [a*TW_W +: TW_W]
  wire signed [MBW-1:0] b_jw, b_vw, b_js, b_e, b_y, b_dlo, b_dhi, b_rb, b_ro, b_c, b_dt, b_y0;
  wire signed [TW_W-1:0] ro_w [0:7];      // row select without a multiplier on the index
  wire signed [TW_W-1:0] ro_bi = ro_w[bi];
  ts_resize #(.IN_W(JWW), .LSH(0), .OUT_W(MBW)) u_bjw (.in(x_jw[{col, jrow}]), .out(b_jw));
  ts_resize #(.IN_W(VLW), .LSH(0), .OUT_W(MBW)) u_bvw (.in(x_vw[jrow]), .out(b_vw));
  ts_resize #(.IN_W(JSW), .LSH(0), .OUT_W(MBW)) u_bjs (.in(js_bi), .out(b_js));
  // e_j (stream y) and y_j (stream c) are the same memory word, read at col
  ts_resize #(.IN_W(EW), .LSH(0), .OUT_W(MBW)) u_be (.in(ey_c), .out(b_e));
  assign b_y = b_e;
  ts_resize #(.IN_W(RCW), .LSH(0), .OUT_W(MBW)) u_by0 (.in(y0_c), .out(b_y0));
  ts_resize #(.IN_W(QFW), .LSH(0), .OUT_W(MBW)) u_bdlo (.in(dlo_c), .out(b_dlo));
  ts_resize #(.IN_W(QFW), .LSH(0), .OUT_W(MBW)) u_bdhi (.in(dhi_c), .out(b_dhi));
  ts_resize #(.IN_W(QD_W), .LSH(0), .OUT_W(MBW)) u_brb (.in(rb_q), .out(b_rb));
  ts_resize #(.IN_W(TW_W), .LSH(0), .OUT_W(MBW)) u_bro (.in(ro_bi), .out(b_ro));
  ts_resize #(.IN_W(STW), .LSH(0), .OUT_W(MBW)) u_bc (.in(cst_c), .out(b_c));
  ts_resize #(.IN_W(DTW), .LSH(0), .OUT_W(MBW)) u_bdt (.in(cfg_dt), .out(b_dt));

  reg signed [MAW-1:0] mul_a;
  reg signed [MBW-1:0] mul_b;
  wire signed [PW-1:0] p;
  ts_mul #(.A_W(MAW), .B_W(MBW), .TARGET(TARGET), .MUL3(MUL3)) u_mul (
    .clk(clk), .rst(rst), .a(mul_a), .b(mul_b), .p(p));

  reg signed [MAW-1:0] a_sel;
  reg signed [MBW-1:0] b_sel;
  always @* begin
    case (asel)
      A_L:     a_sel = a_L;
      A_JS:    a_sel = a_js;
      A_M:     a_sel = a_m;
      A_Y0:    a_sel = a_y0;
      A_MU:    a_sel = a_mu;
      A_KLIM:  a_sel = a_klim;
      A_GK:    a_sel = a_gk;
      default: a_sel = a_qd;
    endcase
    case (bsel)
      B_JW:    b_sel = (bi < 3'd3) ? b_jw : {MBW{1'b0}};
      B_VW:    b_sel = (bi < 3'd3) ? b_vw : {MBW{1'b0}};
      B_JS:    b_sel = b_js;
      B_E:     b_sel = b_e;
      B_Y:     b_sel = b_y;
      B_DLO:   b_sel = bi[0] ? b_dhi : b_dlo;    // the bounds stream: row 0 lo - q, row 1 hi - q
      B_DHI:   b_sel = b_dhi;
      B_RB:    b_sel = b_rb;
      B_RO:    b_sel = b_ro;
      B_C:     b_sel = b_c;
      B_DT:    b_sel = b_dt;
      default: b_sel = b_y0;
    endcase
  end

  // product tags: {valid, sink, joint, row} at the product (tag_p) and after a rounder (tag_r)
  wire [TGW-1:0] tag_p, tag_r;
  ts_delay #(.W(TGW), .DEPTH(MLAT)) u_tagp (.clk(clk), .rst(rst), .din(tag_q), .dout(tag_p));
  // (tag_r1: one cycle before tag_r, for reads that are registered into tag_r's cycle)
  wire [TGW-1:0] tag_r1;
  ts_delay #(.W(TGW), .DEPTH(RL - 1)) u_tagr1 (.clk(clk), .rst(rst), .din(tag_p), .dout(tag_r1));
  ts_delay #(.W(TGW), .DEPTH(1)) u_tagr (.clk(clk), .rst(rst), .din(tag_r1), .dout(tag_r));
  wire [JI_W-1:0] tj_r1 = tag_r1[3 +: JI_W];
  wire unused_tag_r1 = ^{tag_r1[TGW-1:3 + JI_W], tag_r1[2:0]};
  wire       tv_p = tag_p[TGW-1];
  wire       tv_r = tag_r[TGW-1];
  wire [JI_W-1:0] tj_p = tag_p[3 +: JI_W];
  wire [JI_W-1:0] tj_r = tag_r[3 +: JI_W];
  wire [3:0] tm_p = tag_p[3 + JI_W +: 4];
  wire [3:0] tm_r = tag_r[3 + JI_W +: 4];
  wire [2:0] row_p = tag_p[2:0];
  wire [2:0] row_r = tag_r[2:0];
  wire [1:0] vrow_p = (row_p >= 3'd3) ? (row_p[1:0] - 2'd3) : 2'd0;

  // ---- rounders (the model's cvt) --------------------------------------------------------------
  // columns and target: cvt<jsc_t>(L w), cvt<jsc_t>(v), cvt<tw_t>(L V_w), cvt<tw_t>(V_v)
  wire signed [LCW+JWW-1:0] p_lj;
  wire signed [LCW+VLW-1:0] p_lv;
  ts_resize #(.IN_W(PW), .LSH(0), .OUT_W(LCW + JWW)) u_plj (.in(p), .out(p_lj));
  ts_resize #(.IN_W(PW), .LSH(0), .OUT_W(LCW + VLW)) u_plv (.in(p), .out(p_lv));
  wire signed [JSW-1:0] jsl_o, jsv_o;
  wire signed [TW_W-1:0] twl_o, twv_o;
  wire jsl_s, jsv_s, twl_s, twv_s;
  ts_round_sat #(.IN_W(LCW + JWW), .SHIFT(TS_LCHAR_F + TS_JW_F - JSF), .OUT_W(JSW), .SAT(1))
    u_r_jsl (.clk(clk), .rst(rst), .in_x(p_lj), .out_y(jsl_o), .out_sat(jsl_s));
  ts_round_sat #(.IN_W(JVW), .SHIFT(TS_JV_F - JSF), .OUT_W(JSW), .SAT(1))
    u_r_jsv (.clk(clk), .rst(rst), .in_x(x_jv[{tj_p, vrow_p}]), .out_y(jsv_o), .out_sat(jsv_s));
  ts_round_sat #(.IN_W(LCW + VLW), .SHIFT(TS_LCHAR_F + TS_VEL_F - TWF), .OUT_W(TW_W), .SAT(1))
    u_r_twl (.clk(clk), .rst(rst), .in_x(p_lv), .out_y(twl_o), .out_sat(twl_s));
  ts_round_sat #(.IN_W(VLW), .SHIFT(TS_VEL_F - TWF), .OUT_W(TW_W), .SAT(1))
    u_r_twv (.clk(clk), .rst(rst), .in_x(x_vv[vrow_p]), .out_y(twv_o), .out_sat(twv_s));

  // reciprocal: e = cvt<e_t>(1 - m y0), y = cvt<recip_t>(y0 + y0 e), c = cvt<step_t>(mu y)
  wire signed [EIW-1:0] p_e, one_e, e_in;
  ts_resize #(.IN_W(PW), .LSH(0), .OUT_W(EIW)) u_pe (.in(p), .out(p_e));
  assign one_e = {{(EIW - 1){1'b0}}, 1'b1} <<< (MNF + RCF);
  assign e_in = one_e - p_e;
  wire signed [EW-1:0] e_o;
  wire e_s;
  ts_round_sat #(.IN_W(EIW), .SHIFT(MNF + RCF - EF), .OUT_W(EW), .SAT(1))
    u_r_e (.clk(clk), .rst(rst), .in_x(e_in), .out_y(e_o), .out_sat(e_s));
  wire signed [YIW-1:0] p_y, y0_al, y_in;
  ts_resize #(.IN_W(PW), .LSH(0), .OUT_W(YIW)) u_py (.in(p), .out(p_y));
  ts_resize #(.IN_W(RCW), .LSH(EF), .OUT_W(YIW)) u_y0al (.in(y0_p), .out(y0_al));
  assign y_in = y0_al + p_y;
  wire signed [RCW-1:0] y_o;
  wire y_s;
  ts_round_sat #(.IN_W(YIW), .SHIFT(EF), .OUT_W(RCW), .SAT(1))
    u_r_y (.clk(clk), .rst(rst), .in_x(y_in), .out_y(y_o), .out_sat(y_s));
  wire signed [MUW+RCW-1:0] p_c;
  ts_resize #(.IN_W(PW), .LSH(0), .OUT_W(MUW + RCW)) u_pc (.in(p), .out(p_c));
  wire signed [STW-1:0] c_o;
  wire c_s;
  ts_round_sat #(.IN_W(MUW + RCW), .SHIFT(TS_MU_F + RCF - TS_STEP_F), .OUT_W(STW), .SAT(1))
    u_r_c (.clk(clk), .rst(rst), .in_x(p_c), .out_y(c_o), .out_sat(c_s));

  // bounds: vmin = cvt<qd_t>(-vmax), cvt<qdiff_t>(lo - q), cvt<qdiff_t>(hi - q), cvt<qd_t>(klim d)
  wire signed [QD_W:0] vmax_x;
  ts_resize #(.IN_W(QD_W), .LSH(0), .OUT_W(QD_W + 1)) u_vmx (.in(cl_vmax), .out(vmax_x));
  wire signed [QD_W:0] nvmax = -vmax_x;
  wire signed [QD_W-1:0] vmin_o;
  wire vmin_s;
  ts_round_sat #(.IN_W(QD_W + 1), .SHIFT(0), .OUT_W(QD_W), .SAT(1))
    u_r_vmin (.clk(clk), .rst(rst), .in_x(nvmax), .out_y(vmin_o), .out_sat(vmin_s));
  wire signed [ANG_W:0] lo_x, hi_x, q_x;
  ts_resize #(.IN_W(ANG_W), .LSH(0), .OUT_W(ANG_W + 1)) u_lox (.in(cl_lo), .out(lo_x));
  ts_resize #(.IN_W(ANG_W), .LSH(0), .OUT_W(ANG_W + 1)) u_hix (.in(cl_hi), .out(hi_x));
  ts_resize #(.IN_W(ANG_W), .LSH(0), .OUT_W(ANG_W + 1)) u_qx (.in(xc_q), .out(q_x));
  wire signed [ANG_W:0] dlo_in = lo_x - q_x;
  wire signed [ANG_W:0] dhi_in = hi_x - q_x;
  wire dlo_s, dhi_s;
  ts_round_sat #(.IN_W(ANG_W + 1), .SHIFT(AF - TS_QDIFF_F), .OUT_W(QFW), .SAT(1))
    u_r_dlo (.clk(clk), .rst(rst), .in_x(dlo_in), .out_y(dlo), .out_sat(dlo_s));
  ts_round_sat #(.IN_W(ANG_W + 1), .SHIFT(AF - TS_QDIFF_F), .OUT_W(QFW), .SAT(1))
    u_r_dhi (.clk(clk), .rst(rst), .in_x(dhi_in), .out_y(dhi), .out_sat(dhi_s));
  wire signed [PLW-1:0] p_pl;
  ts_resize #(.IN_W(PW), .LSH(0), .OUT_W(PLW)) u_ppl (.in(p), .out(p_pl));
  wire signed [QD_W-1:0] plo_o, phi_o;
  wire plo_s, phi_s;
  ts_round_sat #(.IN_W(PLW), .SHIFT(PLF - QDF), .OUT_W(QD_W), .SAT(1))
    u_r_plo (.clk(clk), .rst(rst), .in_x(plo_q), .out_y(plo_o), .out_sat(plo_s));
  ts_round_sat #(.IN_W(PLW), .SHIFT(PLF - QDF), .OUT_W(QD_W), .SAT(1))
    u_r_phi (.clk(clk), .rst(rst), .in_x(phi_q), .out_y(phi_o), .out_sat(phi_s));
  // exact comparisons of the position bounds with the velocity interval
  wire signed [CMW-1:0] vmin_c, vmax_c, plo_c, phi_c;
  ts_resize #(.IN_W(QD_W), .LSH(PLF - QDF), .OUT_W(CMW)) u_vminc (.in(vmin_b), .out(vmin_c));
  ts_resize #(.IN_W(QD_W), .LSH(PLF - QDF), .OUT_W(CMW)) u_vmaxc (.in(vmax_b), .out(vmax_c));
  ts_resize #(.IN_W(PLW), .LSH(0), .OUT_W(CMW)) u_ploc (.in(plo_q), .out(plo_c));
  ts_resize #(.IN_W(PLW), .LSH(0), .OUT_W(CMW)) u_phic (.in(phi_q), .out(phi_c));

  // residual: racc = cvt<tacc_t>(racc - Js_i b) at the product of a residual-update burst
  wire signed [RIW-1:0] racc_al, p_ral, racc_in;
  wire signed [TAW-1:0] racc_p = racc[row_p];
  ts_resize #(.IN_W(TAW), .LSH(RSF - TAF), .OUT_W(RIW)) u_rcal (.in(racc_p), .out(racc_al));
  ts_resize #(.IN_W(PW), .LSH(RSF - RPF), .OUT_W(RIW)) u_pral (.in(p), .out(p_ral));
  assign racc_in = racc_al - p_ral;
  wire signed [TAW-1:0] racc_o;
  wire racc_s;
  ts_round_sat #(.IN_W(RIW), .SHIFT(RSF - TAF), .OUT_W(TAW), .SAT(1))
    u_r_racc (.clk(clk), .rst(rst), .in_x(racc_in), .out_y(racc_o), .out_sat(racc_s));
  // ro = cvt<tw_t>(racc) per row (the sweep operand and, at the end, r); racc init = vs exactly
  wire [5:0] ro_s;
  wire [6*TAW-1:0] vs_al;
  genvar gr;
  generate
    for (gr = 0; gr < 6; gr = gr + 1) begin : g_row
      ts_round_sat #(.IN_W(TAW), .SHIFT(TAF - TWF), .OUT_W(TW_W), .SAT(1))
        u_r_ro (.clk(clk), .rst(rst), .in_x(racc[gr]), .out_y(ro_f[gr*TW_W +: TW_W]), .out_sat(ro_s[gr]));
      ts_resize #(.IN_W(TW_W), .LSH(TAF - TWF), .OUT_W(TAW)) u_vsal (.in(vs[gr]), .out(vs_al[gr*TAW +: TAW]));
      assign ro_w[gr] = ro_f[gr*TW_W +: TW_W];
    end
    assign ro_w[6] = {TW_W{1'b0}};
    assign ro_w[7] = {TW_W{1'b0}};
  endgenerate

  // g 2^-k: t = s + GLS >= 0, round half up then arithmetic shift (cvt_shr), saturate in u_r_gk
  wire signed [GW-1:0] g_w;
  ts_resize #(.IN_W(ACW), .LSH(0), .OUT_W(GW)) u_gw (.in(acc), .out(g_w));
  wire signed [GXW-1:0] g_x;
  ts_resize #(.IN_W(GW), .LSH(GLS), .OUT_W(GXW)) u_gx (.in(g_w), .out(g_x));
  // The shift and its rounding half come from joint col's k_i, registered every cycle: S_GSH
  // follows the dot burst of the same col, so the variable-index read and the decoder leave the
  // path into gsh_q (no cycle added).
  wire signed [9:0] t_s = {{(10 - KW){kst_c[KW-1]}}, kst_c} + TOFF10;
  wire [6:0] t_u = t_s[6:0];
  wire [GXW-1:0] one_g = {{(GXW - 1){1'b0}}, 1'b1};
  wire signed [GXW-1:0] half_g = (t_u == 7'd0) ? {GXW{1'b0}} : $signed(one_g << (t_u - 7'd1));
  reg  [6:0] t_uq;
  reg  signed [GXW-1:0] half_gq;
  always @(posedge clk) begin
    t_uq <= t_u;
    half_gq <= half_g;
  end
  wire signed [GXW-1:0] gsh = (g_x + half_gq) >>> t_uq;
  wire unused_t = ^t_s[9:7];
  wire signed [GKW-1:0] gk_o;
  wire gk_s;
  ts_round_sat #(.IN_W(GXW), .SHIFT(0), .OUT_W(GKW), .SAT(1))
    u_r_gk (.clk(clk), .rst(rst), .in_x(gsh_q), .out_y(gk_o), .out_sat(gk_s));

  // qn = cvt<qd_t>(q' + gk c), dq = cvt<qd_t>(qn - q')
  wire signed [QIW-1:0] qd_al, p_qal, qn_in;
  ts_resize #(.IN_W(QD_W), .LSH(QSF - QDF), .OUT_W(QIW)) u_qdal (.in(qd[col]), .out(qd_al));
  ts_resize #(.IN_W(PW), .LSH(QSF - QPF), .OUT_W(QIW)) u_pqal (.in(p), .out(p_qal));
  assign qn_in = qd_al + p_qal;
  wire signed [QD_W-1:0] qn_o;
  wire qn_s;
  ts_round_sat #(.IN_W(QIW), .SHIFT(QSF - QDF), .OUT_W(QD_W), .SAT(1))
    u_r_qn (.clk(clk), .rst(rst), .in_x(qn_in), .out_y(qn_o), .out_sat(qn_s));
  wire signed [QD_W:0] qnc_x, qd_x;
  ts_resize #(.IN_W(QD_W), .LSH(0), .OUT_W(QD_W + 1)) u_qncx (.in(qnc_q), .out(qnc_x));
  ts_resize #(.IN_W(QD_W), .LSH(0), .OUT_W(QD_W + 1)) u_qdx (.in(qd[col]), .out(qd_x));
  wire signed [QD_W:0] dq_in = qnc_x - qd_x;
  wire signed [QD_W-1:0] dq_o;
  wire dq_s;
  ts_round_sat #(.IN_W(QD_W + 1), .SHIFT(0), .OUT_W(QD_W), .SAT(1))
    u_r_dq (.clk(clk), .rst(rst), .in_x(dq_in), .out_y(dq_o), .out_sat(dq_s));

  // q_next = cvt<angle_t>(q + q' dt)
  wire signed [NIW-1:0] q_al, p_nal, qx_in;
  ts_resize #(.IN_W(ANG_W), .LSH(NSF - AF), .OUT_W(NIW)) u_qal (.in(xq_p), .out(q_al));
  ts_resize #(.IN_W(PW), .LSH(NSF - NPF), .OUT_W(NIW)) u_pnal (.in(p), .out(p_nal));
  assign qx_in = q_al + p_nal;
  wire signed [ANG_W-1:0] qx_o;
  wire qx_s;
  ts_round_sat #(.IN_W(NIW), .SHIFT(NSF - AF), .OUT_W(ANG_W), .SAT(1))
    u_r_qx (.clk(clk), .rst(rst), .in_x(qx_in), .out_y(qx_o), .out_sat(qx_s));

  // ---- bound decisions (the bounds stream) ------------------------------------------------------
  // Stage 0, the cycle after joint bj0's hi product: plo_q and phi_q hold klim (lo - q) and
  // klim (hi - q) of joint bj0, vmin_b and vmax_b its velocity interval; the exact comparisons.
  // Stage RL (the rounded cvt<qd_t>(plo), cvt<qd_t>(phi) of u_r_plo / u_r_phi): the choice, written
  // to u_bnd and blo_pos / bhi_pos (the model's solver_steps bounds).
  reg             bv0;
  reg [JI_W-1:0]  bj0;
  localparam BDW = 1 + JI_W + 5 + 2 * QD_W;
  wire [BDW-1:0] bd_0 = {bv0, bj0, cfg_lim[bj0], vmin_c < plo_c, vmax_c < plo_c, phi_c < vmax_c,
                         phi_c < vmin_c, vmax_b, vmin_b};
  wire [BDW-1:0] bd_2;
  ts_delay #(.W(BDW), .DEPTH(RL)) u_bd (.clk(clk), .rst(rst), .din(bd_0), .dout(bd_2));
  wire                   bv2 = bd_2[BDW-1];
  wire [JI_W-1:0]        bj2 = bd_2[2 * QD_W + 5 +: JI_W];
  wire                   lim2 = bd_2[2 * QD_W + 4];
  wire                   lo_c2 = bd_2[2 * QD_W + 3];    // vmin < plo: a position bound below
  wire                   lo_v2 = bd_2[2 * QD_W + 2];    // vmax < plo
  wire                   hi_c2 = bd_2[2 * QD_W + 1];    // phi < vmax: a position bound above
  wire                   hi_v2 = bd_2[2 * QD_W];        // phi < vmin
  wire signed [QD_W-1:0] vmax2 = bd_2[QD_W +: QD_W];
  wire signed [QD_W-1:0] vmin2 = bd_2[0 +: QD_W];
  wire                   lo_pos2 = lim2 && lo_c2;
  wire                   hi_pos2 = lim2 && hi_c2;
  wire signed [QD_W-1:0] lo2 = !lo_pos2 ? vmin2 : (lo_v2 ? vmax2 : plo_o);
  wire signed [QD_W-1:0] hi2 = !hi_pos2 ? vmax2 : (hi_v2 ? vmin2 : phi_o);
  wire                   bsat2 = (lo_pos2 && !lo_v2 && plo_s) || (hi_pos2 && !hi_v2 && phi_s);

  // ---- combinational helpers -------------------------------------------------------------------
  // leading one of d = |Js_j|^2 (>= 0) and the normalised mantissa, a pipeline behind the |Js_j|^2
  // stream: d_q (the sum, at its last product), then (N1) the leading one and the shift, (N2) the
  // mantissa, k and d = 0, (N3) the reciprocal seed, written to u_nrm at the joint
  reg  [DW-1:0]   d_q, d1_q;
  reg  [JI_W-1:0] dj_q, dj1_q, dj2_q;
  reg             dv_q, dv1_q, dv2_q;
  reg  [MNF:0]    mr2_q;
  reg  signed [KW-1:0] k2_q;
  reg             dz2_q;
  wire [DW-1:0] dval = d_q;
  // in two levels (the leading one of each 8-bit group, then the highest non-empty group): two
  // short priority chains instead of one DW long (the engine's critical path after the register
  // changes above)
  localparam NG = (DW + 7) / 8;
  wire [NG*8-1:0] dpad = {{(NG * 8 - DW){1'b0}}, dval};
  reg  [NG*3-1:0] gmsb;
  reg  [NG-1:0]   gany;
  reg  [6:0]      msb;
  integer bb, gg;
  always @* begin
    for (gg = 0; gg < NG; gg = gg + 1) begin
      gany[gg] = |dpad[gg*8 +: 8];
      gmsb[gg*3 +: 3] = 3'd0;
      for (bb = 0; bb < 8; bb = bb + 1)
        if (dpad[gg*8 + bb]) gmsb[gg*3 +: 3] = bb[2:0];
    end
    msb = 7'd0;
    for (gg = 0; gg < NG; gg = gg + 1)
      if (gany[gg]) msb = {gg[3:0], gmsb[gg*3 +: 3]};
  end
  // The leading one and the shift are registered (N1), so the detector and the subtraction leave
  // the path through the shifter (priority chain, subtraction and shifter in one cycle were the
  // solver's critical path, 14.7 ns post-route on LFE5U-85F -6).
  reg  [6:0] msb_q, lsh_q;
  wire [DW-1:0] dn = d1_q << lsh_q;
  wire unused_dn = ^dn[DW-MNF-2:0];
  wire signed [KW-1:0] k_new = $signed({1'b0, msb_q}) - DPF_K;

  // reciprocal seed table
  (* rom_style = "logic" *) reg [RCW-1:0] rom [0:(1 << T)-1];
  initial $readmemh(ROM_FILE, rom);
  wire [RCW-1:0] y0_new = rom[mr2_q[MNF-1 -: T]];

  always @(posedge clk) begin
    if (rst) begin
      d1_q <= {DW{1'b0}}; dj1_q <= {JI_W{1'b0}}; dj2_q <= {JI_W{1'b0}}; dv1_q <= 1'b0; dv2_q <= 1'b0;
      msb_q <= 7'd0; lsh_q <= 7'd0; mr2_q <= {(MNF + 1){1'b0}}; k2_q <= {KW{1'b0}}; dz2_q <= 1'b0;
    end else begin
      // N1
      msb_q <= msb;
      lsh_q <= 7'd0 + (DW - 1) - msb;
      d1_q <= d_q; dj1_q <= dj_q; dv1_q <= dv_q;
      // N2
      mr2_q <= dn[DW-1 -: MNF + 1];
      k2_q <= k_new;
      dz2_q <= (d1_q == {DW{1'b0}});
      dj2_q <= dj1_q; dv2_q <= dv1_q;
    end
  end

  // joint col's bounds registered every cycle (col is stable through a step of the sweeps; the warm
  // start stream sets col two cycles before it needs the joint's q')
  reg  signed [QD_W-1:0] blo_cq, bhi_cq;
  always @(posedge clk) begin
    blo_cq <= blo_c;
    bhi_cq <= bhi_c;
  end
  // warm start with its leak, clamped into this tick's box.  The leaked value is registered every
  // cycle (warm_lq), as are the bounds: warm_c is joint col's q' of the cycle before.
  wire signed [QD_W-1:0] warm_x = xc_warm;
  wire signed [QD_W-1:0] warm_sh = warm_x >>> cfg_leak;
  wire signed [QD_W-1:0] warm_l = (cfg_leak == 5'd0) ? warm_x : (warm_x - warm_sh);
  reg  signed [QD_W-1:0] warm_lq;
  always @(posedge clk) warm_lq <= warm_l;
  wire signed [QD_W-1:0] warm_c;
  ts_clamp #(.W(QD_W)) u_warm_c (.in_x(warm_lq), .in_lo(blo_cq), .in_hi(bhi_cq), .out_y(warm_c));
  // sweep step clamp
  wire signed [QD_W-1:0] qn_c;
  ts_clamp #(.W(QD_W)) u_qn_c (.in_x(qn_o), .in_lo(blo_cq), .in_hi(bhi_cq), .out_y(qn_c));
  // integration clamp of the stream's joint tj_r: its limits read a cycle before (at tj_r1) and
  // registered, so the memory reads leave the path into qnext (q_next = clamp(cvt(q + q' dt)))
  reg  signed [ANG_W-1:0] lo_cq, hi_cq;
  reg                     lim_cq;
  always @(posedge clk) begin
    lo_cq <= lo_r1;
    hi_cq <= hi_r1;
    lim_cq <= cfg_lim[tj_r1];
  end
  wire signed [ANG_W-1:0] qx_c;
  ts_clamp #(.W(ANG_W)) u_qx_c (.in_x(qx_o), .in_lo(lo_cq), .in_hi(hi_cq), .out_y(qx_c));
  // active-limit flags of joint tj_r (its final q' against its bounds)
  wire lo_hit = !(blo_r < qd[tj_r]);
  wire hi_hit = !(qd[tj_r] < bhi_r);
  wire lim_act = (blo_pos[tj_r] && lo_hit) || (bhi_pos[tj_r] && hi_hit);
  wire vlim_act = ((!blo_pos[tj_r] && lo_hit) || (!bhi_pos[tj_r] && hi_hit))
                  && (vmax_r != {1'b0, {(QD_W - 1){1'b1}}});

  wire last_col = ({1'b0, col} == n_q - 1'b1);
  wire signed [ACW-1:0] p_acc;
  ts_resize #(.IN_W(PW), .LSH(0), .OUT_W(ACW)) u_pacc (.in(p), .out(p_acc));

  // ---- per-joint memories (ts_ram: distributed RAM on ECP5, no reset) -------------------------------
  // configuration and inputs as written; the preparation streams' words at their sinks
  wire cfg_jwe = in_cfg_we && !cfg_g && !rst;
  wire x_jwe = in_x_we && !x_g && !rst;
  ts_ram #(.W(ANG_W), .AW(JI_W), .R(2)) u_cfg_lo (.clk(clk), .in_we(cfg_jwe && (cfg_f == 4'd0)),
    .in_waddr(cfg_j), .in_wdata(in_cfg_data[ANG_W-1:0]), .in_raddr({tj_r1, col}), .out_rdata({lo_r1, cl_lo}));
  ts_ram #(.W(ANG_W), .AW(JI_W), .R(2)) u_cfg_hi (.clk(clk), .in_we(cfg_jwe && (cfg_f == 4'd1)),
    .in_waddr(cfg_j), .in_wdata(in_cfg_data[ANG_W-1:0]), .in_raddr({tj_r1, col}), .out_rdata({hi_r1, cl_hi}));
  ts_ram #(.W(QD_W), .AW(JI_W), .R(3)) u_cfg_vmax (.clk(clk), .in_we(cfg_jwe && (cfg_f == 4'd2)),
    .in_waddr(cfg_j), .in_wdata(in_cfg_data[QD_W-1:0]), .in_raddr({tj_r, bj0, col}),
    .out_rdata({vmax_r, vmax_b, cl_vmax}));
  ts_ram #(.W(MUW), .AW(JI_W), .R(1)) u_cfg_mu (.clk(clk), .in_we(cfg_jwe && (cfg_f == 4'd3)),
    .in_waddr(cfg_j), .in_wdata(in_cfg_data[MUW-1:0]), .in_raddr(col), .out_rdata(cl_mu));
  ts_ram #(.W(ANG_W), .AW(JI_W), .R(2)) u_x_q (.clk(clk), .in_we(x_jwe && (x_f == 4'd6)),
    .in_waddr(x_j), .in_wdata(in_x_data[ANG_W-1:0]), .in_raddr({tj_p, col}), .out_rdata({xq_p, xc_q}));
  ts_ram #(.W(QD_W), .AW(JI_W), .R(1)) u_x_warm (.clk(clk), .in_we(x_jwe && (x_f == 4'd7)),
    .in_waddr(x_j), .in_wdata(in_x_data[QD_W-1:0]), .in_raddr(col), .out_rdata(xc_warm));
  // the preparation streams' per-joint words (see their declarations); a zero column (|Js_j|^2 = 0)
  // gets c = k = 0
  ts_ram #(.W(NRW), .AW(JI_W), .R(3)) u_nrm (.clk(clk), .in_we(dv2_q && !rst), .in_waddr(dj2_q),
    .in_wdata({dz2_q, k2_q, mr2_q, y0_new}), .in_raddr({tj_r, tj_p, col}), .out_rdata({nrm_r, nrm_p, nrm_c}));
  ts_ram #(.W(RCW), .AW(JI_W), .R(1)) u_ey (.clk(clk),
    .in_we(tv_r && ((tm_r == M_E) || (tm_r == M_Y)) && !rst), .in_waddr(tj_r),
    .in_wdata((tm_r == M_E) ? e_o : y_o), .in_raddr(col), .out_rdata(ey_c));
  // the position differences and vmin of joint col, from their rounders in the columns stream
  // (col holds for the six rows of a joint; the rounders' outputs are joint col's from row RL on)
  wire dd_we = (state == S_STREAM) && (mode == M_COL) && (bi == 3'd5);
  ts_ram #(.W(DDW), .AW(JI_W), .R(2)) u_dd (.clk(clk), .in_we(dd_we && !rst), .in_waddr(col),
    .in_wdata({vmin_o, dhi, dlo}), .in_raddr({bj0, col}), .out_rdata({dd_b, dd_c}));
  ts_ram #(.W(STW + KW), .AW(JI_W), .R(1)) u_ck (.clk(clk), .in_we(tv_r && (tm_r == M_C) && !rst),
    .in_waddr(tj_r), .in_wdata(dz_r ? {(STW + KW){1'b0}} : {c_o, k_r}), .in_raddr(col),
    .out_rdata({cst_c, kst_c}));
  ts_ram #(.W(2 * QD_W), .AW(JI_W), .R(2)) u_bnd (.clk(clk), .in_we(bv2 && !rst),
    .in_waddr(bj2), .in_wdata({hi2, lo2}), .in_raddr({tj_r, col}), .out_rdata({bhi_r, blo_r, bhi_c, blo_c}));

  // ---- sequencer -----------------------------------------------------------------------------------
  // d = |Js_j|^2 at the last product of joint j's |Js_j|^2 stream
  wire signed [ACW-1:0] acc_sum = acc + p_acc;
  wire [DW-1:0] d_sum;
  ts_resize #(.IN_W(ACW), .LSH(0), .OUT_W(DW)) u_dv (.in(acc_sum), .out(d_sum));
  localparam [7:0] RL8 = RL[7:0];
  // A coordinate step's residual update and the next step's dot overlap: the dot's row a is issued
  // once cvt<tw_t>(racc[a]) holds the update of row a (MLAT + 2 RL + 2 cycles after that row's
  // update was issued: product, racc rounder, racc, ro rounder; the rows follow one per cycle on
  // both sides).  The update burst drains UW8 cycles, then S_NEXTJ and S_SWEEP, then the dot's
  // first row.
  localparam integer UWI = (MLAT + 2 * RL - 7 > 0) ? (MLAT + 2 * RL - 7) : 0;
  localparam [7:0] UW8 = UWI[7:0];

  always @(posedge clk) begin
    if (rst) begin
      state <= S_IDLE; ret <= S_IDLE; bret <= S_IDLE; wt <= 8'd0; mode <= M_COL;
      bi <= 3'd0; bdrain <= 8'd0; col <= {JI_W{1'b0}}; n_q <= {(JI_W + 1){1'b0}}; sweep <= {SW_W{1'b0}};
      rpj <= 3'd0; snext <= S_IDLE; sdrain <= 8'd0; pj <= {(JI_W + 1){1'b0}};
      asel <= A_L; bsel <= B_JW; tag_q <= {TGW{1'b0}}; mul_a <= {MAW{1'b0}}; mul_b <= {MBW{1'b0}};
      acc <= {ACW{1'b0}}; d_q <= {DW{1'b0}}; dj_q <= {JI_W{1'b0}}; dv_q <= 1'b0;
      bv0 <= 1'b0; bj0 <= {JI_W{1'b0}}; plo_q <= {PLW{1'b0}}; phi_q <= {PLW{1'b0}};
      rb_q <= {QD_W{1'b0}}; gsh_q <= {GXW{1'b0}}; gk_q <= {GKW{1'b0}};
      qnc_q <= {QD_W{1'b0}}; flags <= 32'd0;
      out_busy <= 1'b0; out_done <= 1'b0; out_r <= {(6 * TW_W){1'b0}}; out_flags <= 32'd0;
      for (ri = 0; ri < NMAX; ri = ri + 1) begin
        blo_pos[ri] <= 1'b0; bhi_pos[ri] <= 1'b0; qd[ri] <= {QD_W{1'b0}}; qnext[ri] <= {ANG_W{1'b0}};
      end
      for (ri = 0; ri < 6; ri = ri + 1) begin
        vs[ri] <= {TW_W{1'b0}}; racc[ri] <= {TAW{1'b0}};
      end
    end else begin
      out_done <= 1'b0;
      tag_q <= {TGW{1'b0}};
      mul_a <= a_sel;
      mul_b <= b_sel;
      dv_q <= 1'b0;
      bv0 <= 1'b0;

      // sinks of the bursts and streams (the mode of a burst or stream holds until its last
      // product has drained)
      if (tv_p && (tm_p == M_DOT)) acc <= acc_sum;
      if (tv_p && (tm_p == M_D)) begin
        acc <= (row_p == 3'd0) ? p_acc : acc_sum;
        if (row_p == 3'd5) begin
          d_q <= d_sum; dj_q <= tj_p; dv_q <= 1'b1;
        end
      end
      if (tv_p && (tm_p == M_B)) begin
        if (row_p == 3'd0) plo_q <= p_pl;
        else begin
          phi_q <= p_pl; bj0 <= tj_p; bv0 <= 1'b1;
        end
      end
      if (tv_r && ((tm_r == M_COL) || (tm_r == M_T))) begin
        if (tm_r == M_T) begin
          vs[row_r] <= (row_r < 3'd3) ? twl_o : twv_o;
          if ((row_r < 3'd3) ? twl_s : twv_s) flags[8] <= 1'b1;
        end else begin
          js[{tj_r, row_r}] <= (row_r < 3'd3) ? jsl_o : jsv_o;
          if ((row_r < 3'd3) ? jsl_s : jsv_s) flags[8] <= 1'b1;
        end
      end
      if (tv_r && (tm_r == M_RUPD)) begin
        racc[row_r] <= racc_o;
        if (racc_s) flags[8] <= 1'b1;
      end
      // e, y, c of a zero column are not used (c = k = 0): their saturation is not the model's
      if (tv_r && !dz_r && (((tm_r == M_E) && e_s) || ((tm_r == M_Y) && y_s) || ((tm_r == M_C) && c_s)))
        flags[8] <= 1'b1;
      if (dd_we && (vmin_s || (cfg_lim[col] && (dlo_s || dhi_s)))) flags[8] <= 1'b1;
      if (tv_r && (tm_r == M_X)) begin
        qnext[tj_r] <= lim_cq ? qx_c : qx_o;
        if (qx_s) flags[0] <= 1'b1;
        if (lim_act) flags[16] <= 1'b1;
        if (vlim_act) flags[17] <= 1'b1;
      end
      if (bv2) begin
        blo_pos[bj2] <= lo_pos2; bhi_pos[bj2] <= hi_pos2;
        if (bsat2) flags[8] <= 1'b1;
      end

      case (state)
        S_IDLE: begin
          if (in_start) begin
            out_busy <= 1'b1;
            flags <= 32'd0;
            n_q <= in_n;
            col <= {JI_W{1'b0}};
            // target: L V_w and V_v
            mode <= M_T; asel <= A_L; bsel <= B_VW; bi <= 3'd0; bdrain <= ML8 + 8'd2;
            bret <= S_RINIT;
            state <= S_ISSUE;
          end
        end
        S_WAIT: begin
          if (wt == 8'd0) state <= ret;
          else wt <= wt - 1'b1;
        end
        S_ISSUE: begin
          // operands of row bi of joint col are registered into the multiplier this cycle
          tag_q <= {1'b1, mode, col, bi};
          if ((mode == M_DOT) && (bi == 3'd0)) acc <= {ACW{1'b0}};
          // the dot's operand cvt<tw_t>(racc[bi]) (saturation flagged as the model's solver_run)
          if ((mode == M_DOT) && ro_s[bi]) flags[8] <= 1'b1;
          if (bi == 3'd5) begin
            bi <= 3'd0;
            wt <= bdrain;
            ret <= bret;
            state <= S_WAIT;
          end else begin
            bi <= bi + 1'b1;
          end
        end
        S_STREAM: begin
          // a preparation stream: products 0..rpj of every joint on consecutive cycles, then the
          // drain of sdrain cycles and snext
          tag_q <= {1'b1, mode, col, bi};
          if (bi == rpj) begin
            bi <= 3'd0;
            if (last_col) begin
              wt <= sdrain;
              ret <= snext;
              state <= S_WAIT;
            end else col <= col + 1'b1;
          end else bi <= bi + 1'b1;
        end
        S_RINIT: begin
          for (ri = 0; ri < 6; ri = ri + 1) racc[ri] <= vs_al[ri*TAW +: TAW];
          // the scaled columns (the position differences and vmin of each joint on the way, dd_we)
          mode <= M_COL; asel <= A_L; bsel <= B_JW; col <= {JI_W{1'b0}}; bi <= 3'd0; rpj <= 3'd5;
          sdrain <= ML8 + RL8; snext <= S_PD;
          state <= S_STREAM;
        end
        S_PD: begin
          // |Js_j|^2, normalised and the seed looked up behind the stream (N1-N3)
          mode <= M_D; asel <= A_JS; bsel <= B_JS; col <= {JI_W{1'b0}}; bi <= 3'd0; rpj <= 3'd5;
          sdrain <= ML8 + 8'd3; snext <= S_PE;
          state <= S_STREAM;
        end
        S_PE: begin
          // e = cvt<e_t>(1 - m y0)
          mode <= M_E; asel <= A_M; bsel <= B_Y0; col <= {JI_W{1'b0}}; bi <= 3'd0; rpj <= 3'd0;
          sdrain <= ML8 + RL8; snext <= S_PY;
          state <= S_STREAM;
        end
        S_PY: begin
          // y = cvt<recip_t>(y0 + y0 e)
          mode <= M_Y; asel <= A_Y0; bsel <= B_E; col <= {JI_W{1'b0}}; bi <= 3'd0; rpj <= 3'd0;
          sdrain <= ML8 + RL8; snext <= S_PC;
          state <= S_STREAM;
        end
        S_PC: begin
          // c = cvt<step_t>(mu y), with k into u_ck
          mode <= M_C; asel <= A_MU; bsel <= B_Y; col <= {JI_W{1'b0}}; bi <= 3'd0; rpj <= 3'd0;
          sdrain <= ML8 + RL8; snext <= S_PB;
          state <= S_STREAM;
        end
        S_PB: begin
          // klim (lo - q) (row 0) and klim (hi - q) (row 1), the decisions behind the stream
          mode <= M_B; asel <= A_KLIM; bsel <= B_DLO; col <= {JI_W{1'b0}}; bi <= 3'd0; rpj <= 3'd1;
          sdrain <= ML8 + RL8 + 8'd1; snext <= S_PW0;
          state <= S_STREAM;
        end
        S_PW0: begin
          // warm start and racc -= Js_j q'_j: col runs two cycles ahead of the joint issued
          mode <= M_RUPD; asel <= A_JS; bsel <= B_RB; col <= {JI_W{1'b0}};
          state <= S_PW1;
        end
        S_PW1: state <= S_PW2;
        S_PW2: begin
          qd[col] <= warm_c;
          rb_q <= warm_c;
          pj <= {(JI_W + 1){1'b0}}; bi <= 3'd0;
          state <= S_PW;
        end
        S_PW: begin
          tag_q <= {1'b1, mode, pj[JI_W-1:0], bi};
          if ((bi == 3'd3) && (pj + 1'b1 != n_q)) col <= col + 1'b1;
          if (bi == 3'd5) begin
            bi <= 3'd0;
            if (pj + 1'b1 == n_q) begin
              col <= {JI_W{1'b0}};
              sweep <= {SW_W{1'b0}};
              wt <= ML8 + RL8 + 8'd2;
              ret <= S_SWEEP;
              state <= S_WAIT;
            end else begin
              pj <= pj + 1'b1;
              qd[col] <= warm_c;
              rb_q <= warm_c;
            end
          end else bi <= bi + 1'b1;
        end
        S_SWEEP: begin
          // one coordinate step of joint col: g = <Js_col, cvt<tw_t>(racc)>
          if (sweep == cfg_sweeps) begin
            col <= {JI_W{1'b0}};
            state <= S_QNX;
          end else begin
            mode <= M_DOT; asel <= A_JS; bsel <= B_RO; bi <= 3'd0; bdrain <= ML8;
            bret <= S_GSH;
            state <= S_ISSUE;
          end
        end
        S_GSH: begin
          gsh_q <= gsh;
          wt <= 8'd1;
          ret <= S_GK;
          state <= S_WAIT;
        end
        S_GK: begin
          gk_q <= gk_o;
          if (gk_s) flags[8] <= 1'b1;
          asel <= A_GK; bsel <= B_C;
          wt <= ML8 + 8'd2;
          ret <= S_QN;
          state <= S_WAIT;
        end
        S_QN: begin
          if (qn_s) flags[8] <= 1'b1;
          qnc_q <= qn_c;
          wt <= 8'd1;
          ret <= S_DQ;
          state <= S_WAIT;
        end
        S_DQ: begin
          if (dq_s) flags[8] <= 1'b1;
          rb_q <= dq_o;
          qd[col] <= qnc_q;
          mode <= M_RUPD; asel <= A_JS; bsel <= B_RB; bi <= 3'd0; bdrain <= UW8;
          bret <= S_NEXTJ;
          state <= S_ISSUE;
        end
        S_NEXTJ: begin
          if (last_col) begin
            col <= {JI_W{1'b0}};
            sweep <= sweep + 1'b1;
          end else begin
            col <= col + 1'b1;
          end
          state <= S_SWEEP;
        end
        S_QNX: begin
          // the integration stream: q' dt of every joint, q_next and the active-limit flags at
          // the rounded product (M_X sink)
          mode <= M_X; asel <= A_QD; bsel <= B_DT; col <= {JI_W{1'b0}}; bi <= 3'd0; rpj <= 3'd0;
          sdrain <= ML8 + RL8; snext <= S_DONE;
          state <= S_STREAM;
        end
        S_DONE: begin
          out_r <= ro_f;
          out_flags <= flags | {23'd0, |ro_s, 8'd0};
          out_busy <= 1'b0;
          out_done <= 1'b1;
          state <= S_IDLE;
        end
        default: state <= S_IDLE;
      endcase
    end
  end


  generate
    for (gr = 0; gr < NMAX; gr = gr + 1) begin : g_out
      assign out_qd[gr*QD_W +: QD_W] = qd[gr];
      assign out_q_next[gr*ANG_W +: ANG_W] = qnext[gr];
    end
  endgenerate


endmodule

`default_nettype wire
