// SPDX-License-Identifier: Apache-2.0
// tensor-servo: the joint quaternion of a revolute joint, bit-exact with ts::joint_quat<Fmt>
// (model/include/tensor_servo/kinematics.hpp):
//   u = wrap<turn_t>(angle * kturn)       half joint angle in turns (AP_RND, then modulo one turn)
//   (sn, cs) = sincos_turns(u)            ts_sincos
//   out = (cs, cvt<quat_t>(sn * axis))    (cos(theta/2), sin(theta/2) a), theta = s q
// angle in angle_t (ANG_W, ANG_F), kturn = s / (4 pi) in kturn_t (KT_W, KT_F), axis and output in
// quat_t.  Latency ts_mul_lat(ANG_W, KT_W) + 2 + ts_sincos latency + ts_mul_lat(Q_W, Q_W) + 2,
// II = 1.  out_flags: the model's Status bits, ts_sincos's (ST_OVF_TRIG, ST_OVF_QUAT) and
// ST_OVF_QUAT (bit 3) when an output component saturated.
// Language: Verilog 2005
`resetall
`timescale 1ns / 1ps
`default_nettype none

module ts_joint_quat #(
  // Joint value width (angle_t W)
  parameter ANG_W = 32,
  // Joint value fraction bits
  parameter ANG_F = 28,
  // Joint constant s / (4 pi) width (kturn_t W)
  parameter KT_W = 30,
  // Joint constant fraction bits
  parameter KT_F = 31,
  // Binary angle width (turn_t W, I = 0)
  parameter U_W = 32,
  // Table index bits
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
  // Quaternion width (quat_t W): axis, sin/cos and output
  parameter Q_W = 27,
  // Quaternion fraction bits
  parameter Q_F = 25,
  // 2 pi constant width (twopi_t W)
  parameter TWOPI_W = 27,
  // 2 pi constant fraction bits
  parameter TWOPI_F = 23,
  // 2 pi raw value
  parameter TWOPI = 52707179,
  // 1/6 constant width (sixth_t W)
  parameter SIXTH_W = 18,
  // 1/6 constant fraction bits
  parameter SIXTH_F = 18,
  // 1/6 raw value
  parameter SIXTH = 43691,
  // Table memory file of ts_sincos
  parameter ROM_FILE = "ts_trig_rom_default.mem",
  // Multiplier implementation: "GENERIC" or "ECP5" (see ts_mul)
  parameter TARGET = "GENERIC",
  // ECP5 wide products on three MULT18X18D (see ts_mul)
  parameter MUL3 = 0
) (
  input  wire                    clk,
  input  wire                    rst,
  input  wire                    in_valid,
  input  wire signed [ANG_W-1:0] in_angle,
  input  wire signed [KT_W-1:0]  in_kturn,
  input  wire signed [Q_W-1:0]   in_axis_x,
  input  wire signed [Q_W-1:0]   in_axis_y,
  input  wire signed [Q_W-1:0]   in_axis_z,
  output wire                    out_valid,
  output wire signed [Q_W-1:0]   out_w,
  output wire signed [Q_W-1:0]   out_x,
  output wire signed [Q_W-1:0]   out_y,
  output wire signed [Q_W-1:0]   out_z,
  output wire             [15:0] out_flags
);

  `include "ts_common.vh"

  localparam MLK = ts_mul_lat(ANG_W, KT_W);
  localparam MLQ = ts_mul_lat(Q_W, Q_W);
  localparam R = U_W - 2 - T_BITS;
  // ts_sincos latency (same formula as its LATENCY).
  localparam RL = ts_round_lat(1);
  localparam LS = ts_mul_lat(R + 1, TWOPI_W) + ts_mul_lat(DELTA_W, DELTA_W) + ts_mul_lat(DSQ_W, SIXTH_W)
                + ts_mul_lat(DELTA_W, DSQ_W) + ts_max(ts_mul_lat(TAB_W, DSQ_W), ts_mul_lat(TAB_W, DELTA_W))
                + 7 * RL + 4;
  localparam C_U = MLK + RL;
  localparam C_SC = C_U + LS;
  // Latency: C_SC + MLQ + RL cycles (the valid follows the sincos valid, then MLQ + RL registers).

  // ---- u = wrap<turn_t>(angle kturn) -----------------------------------------------------------
  wire signed [ANG_W+KT_W-1:0] pk;
  ts_mul #(.A_W(ANG_W), .B_W(KT_W), .TARGET(TARGET), .MUL3(MUL3)) u_mk (
    .clk(clk), .rst(rst), .a(in_angle), .b(in_kturn), .p(pk));
  wire signed [U_W-1:0] u;
  wire unused_wrap_flag;
  ts_round_sat #(.IN_W(ANG_W+KT_W), .SHIFT(ANG_F+KT_F-U_W), .OUT_W(U_W), .SAT(0)) u_wrap (
    .clk(clk), .rst(rst), .in_x(pk), .out_y(u), .out_sat(unused_wrap_flag));

  // ---- sin, cos -------------------------------------------------------------------------------
  wire wrap_valid;
  ts_delay #(.W(1), .DEPTH(C_U)) u_uv (.clk(clk), .rst(rst), .din(in_valid), .dout(wrap_valid));
  wire sc_valid;
  wire signed [Q_W-1:0] sn, cs;
  wire [15:0] sc_flags;
  ts_sincos #(
    .U_W(U_W), .T_BITS(T_BITS), .TAB_W(TAB_W), .TAB_F(TAB_F), .DELTA_W(DELTA_W), .DELTA_F(DELTA_F),
    .DSQ_W(DSQ_W), .DSQ_F(DSQ_F), .ACC_W(ACC_W), .ACC_F(ACC_F), .Q_W(Q_W), .Q_F(Q_F),
    .TWOPI_W(TWOPI_W), .TWOPI_F(TWOPI_F), .TWOPI(TWOPI), .SIXTH_W(SIXTH_W), .SIXTH_F(SIXTH_F),
    .SIXTH(SIXTH), .ROM_FILE(ROM_FILE), .TARGET(TARGET), .MUL3(MUL3)
  ) u_sincos (
    .clk(clk), .rst(rst), .in_valid(wrap_valid), .in_u(u), .out_valid(sc_valid),
    .out_sin(sn), .out_cos(cs), .out_flags(sc_flags));

  // ---- (cs, sn axis) ---------------------------------------------------------------------------
  wire [3*Q_W-1:0] axis_d;
  ts_delay #(.W(3*Q_W), .DEPTH(C_SC)) u_ad (
    .clk(clk), .rst(rst), .din({in_axis_z, in_axis_y, in_axis_x}), .dout(axis_d));
  wire [2:0] sat_v;
  wire signed [Q_W-1:0] v [0:2];
  genvar i;
  generate
    for (i = 0; i < 3; i = i + 1) begin : g_v
      wire signed [2*Q_W-1:0] pv;
      ts_mul #(.A_W(Q_W), .B_W(Q_W), .TARGET(TARGET), .MUL3(MUL3)) u_mv (
        .clk(clk), .rst(rst), .a(sn), .b(axis_d[Q_W*i +: Q_W]), .p(pv));
      ts_round_sat #(.IN_W(2*Q_W), .SHIFT(Q_F), .OUT_W(Q_W), .SAT(1)) u_rv (
        .clk(clk), .rst(rst), .in_x(pv), .out_y(v[i]), .out_sat(sat_v[i]));
    end
  endgenerate
  assign out_x = v[0];
  assign out_y = v[1];
  assign out_z = v[2];
  wire [Q_W-1:0] cs_d;
  ts_delay #(.W(Q_W), .DEPTH(MLQ+RL)) u_cd (.clk(clk), .rst(rst), .din(cs), .dout(cs_d));
  assign out_w = cs_d;
  // ts_sincos raises only ST_OVF_TRIG and ST_OVF_QUAT (bits 2, 3): only those are delayed
  localparam ST_TRIG = 2, ST_QUAT = 3;
  wire [1:0] sc_tq_d;
  ts_delay #(.W(2), .DEPTH(MLQ+RL)) u_sd (.clk(clk), .rst(rst), .din(sc_flags[ST_QUAT:ST_TRIG]), .dout(sc_tq_d));
  wire unused_sc_flags = &{1'b0, sc_flags[15:ST_QUAT+1], sc_flags[ST_TRIG-1:0]};
  assign out_flags = ({15'd0, sc_tq_d[0]} << ST_TRIG) | ({15'd0, sc_tq_d[1] | (|sat_v)} << ST_QUAT);
  ts_delay #(.W(1), .DEPTH(MLQ+RL)) u_valid (.clk(clk), .rst(rst), .din(sc_valid), .dout(out_valid));

endmodule

`default_nettype wire
