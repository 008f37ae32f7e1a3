// SPDX-License-Identifier: Apache-2.0
// tensor-servo: forward kinematics and the Jacobian of a serial chain (the FK/J engine of the
// servo core's front half), bit-exact with the model (model/include/tensor_servo/kinematics.hpp):
//   ts::forward_kinematics (serial chain, one tool) and ts::jacobian(ch, f, ref = tool, basis = root),
// i.e. the Jacobian the servo uses for error choice A without a setpoint frame (servo.hpp
// task_error: basis -1, reference point the tool origin).  Per joint i (frames from the base out):
//   QF  = Q_{i-1} (x) Qo_i                   ts_quat_mul
//   pF  = cvt<pos_t>(p_{i-1} + R(Q_{i-1}) po_i)   ts_quat_rotate (len_t -> len_tmp_t -> pos_t), adder
//   revolute:  Q_i = QF (x) joint_quat(q_i)  ts_joint_quat (all joints streamed at start), ts_quat_mul
//              p_i = pF
//   prismatic: z_i = R(QF) a_i               (the rotation inside ts_screw_transport)
//              d = cvt<lever_t>(s q_i),  p_i = cvt<pos_t>(pF + d z_i),  Q_i = QF
//   tool:      Q_T = Q_n (x) Qt,  p_T = cvt<pos_t>(p_n + R(Q_n) pt)
// then the n columns, streamed through ts_screw_transport (one per FOLD cycles, its II):
//   z_i = R(QF_i) a_i;  revolute: w = cvt<jw_t>(s z_i), v = cross<jv_t>(w, cvt<lever_t>(p_T - p_i));
//   prismatic: w = 0, v = cvt<jv_t>(s z_i).
// One shared instance of each primitive; a sequencer walks the joints (docs/rtl/ts_core_fk.md).
//
// Configuration (raw words of the model's formats, low bits of in_cfg_data; write any time the
// engine is idle): address {global, joint[JI_W-1:0], field[3:0]}
//   global = 0, joint j:  field 0-3 origin quaternion w x y z (quat_t), 4-6 origin xyz (len_t),
//                         8-10 axis xyz (quat_t), 12 scale s (scale_t), 13 kturn = s/(4 pi)
//                         (kturn_t, 0 for a prismatic joint), 14 bit 0: prismatic
//   global = 1:           field 0-3 base quaternion, 4-6 base xyz, 8-11 tool quaternion,
//                         12-14 tool xyz, 15 joint count n (1..NMAX)
// Joint values: in_q_we / in_q_addr / in_q_data (angle_t).  in_start (while idle) runs one
// evaluation: out_busy until out_done (one-cycle pulse); the results then hold until the next
// start: tool pose (out_tool_*), and through the column port (registered: in_col_addr sampled
// at a clock edge, out_col_* valid after it) column j of J (omega: jw_t, v: jv_t) and the
// origin p_{j+1} of joint frame j+1 (pos_t).  out_flags: the model's Status bits of this
// evaluation (ST_OVF_TRIG, ST_OVF_QUAT, ST_OVF_POS, ST_OVF_LEVER, ST_OVF_JAC: bits 2-6; valid with
// out_done and after it).
// Widths: every *_W parameter below is derived from CONFIG (0 default, 1 compact); do not override.
// Language: Verilog 2005
`resetall
`timescale 1ns / 1ps
`default_nettype none

module ts_core_fk #(
  // Largest joint count (a power of two is the natural choice: the joint index has JI_W bits)
  parameter NMAX = 8,
  // Number configuration: 0 default, 1 compact
  parameter CONFIG = 0,
  // Configuration data bus width (every format of the configuration fits)
  parameter CFG_W = 32,
  // sin/cos table memory file (rtl/ts_trig_rom_<config>.mem)
  parameter ROM_FILE = "ts_trig_rom_default.mem",
  // Multiplier implementation: "GENERIC" or "ECP5" (see ts_mul)
  parameter TARGET = "GENERIC",
  // ECP5 wide products on three MULT18X18D (see ts_mul)
  parameter MUL3 = 0,
  // Products per multiplier of the quaternion product, the offset rotation and the screw
  // transport (ts_mul_bank); the columns are issued one per FOLD cycles
  parameter FOLD = 1,
  // Folded multiplier banks (FOLD > 1): 1 holds their operands and products in shift chains
  // (ts_mul_bank CHAIN; the same bits and cycles, more registers, shorter wires).
  parameter CHAIN = 0,
  // Joint index width: derived from NMAX, do not override
  parameter JI_W = (NMAX > 1) ? $clog2(NMAX) : 1,
  // Width of angle_t: derived from CONFIG, do not override
  parameter ANG_W = (CONFIG == 0) ? 32 : 18,
  // Width of quat_t: derived from CONFIG, do not override
  parameter Q_W = (CONFIG == 0) ? 27 : 18,
  // Width of pos_t: derived from CONFIG, do not override
  parameter P_W = (CONFIG == 0) ? 32 : 24,
  // Width of jw_t: derived from CONFIG, do not override
  parameter JW_W = (CONFIG == 0) ? 27 : 18,
  // Width of jv_t: derived from CONFIG, do not override
  parameter JV_W = (CONFIG == 0) ? 27 : 18
) (
  input  wire                    clk,
  input  wire                    rst,
  // configuration write port
  input  wire                    in_cfg_we,
  input  wire [JI_W+4:0]         in_cfg_addr,
  input  wire [CFG_W-1:0]        in_cfg_data,
  // joint values
  input  wire                    in_q_we,
  input  wire [JI_W-1:0]         in_q_addr,
  input  wire signed [ANG_W-1:0] in_q_data,
  // control
  input  wire                    in_start,
  output reg                     out_busy,
  output reg                     out_done,
  output reg  [15:0]             out_flags,
  // tool pose (root frame)
  output reg  signed [Q_W-1:0]   out_tool_q_w,
  output reg  signed [Q_W-1:0]   out_tool_q_x,
  output reg  signed [Q_W-1:0]   out_tool_q_y,
  output reg  signed [Q_W-1:0]   out_tool_q_z,
  output reg  signed [P_W-1:0]   out_tool_p_x,
  output reg  signed [P_W-1:0]   out_tool_p_y,
  output reg  signed [P_W-1:0]   out_tool_p_z,
  // column read port
  input  wire [JI_W-1:0]         in_col_addr,
  output reg  signed [JW_W-1:0]  out_col_w_x,
  output reg  signed [JW_W-1:0]  out_col_w_y,
  output reg  signed [JW_W-1:0]  out_col_w_z,
  output reg  signed [JV_W-1:0]  out_col_v_x,
  output reg  signed [JV_W-1:0]  out_col_v_y,
  output reg  signed [JV_W-1:0]  out_col_v_z,
  output reg  signed [P_W-1:0]   out_col_p_x,
  output reg  signed [P_W-1:0]   out_col_p_y,
  output reg  signed [P_W-1:0]   out_col_p_z
);

  `include "ts_common.vh"
  // Formats of the configuration (ap_fixed<W, I>, F = W - I), the values of rtl/ts_formats.vh
  // (which cannot be included lint-clean here); tb/ts_core_fk checks them against the model.
  localparam TS_KTURN_W = (CONFIG == 0) ? 30 : 18;
  localparam TS_KTURN_F = (CONFIG == 0) ? 31 : 20;
  localparam TS_SCALE_W = (CONFIG == 0) ? 27 : 18;
  localparam TS_SCALE_F = (CONFIG == 0) ? 24 : 15;
  localparam TS_LEN_W = (CONFIG == 0) ? 27 : 18;
  localparam TS_LEN_F = (CONFIG == 0) ? 24 : 15;
  localparam TS_LEN_TMP_W = (CONFIG == 0) ? 27 : 18;
  localparam TS_LEN_TMP_F = (CONFIG == 0) ? 22 : 14;
  localparam TS_LEVER_W = (CONFIG == 0) ? 27 : 18;
  localparam TS_LEVER_F = (CONFIG == 0) ? 23 : 15;
  localparam TS_QUAT_F = (CONFIG == 0) ? 25 : 16;
  localparam TS_POS_F = (CONFIG == 0) ? 27 : 20;
  localparam TS_ANGLE_F = (CONFIG == 0) ? 28 : 14;
  localparam TS_TURN_W = (CONFIG == 0) ? 32 : 26;
  localparam TS_TAB_W = (CONFIG == 0) ? 27 : 18;
  localparam TS_TAB_F = (CONFIG == 0) ? 25 : 16;
  localparam TS_DELTA_W = (CONFIG == 0) ? 27 : 18;
  localparam TS_DELTA_F = (CONFIG == 0) ? 33 : 24;
  localparam TS_DSQ_W = (CONFIG == 0) ? 27 : 18;
  localparam TS_DSQ_F = (CONFIG == 0) ? 40 : 31;
  localparam TS_TRIG_ACC_W = (CONFIG == 0) ? 35 : 26;
  localparam TS_TRIG_ACC_F = (CONFIG == 0) ? 33 : 24;
  localparam TS_TWOPI_W = (CONFIG == 0) ? 27 : 18;
  localparam TS_TWOPI_F = (CONFIG == 0) ? 23 : 14;
  localparam TS_SIXTH_W = 18;
  localparam TS_SIXTH_F = 18;
  localparam TS_UVEC_TMP_W = (CONFIG == 0) ? 27 : 18;
  localparam TS_UVEC_TMP_F = (CONFIG == 0) ? 24 : 15;
  localparam TS_JW_F = (CONFIG == 0) ? 24 : 15;
  localparam TS_JV_F = (CONFIG == 0) ? 22 : 14;
  localparam TS_TRIG_TABLE_BITS = 8;

  localparam KT_W = TS_KTURN_W;
  localparam S_W = TS_SCALE_W;
  localparam S_F = TS_SCALE_F;
  localparam LN_W = TS_LEN_W;
  localparam LN_F = TS_LEN_F;
  localparam L_W = TS_LEVER_W;
  localparam L_F = TS_LEVER_F;
  localparam Q_F = TS_QUAT_F;
  localparam P_F = TS_POS_F;
  localparam A_F = TS_ANGLE_F;
  localparam RL = ts_round_lat(1);
  // ts_sincos constants (rtl/ts_cfg_<config>.vh TS_TWOPI, TS_SIXTH)
  localparam TWOPI = (CONFIG == 0) ? 52707179 : 102944;
  localparam SIXTH = 43691;
  // register array depth (entries beyond NMAX are never addressed by a valid n)
  localparam AD = 1 << JI_W;

  generate
    if ((JI_W < 1) || ((1 << JI_W) < NMAX) || (CFG_W < P_W) || (CFG_W < ANG_W) ||
        (CFG_W < KT_W) || (CFG_W < JI_W + 1)) begin : g_bad
      // Elaboration error: a width parameter was overridden inconsistently with CONFIG / NMAX.
      ts_core_fk_inconsistent_width_parameters u_error ();
    end
  endgenerate

  genvar gi;
  integer k;
  integer kc;  // loop index of the configuration block (one loop variable per process: no shared register)

  // ---- configuration ---------------------------------------------------------------------------
  // Per joint: memories without reset (ts_ram, one per vector component; distributed RAM on ECP5),
  // read at the joint of the step (ji), of the joint-quaternion stream (pre_j) or of the screw
  // transport (st_j).  The loader writes every joint's words at a commit, before any start.
  reg        [AD-1:0]   c_pr;
  reg signed [Q_W-1:0]  c_qb [0:3];
  reg signed [LN_W-1:0] c_pb [0:3];
  reg signed [Q_W-1:0]  c_qt [0:3];
  reg signed [LN_W-1:0] c_pt [0:3];
  reg        [JI_W:0]   c_n;

  wire [3:0]      cf = in_cfg_addr[3:0];
  wire [JI_W-1:0] cj = in_cfg_addr[JI_W+3:4];
  wire            cg = in_cfg_addr[JI_W+4];
  wire unused_cfg_data = ^in_cfg_data;

  wire cfg_wr = in_cfg_we && !out_busy;
  wire q_wr = in_q_we && !out_busy;

  wire cfg_jw = cfg_wr && !cg;
  // joint step (ji), joint-quaternion stream (pre_j) and screw transport (st_j) joints, below
  wire [JI_W-1:0] ji_a, pre_j, st_j_a;
  // origin quaternion and position, components of joint ji
  wire signed [Q_W-1:0]  qo_j [0:3];
  wire signed [LN_W-1:0] po_j [0:2];
  // axis of joint pre_j and of joint st_j
  wire signed [Q_W-1:0]  ax_pre [0:2];
  wire signed [Q_W-1:0]  ax_st [0:2];
  // scale of joint pre_j and st_j, kturn and q of joint pre_j
  wire signed [S_W-1:0]  s_pre, s_st;
  wire signed [KT_W-1:0] k_pre;
  wire signed [ANG_W-1:0] q_pre;
  generate
    for (gi = 0; gi < 4; gi = gi + 1) begin : g_cqo
      ts_ram #(.W(Q_W), .AW(JI_W), .R(1)) u_m (
        .clk(clk), .in_we(cfg_jw && (cf == gi)), .in_waddr(cj), .in_wdata(in_cfg_data[Q_W-1:0]),
        .in_raddr(ji_a), .out_rdata(qo_j[gi]));
    end
    for (gi = 0; gi < 3; gi = gi + 1) begin : g_cpo
      ts_ram #(.W(LN_W), .AW(JI_W), .R(1)) u_m (
        .clk(clk), .in_we(cfg_jw && (cf == 4 + gi)), .in_waddr(cj), .in_wdata(in_cfg_data[LN_W-1:0]),
        .in_raddr(ji_a), .out_rdata(po_j[gi]));
    end
    for (gi = 0; gi < 3; gi = gi + 1) begin : g_cax
      ts_ram #(.W(Q_W), .AW(JI_W), .R(2)) u_m (
        .clk(clk), .in_we(cfg_jw && (cf == 8 + gi)), .in_waddr(cj), .in_wdata(in_cfg_data[Q_W-1:0]),
        .in_raddr({st_j_a, pre_j}), .out_rdata({ax_st[gi], ax_pre[gi]}));
    end
  endgenerate
  ts_ram #(.W(S_W), .AW(JI_W), .R(2)) u_cs (
    .clk(clk), .in_we(cfg_jw && (cf == 4'd12)), .in_waddr(cj), .in_wdata(in_cfg_data[S_W-1:0]),
    .in_raddr({st_j_a, pre_j}), .out_rdata({s_st, s_pre}));
  ts_ram #(.W(KT_W), .AW(JI_W), .R(1)) u_ck (
    .clk(clk), .in_we(cfg_jw && (cf == 4'd13)), .in_waddr(cj), .in_wdata(in_cfg_data[KT_W-1:0]),
    .in_raddr(pre_j), .out_rdata(k_pre));
  ts_ram #(.W(ANG_W), .AW(JI_W), .R(1)) u_cq (
    .clk(clk), .in_we(q_wr), .in_waddr(in_q_addr), .in_wdata(in_q_data), .in_raddr(pre_j), .out_rdata(q_pre));
  always @(posedge clk) begin
    if (rst)                        c_pr <= {AD{1'b0}};
    else if (cfg_jw && (cf == 4'd14)) c_pr[cj] <= in_cfg_data[0];
  end

  // base, tool, joint count
  always @(posedge clk) begin
    if (rst) begin
      for (kc = 0; kc < 4; kc = kc + 1) begin
        c_qb[kc] <= {Q_W{1'b0}};
        c_pb[kc] <= {LN_W{1'b0}};
        c_qt[kc] <= {Q_W{1'b0}};
        c_pt[kc] <= {LN_W{1'b0}};
      end
      c_n <= {(JI_W+1){1'b0}};
    end else if (cfg_wr && cg) begin
      case (cf[3:2])
        2'd0: c_qb[cf[1:0]] <= in_cfg_data[Q_W-1:0];
        2'd1: c_pb[cf[1:0]] <= in_cfg_data[LN_W-1:0];
        2'd2: c_qt[cf[1:0]] <= in_cfg_data[Q_W-1:0];
        default: begin
          if (cf[1:0] == 2'd3) c_n <= in_cfg_data[JI_W:0];
          else c_pt[cf[1:0]] <= in_cfg_data[LN_W-1:0];
        end
      endcase
    end
  end

  // ---- sequencer state ------------------------------------------------------------------------------
  localparam [3:0] S_IDLE = 4'd0, S_ORIG = 4'd1, S_WAIT1 = 4'd2, S_NEXT = 4'd3, S_WAIT2 = 4'd4,
                   S_WAITZ = 4'd5, S_PP = 4'd6, S_WAITP = 4'd7, S_JAC = 4'd8, S_JWAIT = 4'd9,
                   S_DONE = 4'd10;
  reg [3:0] state;
  reg [JI_W-1:0] ji;         // joint of the current step
  reg            tool;       // the current step is the tool's
  reg [JI_W:0]   pre_in;     // joints issued to the joint-quaternion and d pipelines
  reg [JI_W:0]   jq_cnt;     // joint quaternions received
  reg [JI_W:0]   d_cnt;      // prismatic displacements received
  reg [JI_W:0]   col_in;     // columns issued
  reg [JI_W:0]   col_out;    // columns received
  reg have_pf, have_q2;
  // cycles until the next column may be issued (the screw transport's II = FOLD)
  localparam GAP_W = (FOLD > 1) ? $clog2(FOLD) : 1;
  localparam integer FOLD_M1 = FOLD - 1;
  localparam [GAP_W-1:0] GAP_MAX = FOLD_M1[GAP_W-1:0];
  reg [GAP_W-1:0] jgap;

  reg signed [Q_W-1:0] qc [0:3];   // Q_{i-1}
  reg signed [P_W-1:0] pc [0:2];   // p_{i-1}
  reg signed [Q_W-1:0] qf [0:3];   // QF of the current joint
  reg signed [P_W-1:0] pf [0:2];   // pF of the current joint
  reg signed [Q_W-1:0] zr [0:2];   // z of the current (prismatic) joint

  // per-joint results (ts_ram, written below): joint quaternion and d = s q of joint ji, QF_i and
  // p_i of joint st_j
  wire signed [Q_W-1:0] rjq_j [0:3];
  wire signed [L_W-1:0] rd_j;
  wire signed [Q_W-1:0] rqf_st [0:3];
  wire signed [P_W-1:0] rp_st [0:2];

  wire [JI_W-1:0] n_m1 = c_n[JI_W-1:0] - {{(JI_W-1){1'b0}}, 1'b1};

  // ---- joint quaternions and prismatic displacements, streamed at start ----------------------------
  wire            pre_valid = (state != S_IDLE) && (state != S_DONE) && (pre_in < c_n);
  assign pre_j = pre_in[JI_W-1:0];
  wire            jq_valid;
  wire signed [Q_W-1:0] jq_o [0:3];
  wire [15:0]     jq_flags;
  ts_joint_quat #(
    .ANG_W(ANG_W), .ANG_F(A_F), .KT_W(KT_W), .KT_F(TS_KTURN_F), .U_W(TS_TURN_W),
    .T_BITS(TS_TRIG_TABLE_BITS), .TAB_W(TS_TAB_W), .TAB_F(TS_TAB_F), .DELTA_W(TS_DELTA_W),
    .DELTA_F(TS_DELTA_F), .DSQ_W(TS_DSQ_W), .DSQ_F(TS_DSQ_F), .ACC_W(TS_TRIG_ACC_W),
    .ACC_F(TS_TRIG_ACC_F), .Q_W(Q_W), .Q_F(Q_F), .TWOPI_W(TS_TWOPI_W), .TWOPI_F(TS_TWOPI_F),
    .TWOPI(TWOPI), .SIXTH_W(TS_SIXTH_W), .SIXTH_F(TS_SIXTH_F), .SIXTH(SIXTH), .ROM_FILE(ROM_FILE),
    .TARGET(TARGET), .MUL3(MUL3)
  ) u_jq (
    .clk(clk), .rst(rst), .in_valid(pre_valid), .in_angle(q_pre), .in_kturn(k_pre),
    .in_axis_x(ax_pre[0]), .in_axis_y(ax_pre[1]), .in_axis_z(ax_pre[2]),
    .out_valid(jq_valid), .out_w(jq_o[0]), .out_x(jq_o[1]), .out_y(jq_o[2]), .out_z(jq_o[3]),
    .out_flags(jq_flags));

  // d = cvt<lever_t>(s q)
  localparam MLD = ts_mul_lat(S_W, ANG_W);
  wire signed [S_W+ANG_W-1:0] d_p;
  ts_mul #(.A_W(S_W), .B_W(ANG_W), .TARGET(TARGET), .MUL3(MUL3)) u_dm (
    .clk(clk), .rst(rst), .a(s_pre), .b(q_pre), .p(d_p));
  wire signed [L_W-1:0] d_o;
  wire d_sat;
  ts_round_sat #(.IN_W(S_W+ANG_W), .SHIFT(S_F+A_F-L_F), .OUT_W(L_W), .SAT(1)) u_dr (
    .clk(clk), .rst(rst), .in_x(d_p), .out_y(d_o), .out_sat(d_sat));
  wire d_valid;
  ts_delay #(.W(1), .DEPTH(MLD+RL)) u_dv (.clk(clk), .rst(rst), .din(pre_valid), .dout(d_valid));

  wire [JI_W-1:0] jq_j = jq_cnt[JI_W-1:0];
  wire [JI_W-1:0] d_j = d_cnt[JI_W-1:0];

  // ---- quaternion product (QF and Q_i) ----------------------------------------------------------------
  reg qm_valid;
  reg signed [Q_W-1:0] qm_a [0:3];
  reg signed [Q_W-1:0] qm_b [0:3];
  wire qm_ovalid, qm_sat;
  wire signed [Q_W-1:0] qm_o [0:3];
  ts_quat_mul #(.Q_W(Q_W), .Q_F(Q_F), .TARGET(TARGET), .MUL3(MUL3), .FOLD(FOLD), .CHAIN(CHAIN)) u_qm (
    .clk(clk), .rst(rst), .in_valid(qm_valid),
    .in_a_w(qm_a[0]), .in_a_x(qm_a[1]), .in_a_y(qm_a[2]), .in_a_z(qm_a[3]),
    .in_b_w(qm_b[0]), .in_b_x(qm_b[1]), .in_b_y(qm_b[2]), .in_b_z(qm_b[3]),
    .out_valid(qm_ovalid), .out_w(qm_o[0]), .out_x(qm_o[1]), .out_y(qm_o[2]), .out_z(qm_o[3]),
    .out_sat(qm_sat));

  // ---- offset rotation R(Q_{i-1}) po_i, then pF = cvt<pos_t>(p_{i-1} + offset) ----------------------
  reg ro_valid;
  reg signed [LN_W-1:0] ro_v [0:2];
  wire ro_ovalid, ro_sat;
  wire signed [P_W-1:0] ro_o [0:2];
  ts_quat_rotate #(
    .Q_W(Q_W), .Q_F(Q_F), .V_W(LN_W), .V_F(LN_F), .T_W(TS_LEN_TMP_W), .T_F(TS_LEN_TMP_F),
    .O_W(P_W), .O_F(P_F), .INV(0), .TARGET(TARGET), .MUL3(MUL3), .FOLD(FOLD), .CHAIN(CHAIN)
  ) u_ro (
    .clk(clk), .rst(rst), .in_valid(ro_valid),
    .in_q_w(qm_a[0]), .in_q_x(qm_a[1]), .in_q_y(qm_a[2]), .in_q_z(qm_a[3]),
    .in_v_x(ro_v[0]), .in_v_y(ro_v[1]), .in_v_z(ro_v[2]),
    .out_valid(ro_ovalid), .out_x(ro_o[0]), .out_y(ro_o[1]), .out_z(ro_o[2]), .out_sat(ro_sat));

  wire add_valid;
  wire [2:0] add_sat;
  wire signed [P_W-1:0] add_o [0:2];
  ts_delay #(.W(1), .DEPTH(1+RL)) u_av (.clk(clk), .rst(rst), .din(ro_ovalid), .dout(add_valid));
  generate
    for (gi = 0; gi < 3; gi = gi + 1) begin : g_add
      reg signed [P_W:0] sum;
      always @(posedge clk) begin
        if (rst) sum <= {(P_W+1){1'b0}};
        else     sum <= {pc[gi][P_W-1], pc[gi]} + {ro_o[gi][P_W-1], ro_o[gi]};
      end
      ts_round_sat #(.IN_W(P_W+1), .SHIFT(0), .OUT_W(P_W), .SAT(1)) u_rs (
        .clk(clk), .rst(rst), .in_x(sum), .out_y(add_o[gi]), .out_sat(add_sat[gi]));
    end
  endgenerate
  wire ro_sat_d;
  ts_delay #(.W(1), .DEPTH(1+RL)) u_ros (.clk(clk), .rst(rst), .din(ro_sat), .dout(ro_sat_d));

  // ---- screw transport: z of a prismatic joint during FK, then the Jacobian columns ----------------
  reg st_valid;
  reg [JI_W-1:0] st_j;
  reg st_fk;                 // 1: the FK use (prismatic z, lever inputs zero)
  wire st_ovalid;
  wire [15:0] st_flags;
  wire signed [Q_W-1:0] st_z [0:2];
  wire signed [JW_W-1:0] st_w [0:2];
  wire signed [JV_W-1:0] st_v [0:2];
  wire signed [P_W-1:0] st_pref [0:2];
  wire signed [P_W-1:0] st_pi [0:2];
  wire signed [Q_W-1:0] st_q [0:3];
  wire signed [P_W-1:0] tool_p [0:2];
  assign tool_p[0] = out_tool_p_x;
  assign tool_p[1] = out_tool_p_y;
  assign tool_p[2] = out_tool_p_z;
  generate
    for (gi = 0; gi < 4; gi = gi + 1) begin : g_stq
      localparam [1:0] C = gi;
      assign st_q[gi] = st_fk ? qf[gi] : rqf_st[C];
    end
    for (gi = 0; gi < 3; gi = gi + 1) begin : g_stp
      localparam [1:0] C = gi;
      assign st_pref[gi] = st_fk ? {P_W{1'b0}} : tool_p[gi];
      assign st_pi[gi] = st_fk ? {P_W{1'b0}} : rp_st[C];
    end
  endgenerate
  ts_screw_transport #(
    .Q_W(Q_W), .Q_F(Q_F), .UT_W(TS_UVEC_TMP_W), .UT_F(TS_UVEC_TMP_F), .S_W(S_W), .S_F(S_F),
    .P_W(P_W), .P_F(P_F), .L_W(L_W), .L_F(L_F), .JW_W(JW_W), .JW_F(TS_JW_F), .JV_W(JV_W),
    .JV_F(TS_JV_F), .TARGET(TARGET), .MUL3(MUL3), .FOLD(FOLD), .CHAIN(CHAIN)
  ) u_st (
    .clk(clk), .rst(rst), .in_valid(st_valid),
    .in_q_w(st_q[0]), .in_q_x(st_q[1]), .in_q_y(st_q[2]), .in_q_z(st_q[3]),
    .in_axis_x(ax_st[0]), .in_axis_y(ax_st[1]), .in_axis_z(ax_st[2]),
    .in_prismatic(c_pr[st_j] | st_fk), .in_s(s_st),
    .in_pref_x(st_pref[0]), .in_pref_y(st_pref[1]), .in_pref_z(st_pref[2]),
    .in_pi_x(st_pi[0]), .in_pi_y(st_pi[1]), .in_pi_z(st_pi[2]),
    .out_valid(st_ovalid), .out_z_x(st_z[0]), .out_z_y(st_z[1]), .out_z_z(st_z[2]),
    .out_w_x(st_w[0]), .out_w_y(st_w[1]), .out_w_z(st_w[2]),
    .out_v_x(st_v[0]), .out_v_y(st_v[1]), .out_v_z(st_v[2]), .out_flags(st_flags));

  // ---- prismatic origin p_i = cvt<pos_t>(pF + d z) ----------------------------------------------------
  localparam MLP = ts_bank_lat(L_W, Q_W, FOLD);
  localparam PP_F = ts_max(L_F + Q_F, P_F);
  localparam PP_W = ts_max(L_W + Q_W - L_F - Q_F, P_W - P_F) + 1 + PP_F;
  reg pp_valid;
  wire pp_ovalid;
  wire [2:0] pp_sat;
  wire signed [P_W-1:0] pp_o [0:2];
  ts_delay #(.W(1), .DEPTH(MLP+1+RL)) u_ppv (.clk(clk), .rst(rst), .din(pp_valid), .dout(pp_ovalid));
  wire [3*(L_W+Q_W)-1:0] pp_p;
  ts_mul_bank #(.N(3), .FOLD(FOLD), .CHAIN(CHAIN), .A_W(L_W), .B_W(Q_W), .TARGET(TARGET), .MUL3(MUL3)) u_mpp (
    .clk(clk), .rst(rst), .in_valid(pp_valid), .in_a({rd_j, rd_j, rd_j}), .in_b({zr[2], zr[1], zr[0]}),
    .out_p(pp_p));
  generate
    for (gi = 0; gi < 3; gi = gi + 1) begin : g_pp
      wire signed [L_W+Q_W-1:0] prod = pp_p[gi*(L_W+Q_W) +: L_W+Q_W];
      // pF waits for the product (it does not change while the product is formed)
      wire signed [PP_W-1:0] pa, pb;
      ts_resize #(.IN_W(L_W+Q_W), .LSH(PP_F-L_F-Q_F), .OUT_W(PP_W)) u_pa (.in(prod), .out(pa));
      ts_resize #(.IN_W(P_W), .LSH(PP_F-P_F), .OUT_W(PP_W)) u_pb (.in(pf[gi]), .out(pb));
      reg signed [PP_W-1:0] sum;
      always @(posedge clk) begin
        if (rst) sum <= {PP_W{1'b0}};
        else     sum <= pa + pb;
      end
      ts_round_sat #(.IN_W(PP_W), .SHIFT(PP_F-P_F), .OUT_W(P_W), .SAT(1)) u_rs (
        .clk(clk), .rst(rst), .in_x(sum), .out_y(pp_o[gi]), .out_sat(pp_sat[gi]));
    end
  endgenerate

  // base position, exact widening len_t -> pos_t
  wire signed [P_W-1:0] pb_w [0:2];
  generate
    for (gi = 0; gi < 3; gi = gi + 1) begin : g_pb
      ts_resize #(.IN_W(LN_W), .LSH(P_F-LN_F), .OUT_W(P_W)) u_pbw (.in(c_pb[gi]), .out(pb_w[gi]));
    end
  endgenerate

  // ---- the sequencer ----------------------------------------------------------------------------------
  // pF (the position path, longer than the quaternion path) is waited for only where it is used:
  // the end of the joint's step, the tool, the prismatic origin
  wire pf_now = have_pf | add_valid;
  wire signed [P_W-1:0] pf_cur [0:2];
  generate
    for (gi = 0; gi < 3; gi = gi + 1) begin : g_pfc
      assign pf_cur[gi] = add_valid ? add_o[gi] : pf[gi];
    end
  endgenerate
  wire last_col_in = (col_in[JI_W-1:0] == n_m1);

  // the model's Status bits raised this cycle (each result is used, so each flag counts): the
  // joint quaternion of a revolute joint (TRIG, QUAT) and d = s q of a prismatic one (LEVER),
  // the shared quaternion product (QUAT), rotated offset and sum (POS: len_tmp_t, pos_t), the
  // screw transport (QUAT, LEVER, JAC) and the prismatic origin (POS)
  localparam ST_QUAT = 3, ST_POS = 4, ST_LEVER = 5;
  wire [15:0] fl_set = ((jq_valid && !c_pr[jq_j]) ? jq_flags : 16'd0)
                     | (st_ovalid ? st_flags : 16'd0)
                     | ({15'd0, d_valid && c_pr[d_j] && d_sat} << ST_LEVER)
                     | ({15'd0, qm_ovalid && qm_sat} << ST_QUAT)
                     | ({15'd0, (add_valid && (ro_sat_d || (|add_sat))) || (pp_ovalid && (|pp_sat))} << ST_POS);

  always @(posedge clk) begin
    if (rst) begin
      state <= S_IDLE;
      ji <= {JI_W{1'b0}};
      tool <= 1'b0;
      pre_in <= {(JI_W+1){1'b0}};
      jq_cnt <= {(JI_W+1){1'b0}};
      d_cnt <= {(JI_W+1){1'b0}};
      col_in <= {(JI_W+1){1'b0}};
      col_out <= {(JI_W+1){1'b0}};
      have_pf <= 1'b0;
      have_q2 <= 1'b0;
      jgap <= {GAP_W{1'b0}};
      qm_valid <= 1'b0;
      ro_valid <= 1'b0;
      st_valid <= 1'b0;
      st_j <= {JI_W{1'b0}};
      st_fk <= 1'b0;
      pp_valid <= 1'b0;
      out_busy <= 1'b0;
      out_done <= 1'b0;
      out_flags <= 16'd0;
      out_tool_q_w <= {Q_W{1'b0}}; out_tool_q_x <= {Q_W{1'b0}};
      out_tool_q_y <= {Q_W{1'b0}}; out_tool_q_z <= {Q_W{1'b0}};
      out_tool_p_x <= {P_W{1'b0}}; out_tool_p_y <= {P_W{1'b0}}; out_tool_p_z <= {P_W{1'b0}};
      for (k = 0; k < 4; k = k + 1) begin
        qc[k] <= {Q_W{1'b0}};
        qf[k] <= {Q_W{1'b0}};
        qm_a[k] <= {Q_W{1'b0}};
        qm_b[k] <= {Q_W{1'b0}};
      end
      for (k = 0; k < 3; k = k + 1) begin
        pc[k] <= {P_W{1'b0}};
        pf[k] <= {P_W{1'b0}};
        zr[k] <= {Q_W{1'b0}};
        ro_v[k] <= {LN_W{1'b0}};
      end
    end else begin
      qm_valid <= 1'b0;
      ro_valid <= 1'b0;
      st_valid <= 1'b0;
      pp_valid <= 1'b0;
      out_done <= 1'b0;

      // joint quaternion and d streams (issued from the start on, received whatever the state)
      if (pre_valid) pre_in <= pre_in + 1'b1;
      if (jq_valid) jq_cnt <= jq_cnt + 1'b1;
      if (d_valid) d_cnt <= d_cnt + 1'b1;
      // the Status bits raised this cycle (fl_set); cleared at the start below
      out_flags <= out_flags | fl_set;
      // pF of the current step, whatever the state
      if (add_valid) begin
        have_pf <= 1'b1;
        for (k = 0; k < 3; k = k + 1) pf[k] <= add_o[k];
      end

      case (state)
        S_IDLE: begin
          if (in_start) begin
            out_busy <= 1'b1;
            out_flags <= 16'd0;
            pre_in <= {(JI_W+1){1'b0}};
            jq_cnt <= {(JI_W+1){1'b0}};
            d_cnt <= {(JI_W+1){1'b0}};
            ji <= {JI_W{1'b0}};
            tool <= (c_n == {(JI_W+1){1'b0}});
            for (k = 0; k < 4; k = k + 1) qc[k] <= c_qb[k];
            for (k = 0; k < 3; k = k + 1) pc[k] <= pb_w[k];
            state <= S_ORIG;
          end
        end
        S_ORIG: begin
          // QF = Q_{i-1} (x) Qo_i and R(Q_{i-1}) po_i (tool: Qt, pt), issued together
          qm_valid <= 1'b1;
          ro_valid <= 1'b1;
          for (k = 0; k < 4; k = k + 1) begin
            qm_a[k] <= qc[k];
            qm_b[k] <= tool ? c_qt[k] : qo_j[k];
          end
          for (k = 0; k < 3; k = k + 1) ro_v[k] <= tool ? c_pt[k] : po_j[k];
          have_pf <= 1'b0;
          have_q2 <= 1'b0;
          state <= S_WAIT1;
        end
        S_WAIT1: begin
          if (qm_ovalid) begin
            for (k = 0; k < 4; k = k + 1) qf[k] <= qm_o[k];
            state <= S_NEXT;
          end
        end
        S_NEXT: begin
          if (tool) begin
            if (pf_now) begin
              out_tool_q_w <= qf[0]; out_tool_q_x <= qf[1]; out_tool_q_y <= qf[2]; out_tool_q_z <= qf[3];
              out_tool_p_x <= pf_cur[0]; out_tool_p_y <= pf_cur[1]; out_tool_p_z <= pf_cur[2];
              col_in <= {(JI_W+1){1'b0}};
              col_out <= {(JI_W+1){1'b0}};
              jgap <= {GAP_W{1'b0}};
              state <= (c_n == {(JI_W+1){1'b0}}) ? S_DONE : S_JAC;
            end
          end else if (!c_pr[ji]) begin
            // revolute: Q_i = QF (x) Qj_i once the joint quaternion is there
            if (jq_cnt > {1'b0, ji}) begin
              qm_valid <= 1'b1;
              for (k = 0; k < 4; k = k + 1) begin
                qm_a[k] <= qf[k];
                qm_b[k] <= rjq_j[k];
              end
              state <= S_WAIT2;
            end
          end else begin
            // prismatic: z_i = R(QF) a_i (screw transport, FK use)
            if (d_cnt > {1'b0, ji}) begin
              st_valid <= 1'b1;
              st_fk <= 1'b1;
              st_j <= ji;
              state <= S_WAITZ;
            end
          end
        end
        S_WAIT2: begin
          // Q_i (kept in qc: Q_{i-1} is not needed any more) and pF
          if (qm_ovalid) begin
            have_q2 <= 1'b1;
            for (k = 0; k < 4; k = k + 1) qc[k] <= qm_o[k];
          end
          if ((have_q2 || qm_ovalid) && pf_now) begin
            for (k = 0; k < 3; k = k + 1) pc[k] <= pf_cur[k];
            if ({1'b0, ji} == c_n - 1'b1) tool <= 1'b1;
            else ji <= ji + 1'b1;
            state <= S_ORIG;
          end
        end
        S_WAITZ: begin
          if (st_ovalid) begin
            for (k = 0; k < 3; k = k + 1) zr[k] <= st_z[k];
            st_fk <= 1'b0;
            state <= S_PP;
          end
        end
        S_PP: begin
          if (have_pf) begin
            pp_valid <= 1'b1;
            state <= S_WAITP;
          end
        end
        S_WAITP: begin
          if (pp_ovalid) begin
            for (k = 0; k < 4; k = k + 1) qc[k] <= qf[k];
            for (k = 0; k < 3; k = k + 1) pc[k] <= pp_o[k];
            if ({1'b0, ji} == c_n - 1'b1) tool <= 1'b1;
            else ji <= ji + 1'b1;
            state <= S_ORIG;
          end
        end
        S_JAC: begin
          // one column per FOLD cycles (the screw transport's II)
          st_fk <= 1'b0;
          if (jgap == {GAP_W{1'b0}}) begin
            st_valid <= 1'b1;
            st_j <= col_in[JI_W-1:0];
            col_in <= col_in + 1'b1;
            jgap <= GAP_MAX;
            if (last_col_in) state <= S_JWAIT;
          end else begin
            jgap <= jgap - 1'b1;
          end
        end
        S_JWAIT: begin
          // every column received (and every joint-quaternion and d result, which the last
          // joints may not have waited for)
          if ((col_out == c_n) && (jq_cnt == c_n) && (d_cnt == c_n)) state <= S_DONE;
        end
        S_DONE: begin
          out_busy <= 1'b0;
          out_done <= 1'b1;
          state <= S_IDLE;
        end
        default: state <= S_IDLE;
      endcase

      // columns (the screw transport's Jacobian use)
      if (col_we) col_out <= col_out + 1'b1;
    end
  end

  // ---- per-joint results -----------------------------------------------------------------------------
  // frame i stored at the end of its step: QF_i, and p_i (pF, or the prismatic origin)
  wire fr_we = ((state == S_WAIT2) && (have_q2 || qm_ovalid) && pf_now) || ((state == S_WAITP) && pp_ovalid);
  wire col_we = st_ovalid && ((state == S_JAC) || (state == S_JWAIT));
  wire [JI_W-1:0] col_j = col_out[JI_W-1:0];
  assign ji_a = ji;
  assign st_j_a = st_j;
  wire [3*P_W-1:0] fr_p = (state == S_WAITP) ? {pp_o[2], pp_o[1], pp_o[0]} : {pf_cur[2], pf_cur[1], pf_cur[0]};
  wire [3*JW_W-1:0] col_w;
  wire [3*JV_W-1:0] col_v;
  wire [3*P_W-1:0] col_p;
  ts_ram #(.W(4*Q_W), .AW(JI_W), .R(1)) u_rjq (
    .clk(clk), .in_we(jq_valid), .in_waddr(jq_j), .in_wdata({jq_o[3], jq_o[2], jq_o[1], jq_o[0]}),
    .in_raddr(ji), .out_rdata({rjq_j[3], rjq_j[2], rjq_j[1], rjq_j[0]}));
  ts_ram #(.W(L_W), .AW(JI_W), .R(1)) u_rd (
    .clk(clk), .in_we(d_valid), .in_waddr(d_j), .in_wdata(d_o), .in_raddr(ji), .out_rdata(rd_j));
  ts_ram #(.W(4*Q_W), .AW(JI_W), .R(1)) u_rqf (
    .clk(clk), .in_we(fr_we), .in_waddr(ji), .in_wdata({qf[3], qf[2], qf[1], qf[0]}),
    .in_raddr(st_j), .out_rdata({rqf_st[3], rqf_st[2], rqf_st[1], rqf_st[0]}));
  ts_ram #(.W(3*P_W), .AW(JI_W), .R(2)) u_rp (
    .clk(clk), .in_we(fr_we), .in_waddr(ji), .in_wdata(fr_p),
    .in_raddr({in_col_addr, st_j}), .out_rdata({col_p, rp_st[2], rp_st[1], rp_st[0]}));
  ts_ram #(.W(3*JW_W), .AW(JI_W), .R(1)) u_rw (
    .clk(clk), .in_we(col_we), .in_waddr(col_j), .in_wdata({st_w[2], st_w[1], st_w[0]}),
    .in_raddr(in_col_addr), .out_rdata(col_w));
  ts_ram #(.W(3*JV_W), .AW(JI_W), .R(1)) u_rv (
    .clk(clk), .in_we(col_we), .in_waddr(col_j), .in_wdata({st_v[2], st_v[1], st_v[0]}),
    .in_raddr(in_col_addr), .out_rdata(col_v));

  // ---- column read port -----------------------------------------------------------------------------
  always @(posedge clk) begin
    if (rst) begin
      out_col_w_x <= {JW_W{1'b0}}; out_col_w_y <= {JW_W{1'b0}}; out_col_w_z <= {JW_W{1'b0}};
      out_col_v_x <= {JV_W{1'b0}}; out_col_v_y <= {JV_W{1'b0}}; out_col_v_z <= {JV_W{1'b0}};
      out_col_p_x <= {P_W{1'b0}};  out_col_p_y <= {P_W{1'b0}};  out_col_p_z <= {P_W{1'b0}};
    end else begin
      {out_col_w_z, out_col_w_y, out_col_w_x} <= col_w;
      {out_col_v_z, out_col_v_y, out_col_v_x} <= col_v;
      {out_col_p_z, out_col_p_y, out_col_p_x} <= col_p;
    end
  end

endmodule

`default_nettype wire
