// SPDX-License-Identifier: Apache-2.0
// tensor-servo: sine and cosine of a binary angle, bit-exact with ts::sincos_turns<Fmt>
// (model/include/tensor_servo/sincos.hpp).  The angle u (turn_t, U_W bits, turns modulo one) splits
// into [quadrant : 2][index : T_BITS][residual : R = U_W - 2 - T_BITS]; the quarter-wave table ROM
// (ROM_FILE, generated from the model by scripts/gen_rtl_data.py) holds S_k = sin(k pi / 2^(T+1)),
// C_k = cos(...) in tab_t, and the residual angle d is rotated in by eight multiplies:
//   d  = cvt<delta_t>(residual 2^-U_W * two_pi)     d2 = cvt<dsq_t>(d d)       h = d2 / 2 (exact)
//   e  = cvt<dsq_t>(d2 * sixth)                      de = cvt<delta_t>(d e)     sd = cvt<delta_t>(d - de)
//   Sh, Ch, Csd, Ssd = cvt<trig_acc_t>(S h, C h, C sd, S sd)
//   sn = cvt<quat_t>((S - Sh) + Csd)                 cs = cvt<quat_t>((C - Ch) - Ssd)
// then the quadrant swaps and negates (negation saturates: cvt<quat_t>(-x)).  Every cvt rounds
// half up (AP_RND) and saturates (AP_SAT).  out_flags: the model's Status bits of the evaluation,
// ST_OVF_TRIG (bit 2) for the internal formats delta_t, dsq_t, trig_acc_t and ST_OVF_QUAT (bit 3)
// for the outputs' quat_t conversions and negations; the other bits are 0.
// Latency: see LATENCY (docs/rtl/ts_sincos.md), II = 1.
// Language: Verilog 2005
`resetall
`timescale 1ns / 1ps
`default_nettype none

module ts_sincos #(
  // Binary angle width (turn_t W, I = 0)
  parameter U_W = 32,
  // Table index bits (2^T_BITS entries over a quarter turn)
  parameter T_BITS = 8,
  // Table entry width (tab_t W)
  parameter TAB_W = 27,
  // Table entry fraction bits
  parameter TAB_F = 25,
  // Residual angle width (delta_t W)
  parameter DELTA_W = 27,
  // Residual angle fraction bits
  parameter DELTA_F = 33,
  // Squared residual width (dsq_t W)
  parameter DSQ_W = 27,
  // Squared residual fraction bits
  parameter DSQ_F = 40,
  // Product accumulator width (trig_acc_t W)
  parameter ACC_W = 35,
  // Product accumulator fraction bits
  parameter ACC_F = 33,
  // Output width (quat_t W)
  parameter Q_W = 27,
  // Output fraction bits
  parameter Q_F = 25,
  // 2 pi constant width (twopi_t W)
  parameter TWOPI_W = 27,
  // 2 pi constant fraction bits
  parameter TWOPI_F = 23,
  // 2 pi raw value: round(2 pi 2^TWOPI_F)
  parameter TWOPI = 52707179,
  // 1/6 constant width (sixth_t W)
  parameter SIXTH_W = 18,
  // 1/6 constant fraction bits
  parameter SIXTH_F = 18,
  // 1/6 raw value: round(2^SIXTH_F / 6)
  parameter SIXTH = 43691,
  // Table memory file ($readmemh): word k = {S_k, C_k}, each TAB_W bits
  parameter ROM_FILE = "ts_trig_rom_default.mem",
  // Multiplier implementation: "GENERIC" or "ECP5" (see ts_mul)
  parameter TARGET = "GENERIC",
  // ECP5 wide products on three MULT18X18D (see ts_mul)
  parameter MUL3 = 0
) (
  input  wire                  clk,
  input  wire                  rst,
  input  wire                  in_valid,
  input  wire        [U_W-1:0] in_u,
  output wire                  out_valid,
  output reg  signed [Q_W-1:0] out_sin,
  output reg  signed [Q_W-1:0] out_cos,
  output wire           [15:0] out_flags
);

  `include "ts_common.vh"

  localparam R = U_W - 2 - T_BITS;
  localparam N = 1 << T_BITS;
  // Multiplier latencies of the five steps.
  localparam ML1 = ts_mul_lat(R + 1, TWOPI_W);
  localparam ML2 = ts_mul_lat(DELTA_W, DELTA_W);
  localparam ML3 = ts_mul_lat(DSQ_W, SIXTH_W);
  localparam ML4 = ts_mul_lat(DELTA_W, DSQ_W);
  localparam ML6H = ts_mul_lat(TAB_W, DSQ_W);
  localparam ML6S = ts_mul_lat(TAB_W, DELTA_W);
  localparam ML6 = ts_max(ML6H, ML6S);
  // Cycle (after the input) at which each signal is available.
  localparam RL = ts_round_lat(1);
  localparam C_D = ML1 + RL;
  localparam C_D2 = C_D + ML2 + RL;
  localparam C_E = C_D2 + ML3 + RL;
  localparam C_DE = C_E + ML4 + RL;
  localparam C_SD = C_DE + RL;
  localparam C_ACC = C_SD + ML6 + RL;
  localparam C_SC = C_ACC + 2 + RL;
  localparam LATENCY = C_SC + 2;

  // ---- the angle fields -----------------------------------------------------------------------
  wire [1:0]        quadrant = in_u[U_W-1:U_W-2];
  wire [T_BITS-1:0] index    = in_u[U_W-3:R];
  // residual, a non-negative R + 1 bit signed operand
  wire signed [R:0] residual = {1'b0, in_u[R-1:0]};

  // ---- d = cvt<delta_t>(residual * two_pi) ----------------------------------------------------
  localparam signed [TWOPI_W-1:0] K_TWOPI = TWOPI[TWOPI_W-1:0];
  localparam signed [SIXTH_W-1:0] K_SIXTH = SIXTH[SIXTH_W-1:0];
  wire signed [R+TWOPI_W:0] p1;
  ts_mul #(.A_W(R+1), .B_W(TWOPI_W), .TARGET(TARGET), .MUL3(MUL3)) u_m1 (
    .clk(clk), .rst(rst), .a(residual), .b(K_TWOPI), .p(p1));
  wire signed [DELTA_W-1:0] d;
  wire sat_d;
  ts_round_sat #(.IN_W(R+1+TWOPI_W), .SHIFT(U_W+TWOPI_F-DELTA_F), .OUT_W(DELTA_W), .SAT(1)) u_r1 (
    .clk(clk), .rst(rst), .in_x(p1), .out_y(d), .out_sat(sat_d));

  // ---- d2 = cvt<dsq_t>(d d) -------------------------------------------------------------------
  wire signed [2*DELTA_W-1:0] p2;
  ts_mul #(.A_W(DELTA_W), .B_W(DELTA_W), .TARGET(TARGET), .MUL3(MUL3)) u_m2 (
    .clk(clk), .rst(rst), .a(d), .b(d), .p(p2));
  wire signed [DSQ_W-1:0] d2;
  wire sat_d2;
  ts_round_sat #(.IN_W(2*DELTA_W), .SHIFT(2*DELTA_F-DSQ_F), .OUT_W(DSQ_W), .SAT(1)) u_r2 (
    .clk(clk), .rst(rst), .in_x(p2), .out_y(d2), .out_sat(sat_d2));

  // ---- e = cvt<dsq_t>(d2 sixth) ---------------------------------------------------------------
  wire signed [DSQ_W+SIXTH_W-1:0] p3;
  ts_mul #(.A_W(DSQ_W), .B_W(SIXTH_W), .TARGET(TARGET), .MUL3(MUL3)) u_m3 (
    .clk(clk), .rst(rst), .a(d2), .b(K_SIXTH), .p(p3));
  wire signed [DSQ_W-1:0] e;
  wire sat_e;
  ts_round_sat #(.IN_W(DSQ_W+SIXTH_W), .SHIFT(SIXTH_F), .OUT_W(DSQ_W), .SAT(1)) u_r3 (
    .clk(clk), .rst(rst), .in_x(p3), .out_y(e), .out_sat(sat_e));

  // ---- de = cvt<delta_t>(d e) -----------------------------------------------------------------
  wire [DELTA_W-1:0] d_at_e;
  ts_delay #(.W(DELTA_W), .DEPTH(C_E-C_D)) u_dd1 (.clk(clk), .rst(rst), .din(d), .dout(d_at_e));
  wire signed [DELTA_W+DSQ_W-1:0] p4;
  ts_mul #(.A_W(DELTA_W), .B_W(DSQ_W), .TARGET(TARGET), .MUL3(MUL3)) u_m4 (
    .clk(clk), .rst(rst), .a(d_at_e), .b(e), .p(p4));
  wire signed [DELTA_W-1:0] de;
  wire sat_de;
  ts_round_sat #(.IN_W(DELTA_W+DSQ_W), .SHIFT(DSQ_F), .OUT_W(DELTA_W), .SAT(1)) u_r4 (
    .clk(clk), .rst(rst), .in_x(p4), .out_y(de), .out_sat(sat_de));

  // ---- sd = cvt<delta_t>(d - de): the difference enters the rounding stage (SHIFT 0: no adder) --
  wire [DELTA_W-1:0] d_at_de;
  ts_delay #(.W(DELTA_W), .DEPTH(C_DE-C_E)) u_dd2 (.clk(clk), .rst(rst), .din(d_at_e), .dout(d_at_de));
  wire signed [DELTA_W:0] dsub = {d_at_de[DELTA_W-1], d_at_de} - {de[DELTA_W-1], de};
  wire signed [DELTA_W-1:0] sd;
  wire sat_sd;
  ts_round_sat #(.IN_W(DELTA_W+1), .SHIFT(0), .OUT_W(DELTA_W), .SAT(1)) u_r5 (
    .clk(clk), .rst(rst), .in_x(dsub), .out_y(sd), .out_sat(sat_sd));

  // ---- table: S, C of the index, read so that they arrive with sd -----------------------------
  // A ROM in logic, read in two registered stages: four banks indexed by the low index
  // bits, then the bank selected by the high bits.  (ECP5 EBR: yosys maps it without the output
  // register, whose 5.8 ns clock-to-output at speed grade 6 alone nearly fills a 150 MHz cycle.)
  // (T_BITS >= 3.)
  localparam LO = T_BITS - 2;
  (* rom_style = "logic" *) reg [2*TAB_W-1:0] rom [0:N-1];
  initial $readmemh(ROM_FILE, rom);
  wire [T_BITS-1:0] index_rd;
  ts_delay #(.W(T_BITS), .DEPTH(C_SD-2)) u_id (.clk(clk), .rst(rst), .din(index), .dout(index_rd));
  wire [4*2*TAB_W-1:0] banks;
  reg [1:0] bank_sel;
  genvar gb;
  generate
    for (gb = 0; gb < 4; gb = gb + 1) begin : g_bank
      localparam [1:0] BANK = gb;
      reg [2*TAB_W-1:0] q;
      always @(posedge clk) q <= rom[{BANK, index_rd[LO-1:0]}];
      assign banks[gb*2*TAB_W +: 2*TAB_W] = q;
    end
  endgenerate
  always @(posedge clk) bank_sel <= index_rd[T_BITS-1:LO];
  // bank select as a 4:1 multiplexer tree (ts_sel): the part-select banks[bank_sel*2*TAB_W +: ...]
  // became a MULT18X18D for the index and a barrel shifter, the FK engine's critical path (79 MHz)
  wire [2*TAB_W-1:0] bank_q;
  ts_sel #(.W(2*TAB_W), .N(4), .IW(2)) u_bank (.in_vec(banks), .in_idx(bank_sel), .out_el(bank_q));
  reg [2*TAB_W-1:0] rom_q;
  always @(posedge clk) rom_q <= bank_q;

  // ---- Sh, Ch, Csd, Ssd = cvt<trig_acc_t>(...) --------------------------------------------------
  // h = d2 / 2 is d2 with one more fraction bit; d2 and sd are delayed to meet the table words
  // (and to equalise the two multiplier latencies).
  wire signed [DSQ_W-1:0] h;
  ts_delay #(.W(DSQ_W), .DEPTH(C_SD-C_D2+ML6-ML6H)) u_hd (.clk(clk), .rst(rst), .din(d2), .dout(h));
  wire signed [DELTA_W-1:0] sd_m;
  ts_delay #(.W(DELTA_W), .DEPTH(ML6-ML6S)) u_sdd (.clk(clk), .rst(rst), .din(sd), .dout(sd_m));
  wire signed [TAB_W-1:0] tab_s_h, tab_c_h, tab_s_s, tab_c_s;
  ts_delay #(.W(2*TAB_W), .DEPTH(ML6-ML6H)) u_tdh (.clk(clk), .rst(rst), .din(rom_q), .dout({tab_s_h, tab_c_h}));
  ts_delay #(.W(2*TAB_W), .DEPTH(ML6-ML6S)) u_tds (.clk(clk), .rst(rst), .din(rom_q), .dout({tab_s_s, tab_c_s}));
  wire signed [TAB_W+DSQ_W-1:0] p_sh, p_ch;
  wire signed [TAB_W+DELTA_W-1:0] p_csd, p_ssd;
  ts_mul #(.A_W(TAB_W), .B_W(DSQ_W), .TARGET(TARGET), .MUL3(MUL3)) u_msh (
    .clk(clk), .rst(rst), .a(tab_s_h), .b(h), .p(p_sh));
  ts_mul #(.A_W(TAB_W), .B_W(DSQ_W), .TARGET(TARGET), .MUL3(MUL3)) u_mch (
    .clk(clk), .rst(rst), .a(tab_c_h), .b(h), .p(p_ch));
  ts_mul #(.A_W(TAB_W), .B_W(DELTA_W), .TARGET(TARGET), .MUL3(MUL3)) u_mcs (
    .clk(clk), .rst(rst), .a(tab_c_s), .b(sd_m), .p(p_csd));
  ts_mul #(.A_W(TAB_W), .B_W(DELTA_W), .TARGET(TARGET), .MUL3(MUL3)) u_mss (
    .clk(clk), .rst(rst), .a(tab_s_s), .b(sd_m), .p(p_ssd));
  wire signed [ACC_W-1:0] a_sh, a_ch, a_csd, a_ssd;
  wire [3:0] sat_acc;
  ts_round_sat #(.IN_W(TAB_W+DSQ_W), .SHIFT(TAB_F+DSQ_F+1-ACC_F), .OUT_W(ACC_W), .SAT(1)) u_rsh (
    .clk(clk), .rst(rst), .in_x(p_sh), .out_y(a_sh), .out_sat(sat_acc[0]));
  ts_round_sat #(.IN_W(TAB_W+DSQ_W), .SHIFT(TAB_F+DSQ_F+1-ACC_F), .OUT_W(ACC_W), .SAT(1)) u_rch (
    .clk(clk), .rst(rst), .in_x(p_ch), .out_y(a_ch), .out_sat(sat_acc[1]));
  ts_round_sat #(.IN_W(TAB_W+DELTA_W), .SHIFT(TAB_F+DELTA_F-ACC_F), .OUT_W(ACC_W), .SAT(1)) u_rcs (
    .clk(clk), .rst(rst), .in_x(p_csd), .out_y(a_csd), .out_sat(sat_acc[2]));
  ts_round_sat #(.IN_W(TAB_W+DELTA_W), .SHIFT(TAB_F+DELTA_F-ACC_F), .OUT_W(ACC_W), .SAT(1)) u_rss (
    .clk(clk), .rst(rst), .in_x(p_ssd), .out_y(a_ssd), .out_sat(sat_acc[3]));

  // ---- sn = (S - Sh) + Csd, cs = (C - Ch) - Ssd: two registered adder levels ------------------
  // Exact sum format: fraction SF = max(TAB_F, ACC_F), integer bits max + 2.
  localparam SF = ts_max(TAB_F, ACC_F);
  localparam S_W = ts_max(TAB_W - TAB_F, ACC_W - ACC_F) + 2 + SF;
  wire [2*TAB_W-1:0] tab_acc;
  ts_delay #(.W(2*TAB_W), .DEPTH(C_ACC-C_SD)) u_tda (.clk(clk), .rst(rst), .din(rom_q), .dout(tab_acc));
  wire signed [S_W-1:0] e_s, e_c, e_sh, e_ch, e_csd, e_ssd;
  ts_resize #(.IN_W(TAB_W), .LSH(SF-TAB_F), .OUT_W(S_W)) u_es (.in(tab_acc[2*TAB_W-1:TAB_W]), .out(e_s));
  ts_resize #(.IN_W(TAB_W), .LSH(SF-TAB_F), .OUT_W(S_W)) u_ec (.in(tab_acc[TAB_W-1:0]), .out(e_c));
  ts_resize #(.IN_W(ACC_W), .LSH(SF-ACC_F), .OUT_W(S_W)) u_esh (.in(a_sh), .out(e_sh));
  ts_resize #(.IN_W(ACC_W), .LSH(SF-ACC_F), .OUT_W(S_W)) u_ech (.in(a_ch), .out(e_ch));
  ts_resize #(.IN_W(ACC_W), .LSH(SF-ACC_F), .OUT_W(S_W)) u_ecs (.in(a_csd), .out(e_csd));
  ts_resize #(.IN_W(ACC_W), .LSH(SF-ACC_F), .OUT_W(S_W)) u_ess (.in(a_ssd), .out(e_ssd));
  reg signed [S_W-1:0] sn1, sn2, cs1, cs2, sn_sum, cs_sum;
  always @(posedge clk) begin
    if (rst) begin
      sn1 <= {S_W{1'b0}}; sn2 <= {S_W{1'b0}}; cs1 <= {S_W{1'b0}}; cs2 <= {S_W{1'b0}};
      sn_sum <= {S_W{1'b0}}; cs_sum <= {S_W{1'b0}};
    end else begin
      sn1 <= e_s - e_sh;
      sn2 <= e_csd;
      cs1 <= e_c - e_ch;
      cs2 <= e_ssd;
      sn_sum <= sn1 + sn2;
      cs_sum <= cs1 - cs2;
    end
  end
  wire signed [Q_W-1:0] sn, cs;
  wire [1:0] sat_sc;
  ts_round_sat #(.IN_W(S_W), .SHIFT(SF-Q_F), .OUT_W(Q_W), .SAT(1)) u_rsn (
    .clk(clk), .rst(rst), .in_x(sn_sum), .out_y(sn), .out_sat(sat_sc[0]));
  ts_round_sat #(.IN_W(S_W), .SHIFT(SF-Q_F), .OUT_W(Q_W), .SAT(1)) u_rcs2 (
    .clk(clk), .rst(rst), .in_x(cs_sum), .out_y(cs), .out_sat(sat_sc[1]));

  // ---- quadrant: saturating negations (registered), then swaps -----------------------------------
  wire [1:0] quadrant_q;
  ts_delay #(.W(2), .DEPTH(C_SC+1)) u_qd (.clk(clk), .rst(rst), .din(quadrant), .dout(quadrant_q));
  localparam signed [Q_W-1:0] Q_MIN = {1'b1, {(Q_W-1){1'b0}}};
  localparam signed [Q_W-1:0] Q_MAX = {1'b0, {(Q_W-1){1'b1}}};
  reg signed [Q_W-1:0] sn_r, cs_r, neg_sn, neg_cs;
  reg sn_min, cs_min;
  always @(posedge clk) begin
    if (rst) begin
      sn_r <= {Q_W{1'b0}}; cs_r <= {Q_W{1'b0}}; neg_sn <= {Q_W{1'b0}}; neg_cs <= {Q_W{1'b0}};
      sn_min <= 1'b0; cs_min <= 1'b0;
    end else begin
      sn_r <= sn;
      cs_r <= cs;
      neg_sn <= (sn == Q_MIN) ? Q_MAX : -sn;
      neg_cs <= (cs == Q_MIN) ? Q_MAX : -cs;
      sn_min <= (sn == Q_MIN);
      cs_min <= (cs == Q_MIN);
    end
  end
  reg sat_q;
  always @(posedge clk) begin
    if (rst) begin
      out_sin <= {Q_W{1'b0}};
      out_cos <= {Q_W{1'b0}};
      sat_q <= 1'b0;
    end else begin
      case (quadrant_q)
        2'd0: begin out_sin <= sn_r;   out_cos <= cs_r;   sat_q <= 1'b0;            end
        2'd1: begin out_sin <= cs_r;   out_cos <= neg_sn; sat_q <= sn_min;          end
        2'd2: begin out_sin <= neg_sn; out_cos <= neg_cs; sat_q <= sn_min | cs_min; end
        default: begin out_sin <= neg_cs; out_cos <= sn_r; sat_q <= cs_min;         end
      endcase
    end
  end

  // ---- saturation flags, each delayed to the output ---------------------------------------------
  wire [6:0] sat_at_out;
  ts_delay #(.W(1), .DEPTH(LATENCY-C_D))   u_f0 (.clk(clk), .rst(rst), .din(sat_d),      .dout(sat_at_out[0]));
  ts_delay #(.W(1), .DEPTH(LATENCY-C_D2))  u_f1 (.clk(clk), .rst(rst), .din(sat_d2),     .dout(sat_at_out[1]));
  ts_delay #(.W(1), .DEPTH(LATENCY-C_E))   u_f2 (.clk(clk), .rst(rst), .din(sat_e),      .dout(sat_at_out[2]));
  ts_delay #(.W(1), .DEPTH(LATENCY-C_DE))  u_f3 (.clk(clk), .rst(rst), .din(sat_de),     .dout(sat_at_out[3]));
  ts_delay #(.W(1), .DEPTH(LATENCY-C_SD))  u_f4 (.clk(clk), .rst(rst), .din(sat_sd),     .dout(sat_at_out[4]));
  ts_delay #(.W(1), .DEPTH(LATENCY-C_ACC)) u_f5 (.clk(clk), .rst(rst), .din(|sat_acc),   .dout(sat_at_out[5]));
  ts_delay #(.W(1), .DEPTH(LATENCY-C_SC))  u_f6 (.clk(clk), .rst(rst), .din(|sat_sc),    .dout(sat_at_out[6]));
  localparam ST_TRIG = 2, ST_QUAT = 3;
  assign out_flags = ({15'd0, |sat_at_out[5:0]} << ST_TRIG) | ({15'd0, sat_q | sat_at_out[6]} << ST_QUAT);

  ts_delay #(.W(1), .DEPTH(LATENCY)) u_valid (.clk(clk), .rst(rst), .din(in_valid), .dout(out_valid));

endmodule

`default_nettype wire
