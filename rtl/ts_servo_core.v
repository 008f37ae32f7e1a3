// tensor-servo: the servo core top (docs/rtl/ts_servo_core.md, docs/theory_of_operation.md).
//
// Joins the register block (ts_servo_regs, generated), the commit step (ts_core_commit), the FK /
// Jacobian engine (ts_core_fk), the servo law (ts_core_law) and the solver (ts_core_solve) under
// one sequencer, with the AXI4-Stream packet handling and the warm-start / virtual-mode state:
//
//   in  packet (1 + n + 13 words): control (bit 0 COLD, bit 1 LOAD_Q), q_1..q_n (angle_t),
//       U quaternion w x y z (quat_t), position x y z (pos_t), omega x y z, v x y z (vel_t)
//   out packet (2n + 8 words): q'_j (qd_t), q_next_j (angle_t), ep (perr_t, 3), eo (rot_t, 3),
//       status (the tick's Status bits; bit 30 malformed input packet), tick count
//
// Sequencer: IDLE -> IN -> PREP (q and warm start into the engines) -> FK -> LAW (columns through
// the law's basis port into the solver) -> V -> SOLVE -> OUT.  CTRL.COMMIT is held while a tick
// runs; after a successful commit a loader (LOAD) writes the engines' configuration ports from
// the commit's shadow outputs and the register block's joint words (whose writes wait from the
// commit's start until LOAD ends).  Ticks run only while CFG_OK and CTRL.RUN (TREADY low otherwise).
`resetall
`timescale 1ns / 1ps
`default_nettype none

module ts_servo_core #(
  parameter NMAX = 8,
  parameter CONFIG = 0,
  parameter TARGET = "GENERIC",
  parameter TRIG_ROM = (CONFIG == 0) ? "ts_trig_rom_default.mem" : "ts_trig_rom_compact.mem",
  parameter RECIP_ROM = (CONFIG == 0) ? "ts_recip_rom_default.mem" : "ts_recip_rom_compact.mem",
  parameter ROTVEC_ROM = (CONFIG == 0) ? "ts_rotvec_rom_default.mem" : "ts_rotvec_rom_compact.mem",
  // Products per multiplier of the FK and law engines' product units (ts_mul_bank; 1: fully
  // parallel).  The bits never depend on it; the cycle count of a tick does (docs/resources.md).
  // Default: the smallest fold at which the core's MULT18X18D fit the budget of its device
  // (default configuration: 9, about 143 of LFE5U-85F's 156; compact: 7, about 44 of LFE5U-45F's
  // 72; up to 7 it costs no column throughput, as the solver takes a column per 7 cycles).
  parameter FOLD = (CONFIG == 0) ? 9 : 7,
  // 1: the FK and law engines' folded banks hold operands and products in shift chains (the same
  // bits and cycles; more registers and LUTs, shorter wires: docs/resources.md has both on ECP5).
  parameter CHAIN = 0,
  // 1: ECP5 products with both operands of 19-33 bits on three MULT18X18D instead of four
  // (ts_mul MUL3: the same bits and cycles, more LUTs; docs/resources.md).  No effect on "GENERIC"
  // or on the compact configuration, whose operands are all <= 18 bits.
  parameter MUL3 = 0
) (
  input  wire        clk,
  input  wire        rst,
  // AXI4-Lite slave (registers)
  input  wire [11:0] s_axil_awaddr,
  input  wire [2:0]  s_axil_awprot,
  input  wire        s_axil_awvalid,
  output wire        s_axil_awready,
  input  wire [31:0] s_axil_wdata,
  input  wire [3:0]  s_axil_wstrb,
  input  wire        s_axil_wvalid,
  output wire        s_axil_wready,
  output wire [1:0]  s_axil_bresp,
  output wire        s_axil_bvalid,
  input  wire        s_axil_bready,
  input  wire [11:0] s_axil_araddr,
  input  wire [2:0]  s_axil_arprot,
  input  wire        s_axil_arvalid,
  output wire        s_axil_arready,
  output wire [31:0] s_axil_rdata,
  output wire [1:0]  s_axil_rresp,
  output wire        s_axil_rvalid,
  input  wire        s_axil_rready,
  // AXI4-Stream slave (input packets)
  input  wire [31:0] s_axis_tdata,
  input  wire        s_axis_tvalid,
  output wire        s_axis_tready,
  input  wire        s_axis_tlast,
  // AXI4-Stream master (output packets)
  output reg  [31:0] m_axis_tdata,
  output wire        m_axis_tvalid,
  input  wire        m_axis_tready,
  output wire        m_axis_tlast
);

  // ---- widths (the register block's and the engines' defaults for CONFIG) -------------------------
  localparam integer ANGLE_W = (CONFIG == 0) ? 32 : 18;
  localparam integer DT_W = (CONFIG == 0) ? 32 : 18;
  localparam integer GAIN_W = (CONFIG == 0) ? 27 : 18;
  localparam integer KLIM_W = (CONFIG == 0) ? 27 : 18;
  localparam integer LCHAR_W = 18;
  localparam integer LEN_W = (CONFIG == 0) ? 27 : 18;
  localparam integer MU_W = 18;
  localparam integer QD_W = (CONFIG == 0) ? 27 : 18;
  localparam integer QUAT_W = (CONFIG == 0) ? 27 : 18;
  localparam integer SCALE_W = (CONFIG == 0) ? 27 : 18;
  localparam integer KT_W = (CONFIG == 0) ? 30 : 18;
  localparam integer P_W = (CONFIG == 0) ? 32 : 24;      // pos_t
  localparam integer V_W = (CONFIG == 0) ? 27 : 18;      // vel_t
  localparam integer PE_W = (CONFIG == 0) ? 27 : 18;     // perr_t
  localparam integer RO_W = (CONFIG == 0) ? 27 : 18;     // rot_t
  localparam integer JW_W = (CONFIG == 0) ? 27 : 18;     // jw_t
  localparam integer JV_W = (CONFIG == 0) ? 27 : 18;     // jv_t
  localparam integer CD_W = (CONFIG == 0) ? 32 : 18;     // ts_core_solve data port
  localparam integer JI_W = (NMAX > 1) ? $clog2(NMAX) : 1;
  localparam integer JN = 1 << JI_W;                     // joint arrays (addressable entries)
  localparam integer WI_W = JI_W + 4;                    // packet word index
  localparam integer LA_W = JI_W + 5;                    // engine configuration address

  localparam [3:0] S_IDLE = 4'd0, S_IN = 4'd1, S_CMT = 4'd2, S_LOAD = 4'd3, S_PREP = 4'd4,
                   S_FK = 4'd5, S_LAW = 4'd6, S_V = 4'd7, S_SOLVE = 4'd8, S_OUT = 4'd9;

  // ---- register block --------------------------------------------------------------------------
  wire ctrl_run, ctrl_commit, ctrl_clear, ctrl_virtual;
  wire [17:0] flags_q;
  reg  [17:0] flags_set;
  reg  [31:0] tick_count, tick_cycles;
  wire st_busy, cfg_ok, cfg_err, cfg_busy;
  wire [7:0] err_code, err_joint;
  wire joint_hold;                // the register block's joint writes wait (commit and load)

  wire [7:0] r_njoints, r_sweeps;
  wire r_err_b, r_err_only;
  wire [3:0] r_leak;
  wire signed [GAIN_W-1:0] r_kp, r_ko;
  wire signed [LCHAR_W-1:0] r_lchar;
  wire signed [KLIM_W-1:0] r_klim;
  wire signed [DT_W-1:0] r_dt;
  wire signed [QUAT_W-1:0] r_bqw, r_bqx, r_bqy, r_bqz, r_tqw, r_tqx, r_tqy, r_tqz;
  wire signed [LEN_W-1:0] r_bpx, r_bpy, r_bpz, r_tpx, r_tpy, r_tpz;
  wire [NMAX-1:0] r_pri, r_lim, r_vlim;
  wire [NMAX*QUAT_W-1:0] r_oqw, r_oqx, r_oqy, r_oqz, r_ax, r_ay, r_az;
  wire [NMAX*LEN_W-1:0] r_opx, r_opy, r_opz;
  wire [NMAX*SCALE_W-1:0] r_scale;
  wire [NMAX*ANGLE_W-1:0] r_lower, r_upper;
  wire [NMAX*QD_W-1:0] r_vmax;
  wire [NMAX*MU_W-1:0] r_mu;

  ts_servo_regs #(.NMAX(NMAX), .CONFIG(CONFIG)) u_regs (
    .clk(clk), .rst(rst),
    .s_axil_awaddr(s_axil_awaddr), .s_axil_awprot(s_axil_awprot), .s_axil_awvalid(s_axil_awvalid),
    .s_axil_awready(s_axil_awready), .s_axil_wdata(s_axil_wdata), .s_axil_wstrb(s_axil_wstrb),
    .s_axil_wvalid(s_axil_wvalid), .s_axil_wready(s_axil_wready), .s_axil_bresp(s_axil_bresp),
    .s_axil_bvalid(s_axil_bvalid), .s_axil_bready(s_axil_bready), .s_axil_araddr(s_axil_araddr),
    .s_axil_arprot(s_axil_arprot), .s_axil_arvalid(s_axil_arvalid), .s_axil_arready(s_axil_arready),
    .s_axil_rdata(s_axil_rdata), .s_axil_rresp(s_axil_rresp), .s_axil_rvalid(s_axil_rvalid),
    .s_axil_rready(s_axil_rready),
    .out_ctrl_run(ctrl_run), .out_ctrl_commit(ctrl_commit), .out_ctrl_clear(ctrl_clear),
    .out_ctrl_virtual(ctrl_virtual),
    .in_status_busy(st_busy), .in_status_cfg_ok(cfg_ok), .in_status_cfg_err(cfg_err),
    .in_status_cfg_busy(cfg_busy), .in_cfg_error_code(err_code), .in_cfg_error_joint(err_joint),
    .in_flags_set(flags_set), .out_flags(flags_q), .in_tick_count(tick_count),
    .in_tick_cycles(tick_cycles), .in_joint_hold(joint_hold),
    .out_njoints(r_njoints), .out_mode_err_b(r_err_b), .out_mode_error_only(r_err_only),
    .out_mode_sweeps(r_sweeps), .out_mode_warm_leak(r_leak), .out_kp(r_kp), .out_ko(r_ko),
    .out_lchar(r_lchar), .out_klim(r_klim), .out_dt(r_dt),
    .out_base_qw(r_bqw), .out_base_qx(r_bqx), .out_base_qy(r_bqy), .out_base_qz(r_bqz),
    .out_base_px(r_bpx), .out_base_py(r_bpy), .out_base_pz(r_bpz),
    .out_tool_qw(r_tqw), .out_tool_qx(r_tqx), .out_tool_qy(r_tqy), .out_tool_qz(r_tqz),
    .out_tool_px(r_tpx), .out_tool_py(r_tpy), .out_tool_pz(r_tpz),
    .out_joint_jcfg_prismatic(r_pri), .out_joint_jcfg_limited(r_lim), .out_joint_jcfg_vlimited(r_vlim),
    .out_joint_origin_qw(r_oqw), .out_joint_origin_qx(r_oqx), .out_joint_origin_qy(r_oqy),
    .out_joint_origin_qz(r_oqz), .out_joint_origin_px(r_opx), .out_joint_origin_py(r_opy),
    .out_joint_origin_pz(r_opz), .out_joint_axis_x(r_ax), .out_joint_axis_y(r_ay), .out_joint_axis_z(r_az),
    .out_joint_scale(r_scale), .out_joint_lower(r_lower), .out_joint_upper(r_upper),
    .out_joint_vmax(r_vmax), .out_joint_mu(r_mu)
  );

  // ---- commit step ------------------------------------------------------------------------------
  reg  c_start;
  wire c_busy, c_done, c_ok, c_err;
  wire [7:0] c_n, c_sweeps;
  wire c_err_b, c_err_only;
  wire [3:0] c_leak;
  wire signed [GAIN_W-1:0] c_kp, c_ko;
  wire signed [LCHAR_W-1:0] c_lchar;
  wire signed [KLIM_W-1:0] c_klim;
  wire signed [DT_W-1:0] c_dt;
  wire signed [QUAT_W-1:0] c_bqw, c_bqx, c_bqy, c_bqz, c_tqw, c_tqx, c_tqy, c_tqz;
  wire signed [LEN_W-1:0] c_bpx, c_bpy, c_bpz, c_tpx, c_tpy, c_tpz;
  wire [NMAX-1:0] c_pri, c_lim, c_vlim;
  wire [NMAX*KT_W-1:0] c_kturn;

  // the loader's joint and that joint's register words, through the commit engine's multiplexers
  wire [7:0] ld_j8;
  wire [QUAT_W-1:0] j_oqw, j_oqx, j_oqy, j_oqz, j_ax, j_ay, j_az;
  wire [LEN_W-1:0] j_opx, j_opy, j_opz;
  wire [SCALE_W-1:0] j_sc;
  wire [ANGLE_W-1:0] j_lo, j_hi;
  wire [QD_W-1:0] j_vm;
  wire [MU_W-1:0] j_mu;
  ts_core_commit #(.NMAX(NMAX), .CONFIG(CONFIG), .TARGET(TARGET), .MUL3(MUL3)) u_commit (
    .clk(clk), .rst(rst), .in_start(c_start),
    .in_njoints(r_njoints), .in_mode_err_b(r_err_b), .in_mode_error_only(r_err_only),
    .in_mode_sweeps(r_sweeps), .in_mode_warm_leak(r_leak), .in_kp(r_kp), .in_ko(r_ko),
    .in_lchar(r_lchar), .in_klim(r_klim), .in_dt(r_dt),
    .in_base_qw(r_bqw), .in_base_qx(r_bqx), .in_base_qy(r_bqy), .in_base_qz(r_bqz),
    .in_base_px(r_bpx), .in_base_py(r_bpy), .in_base_pz(r_bpz),
    .in_tool_qw(r_tqw), .in_tool_qx(r_tqx), .in_tool_qy(r_tqy), .in_tool_qz(r_tqz),
    .in_tool_px(r_tpx), .in_tool_py(r_tpy), .in_tool_pz(r_tpz),
    .in_joint_jcfg_prismatic(r_pri), .in_joint_jcfg_limited(r_lim), .in_joint_jcfg_vlimited(r_vlim),
    .in_joint_origin_qw(r_oqw), .in_joint_origin_qx(r_oqx), .in_joint_origin_qy(r_oqy),
    .in_joint_origin_qz(r_oqz), .in_joint_origin_px(r_opx), .in_joint_origin_py(r_opy),
    .in_joint_origin_pz(r_opz), .in_joint_axis_x(r_ax), .in_joint_axis_y(r_ay), .in_joint_axis_z(r_az),
    .in_joint_scale(r_scale), .in_joint_lower(r_lower), .in_joint_upper(r_upper),
    .in_joint_vmax(r_vmax), .in_joint_mu(r_mu),
    .out_busy(c_busy), .out_done(c_done), .out_cfg_ok(c_ok), .out_cfg_err(c_err),
    .out_err_code(err_code), .out_err_joint(err_joint),
    .out_njoints(c_n), .out_mode_err_b(c_err_b), .out_mode_error_only(c_err_only),
    .out_mode_sweeps(c_sweeps), .out_mode_warm_leak(c_leak), .out_kp(c_kp), .out_ko(c_ko),
    .out_lchar(c_lchar), .out_klim(c_klim), .out_dt(c_dt),
    .out_base_qw(c_bqw), .out_base_qx(c_bqx), .out_base_qy(c_bqy), .out_base_qz(c_bqz),
    .out_base_px(c_bpx), .out_base_py(c_bpy), .out_base_pz(c_bpz),
    .out_tool_qw(c_tqw), .out_tool_qx(c_tqx), .out_tool_qy(c_tqy), .out_tool_qz(c_tqz),
    .out_tool_px(c_tpx), .out_tool_py(c_tpy), .out_tool_pz(c_tpz),
    .out_joint_jcfg_prismatic(c_pri), .out_joint_jcfg_limited(c_lim), .out_joint_jcfg_vlimited(c_vlim),
    .out_joint_kturn(c_kturn),
    .in_ld_j(ld_j8), .out_ld_qo0(j_oqw), .out_ld_qo1(j_oqx), .out_ld_qo2(j_oqy), .out_ld_qo3(j_oqz),
    .out_ld_ax0(j_ax), .out_ld_ax1(j_ay), .out_ld_ax2(j_az), .out_ld_pox(j_opx), .out_ld_poy(j_opy),
    .out_ld_poz(j_opz), .out_ld_s(j_sc), .out_ld_lo(j_lo), .out_ld_hi(j_hi), .out_ld_vmax(j_vm),
    .out_ld_mu(j_mu)
  );

  // ---- sequencer state ---------------------------------------------------------------------------
  reg [3:0] st;
  reg pend;                       // CTRL.COMMIT seen, not yet started
  reg loaded;                     // the engines hold the committed configuration
  reg [LA_W-1:0] ld;              // loader address {global, joint, field}
  reg [WI_W-1:0] wi;              // input word index
  reg bad;                        // malformed packet
  reg [1:0] ctl;                  // packet control word (bit 0 COLD, bit 1 LOAD_Q)
  reg use_int;                    // this tick takes q from the core (virtual mode, no LOAD_Q)
  reg [JN*ANGLE_W-1:0] qbuf;      // the packet's q
  reg [31:0] sp [0:12];           // the packet's setpoint words
  reg [JN*ANGLE_W-1:0] q_int;     // q_next of the last tick (virtual q, output words)
  reg [JN*QD_W-1:0] qd_prev;      // q' of the last tick (warm start, output words)
  reg [JI_W:0] pj;                // joint counter (PREP)
  reg psub;                       // PREP: 0 q, 1 warm start
  reg [31:0] cyc;                 // cycles of this tick
  reg [31:0] status_w;            // status word of this tick
  reg [WI_W-1:0] ow;              // output word index

  // The joint count and the packet lengths and offsets it sets, registered: they change only at a
  // commit, hundreds of cycles before a tick uses them, and the commit engine's shadow count would
  // otherwise reach the sequencer's comparisons through these adders across the device (the
  // compact core's critical path post-route, 17.0 ns).
  reg [JI_W:0] n_c;
  reg [WI_W-1:0] n_w, n_w2, last_in, last_out, last_out_m1;
  always @(posedge clk) begin
    if (rst) begin
      n_c <= {(JI_W + 1){1'b0}}; n_w <= {WI_W{1'b0}}; n_w2 <= {WI_W{1'b0}};
      last_in <= {WI_W{1'b0}}; last_out <= {WI_W{1'b0}}; last_out_m1 <= {WI_W{1'b0}};
    end else begin
      n_c <= c_n[JI_W:0];
      n_w <= {{(WI_W - JI_W - 1){1'b0}}, n_c};
      n_w2 <= n_w + n_w;
      last_in <= n_w + {{(WI_W - 4){1'b0}}, 4'd13};
      last_out <= n_w + n_w + {{(WI_W - 3){1'b0}}, 3'd7};
      last_out_m1 <= n_w + n_w + {{(WI_W - 3){1'b0}}, 3'd6};
    end
  end
  wire beat_in = s_axis_tvalid && s_axis_tready;
  wire [JI_W-1:0] qi = wi[JI_W-1:0] - 1'b1;                 // q word -> joint
  wire [WI_W-1:0] si_w = wi - n_w - 1'b1;                   // setpoint word index
  wire [3:0] si = si_w[3:0];
  wire beat_out = m_axis_tvalid && m_axis_tready;
  wire can_tick = c_ok && loaded && ctrl_run && !pend;
  assign s_axis_tready = ((st == S_IDLE) && can_tick) || (st == S_IN);
  assign m_axis_tvalid = (st == S_OUT);
  assign m_axis_tlast = (st == S_OUT) && (ow == last_out);

  assign st_busy = (st != S_IDLE) && (st != S_CMT) && (st != S_LOAD);
  assign cfg_busy = pend || (st == S_CMT) || (st == S_LOAD);
  assign cfg_ok = c_ok && loaded;
  assign cfg_err = c_err;
  // The commit engine keeps no shadow of the joints' words (it would duplicate the register block's
  // 15 NMAX words): its checks and the loader read the register block directly, so joint-register
  // writes wait from the start edge (st = S_CMT) until the loader is done.  The AXI write is
  // accepted and its response delayed; global registers (CTRL, FLAGS, MODE, ...) are not held.
  assign joint_hold = (st == S_CMT) || (st == S_LOAD);

  // ---- loader: configuration words of the engines --------------------------------------------------
  wire ld_g = ld[LA_W-1];
  wire [JI_W-1:0] ld_j = ld[JI_W+3:4];
  wire [3:0] ld_f = ld[3:0];
  wire ld_jok = ld_g || ({{(32 - JI_W){1'b0}}, ld_j} < NMAX);
  wire [JI_W-1:0] lj = ld_jok && !ld_g ? ld_j : {JI_W{1'b0}};
  reg [31:0] fk_cd;
  reg fk_cv;
  reg [CD_W-1:0] sv_cd;
  reg sv_cv;
  // The loader's write port is registered: the word selected at ld (through the commit engine's
  // joint multiplexers and the field case below) is written one cycle later at ld_q.  Without the
  // register this select ran straight into the engines' memories across the chip (the compact
  // core's critical path post-route, 20.8 ns).  LOAD lasts one cycle more (ld_fin).
  reg [LA_W-1:0] ld_q;
  reg fk_we_q, sv_we_q;
  reg [31:0] fk_cd_q;
  reg [CD_W-1:0] sv_cd_q;
  reg ld_fin;                     // LOAD: the last address was selected, its write is under way
  always @(posedge clk) begin
    if (rst) begin
      ld_q <= {LA_W{1'b0}}; fk_we_q <= 1'b0; sv_we_q <= 1'b0; fk_cd_q <= 32'd0;
      sv_cd_q <= {CD_W{1'b0}};
    end else begin
      ld_q <= ld;
      fk_we_q <= (st == S_LOAD) && !ld_fin && fk_cv;
      sv_we_q <= (st == S_LOAD) && !ld_fin && sv_cv;
      fk_cd_q <= fk_cd;
      sv_cd_q <= sv_cd;
    end
  end

  wire [8+JI_W-1:0] lj_x = {8'd0, lj};
  assign ld_j8 = lj_x[7:0];
  wire unused_lj_x = ^lj_x[8+JI_W-1:8];
  // sign extension of the shadow words to 32 / CD_W bits
  wire [KT_W-1:0] j_kt;
  ts_sel #(.W(KT_W), .N(NMAX), .IW(JI_W)) u_sel_j_kt (.in_vec(c_kturn), .in_idx(lj), .out_el(j_kt));

  always @(*) begin
    fk_cd = 32'd0;
    fk_cv = ld_jok;
    sv_cd = {CD_W{1'b0}};
    sv_cv = ld_jok;
    if (!ld_g) begin
      case (ld_f)
        4'd0: fk_cd = {{(33 - QUAT_W){j_oqw[QUAT_W-1]}}, j_oqw[QUAT_W-2:0]};
        4'd1: fk_cd = {{(33 - QUAT_W){j_oqx[QUAT_W-1]}}, j_oqx[QUAT_W-2:0]};
        4'd2: fk_cd = {{(33 - QUAT_W){j_oqy[QUAT_W-1]}}, j_oqy[QUAT_W-2:0]};
        4'd3: fk_cd = {{(33 - QUAT_W){j_oqz[QUAT_W-1]}}, j_oqz[QUAT_W-2:0]};
        4'd4: fk_cd = {{(33 - LEN_W){j_opx[LEN_W-1]}}, j_opx[LEN_W-2:0]};
        4'd5: fk_cd = {{(33 - LEN_W){j_opy[LEN_W-1]}}, j_opy[LEN_W-2:0]};
        4'd6: fk_cd = {{(33 - LEN_W){j_opz[LEN_W-1]}}, j_opz[LEN_W-2:0]};
        4'd8: fk_cd = {{(33 - QUAT_W){j_ax[QUAT_W-1]}}, j_ax[QUAT_W-2:0]};
        4'd9: fk_cd = {{(33 - QUAT_W){j_ay[QUAT_W-1]}}, j_ay[QUAT_W-2:0]};
        4'd10: fk_cd = {{(33 - QUAT_W){j_az[QUAT_W-1]}}, j_az[QUAT_W-2:0]};
        4'd12: fk_cd = {{(33 - SCALE_W){j_sc[SCALE_W-1]}}, j_sc[SCALE_W-2:0]};
        4'd13: fk_cd = {{(33 - KT_W){j_kt[KT_W-1]}}, j_kt[KT_W-2:0]};
        4'd14: fk_cd = {31'd0, c_pri[lj]};
        default: fk_cv = 1'b0;
      endcase
      case (ld_f)
        4'd0: sv_cd = {{(CD_W + 1 - ANGLE_W){j_lo[ANGLE_W-1]}}, j_lo[ANGLE_W-2:0]};
        4'd1: sv_cd = {{(CD_W + 1 - ANGLE_W){j_hi[ANGLE_W-1]}}, j_hi[ANGLE_W-2:0]};
        4'd2: sv_cd = {{(CD_W + 1 - QD_W){j_vm[QD_W-1]}}, j_vm[QD_W-2:0]};
        4'd3: sv_cd = {{(CD_W + 1 - MU_W){j_mu[MU_W-1]}}, j_mu[MU_W-2:0]};
        4'd4: sv_cd = {{(CD_W - 1){1'b0}}, c_lim[lj]};
        default: sv_cv = 1'b0;
      endcase
    end else begin
      case (ld_f)
        4'd0: fk_cd = {{(33 - QUAT_W){c_bqw[QUAT_W-1]}}, c_bqw[QUAT_W-2:0]};
        4'd1: fk_cd = {{(33 - QUAT_W){c_bqx[QUAT_W-1]}}, c_bqx[QUAT_W-2:0]};
        4'd2: fk_cd = {{(33 - QUAT_W){c_bqy[QUAT_W-1]}}, c_bqy[QUAT_W-2:0]};
        4'd3: fk_cd = {{(33 - QUAT_W){c_bqz[QUAT_W-1]}}, c_bqz[QUAT_W-2:0]};
        4'd4: fk_cd = {{(33 - LEN_W){c_bpx[LEN_W-1]}}, c_bpx[LEN_W-2:0]};
        4'd5: fk_cd = {{(33 - LEN_W){c_bpy[LEN_W-1]}}, c_bpy[LEN_W-2:0]};
        4'd6: fk_cd = {{(33 - LEN_W){c_bpz[LEN_W-1]}}, c_bpz[LEN_W-2:0]};
        4'd8: fk_cd = {{(33 - QUAT_W){c_tqw[QUAT_W-1]}}, c_tqw[QUAT_W-2:0]};
        4'd9: fk_cd = {{(33 - QUAT_W){c_tqx[QUAT_W-1]}}, c_tqx[QUAT_W-2:0]};
        4'd10: fk_cd = {{(33 - QUAT_W){c_tqy[QUAT_W-1]}}, c_tqy[QUAT_W-2:0]};
        4'd11: fk_cd = {{(33 - QUAT_W){c_tqz[QUAT_W-1]}}, c_tqz[QUAT_W-2:0]};
        4'd12: fk_cd = {{(33 - LEN_W){c_tpx[LEN_W-1]}}, c_tpx[LEN_W-2:0]};
        4'd13: fk_cd = {{(33 - LEN_W){c_tpy[LEN_W-1]}}, c_tpy[LEN_W-2:0]};
        4'd14: fk_cd = {{(33 - LEN_W){c_tpz[LEN_W-1]}}, c_tpz[LEN_W-2:0]};
        default: fk_cd = {24'd0, c_n};
      endcase
      case (ld_f)
        4'd0: sv_cd = {{(CD_W + 1 - LCHAR_W){c_lchar[LCHAR_W-1]}}, c_lchar[LCHAR_W-2:0]};
        4'd1: sv_cd = {{(CD_W + 1 - KLIM_W){c_klim[KLIM_W-1]}}, c_klim[KLIM_W-2:0]};
        4'd2: sv_cd = {{(CD_W + 1 - DT_W){c_dt[DT_W-1]}}, c_dt[DT_W-2:0]};
        4'd3: sv_cd = {{(CD_W - 8){1'b0}}, c_sweeps};
        4'd4: sv_cd = {{(CD_W - 4){1'b0}}, c_leak};
        default: sv_cv = 1'b0;
      endcase
    end
  end

  // ---- per-tick input words ------------------------------------------------------------------------
  wire [JI_W-1:0] pjj = pj[JI_W-1:0];
  wire [ANGLE_W-1:0] q_int_j, qbuf_j;
  wire [QD_W-1:0] qd_prev_j;
  ts_sel #(.W(ANGLE_W), .N(JN), .IW(JI_W)) u_sel_qint (.in_vec(q_int), .in_idx(pjj), .out_el(q_int_j));
  ts_sel #(.W(ANGLE_W), .N(JN), .IW(JI_W)) u_sel_qbuf (.in_vec(qbuf), .in_idx(pjj), .out_el(qbuf_j));
  ts_sel #(.W(QD_W), .N(JN), .IW(JI_W)) u_sel_warm (.in_vec(qd_prev), .in_idx(pjj), .out_el(qd_prev_j));
  wire [ANGLE_W-1:0] q_sel = use_int ? q_int_j : qbuf_j;
  wire [QD_W-1:0] warm_sel = ctl[0] ? {QD_W{1'b0}} : qd_prev_j;
  wire in_prep = (st == S_PREP);

  // setpoint words (low bits of each 32-bit word)
  wire signed [QUAT_W-1:0] u_qw = sp[0][QUAT_W-1:0], u_qx = sp[1][QUAT_W-1:0];
  wire signed [QUAT_W-1:0] u_qy = sp[2][QUAT_W-1:0], u_qz = sp[3][QUAT_W-1:0];
  wire signed [P_W-1:0] u_px = sp[4][P_W-1:0], u_py = sp[5][P_W-1:0], u_pz = sp[6][P_W-1:0];
  wire signed [V_W-1:0] u_wx = sp[7][V_W-1:0], u_wy = sp[8][V_W-1:0], u_wz = sp[9][V_W-1:0];
  wire signed [V_W-1:0] u_vx = sp[10][V_W-1:0], u_vy = sp[11][V_W-1:0], u_vz = sp[12][V_W-1:0];

  // ---- FK engine -----------------------------------------------------------------------------------
  reg fk_start;
  reg [JI_W-1:0] col_addr;
  wire fk_busy, fk_done;
  wire [15:0] fk_flags;
  wire signed [QUAT_W-1:0] tq_w, tq_x, tq_y, tq_z;
  wire signed [P_W-1:0] tp_x, tp_y, tp_z;
  wire signed [JW_W-1:0] fc_wx, fc_wy, fc_wz;
  wire signed [JV_W-1:0] fc_vx, fc_vy, fc_vz;
  wire signed [P_W-1:0] fc_px, fc_py, fc_pz;

  ts_core_fk #(.NMAX(NMAX), .CONFIG(CONFIG), .ROM_FILE(TRIG_ROM),
    .TARGET(TARGET), .MUL3(MUL3), .FOLD(FOLD), .CHAIN(CHAIN)) u_fk (
    .clk(clk), .rst(rst),
    .in_cfg_we(fk_we_q), .in_cfg_addr(ld_q), .in_cfg_data(fk_cd_q),
    .in_q_we(in_prep && !psub), .in_q_addr(pjj), .in_q_data(q_sel),
    .in_start(fk_start), .out_busy(fk_busy), .out_done(fk_done), .out_flags(fk_flags),
    .out_tool_q_w(tq_w), .out_tool_q_x(tq_x), .out_tool_q_y(tq_y), .out_tool_q_z(tq_z),
    .out_tool_p_x(tp_x), .out_tool_p_y(tp_y), .out_tool_p_z(tp_z),
    .in_col_addr(col_addr),
    .out_col_w_x(fc_wx), .out_col_w_y(fc_wy), .out_col_w_z(fc_wz),
    .out_col_v_x(fc_vx), .out_col_v_y(fc_vy), .out_col_v_z(fc_vz),
    .out_col_p_x(fc_px), .out_col_p_y(fc_py), .out_col_p_z(fc_pz)
  );

  // ---- servo law -----------------------------------------------------------------------------------
  reg law_start;
  reg col_v;                      // FK's column output holds a column for the law
  wire law_busy, law_done;
  wire [15:0] law_flags;
  wire signed [PE_W-1:0] ep_x, ep_y, ep_z;
  wire signed [RO_W-1:0] eo_x, eo_y, eo_z;
  wire signed [V_W-1:0] vw_x, vw_y, vw_z, vv_x, vv_y, vv_z;
  wire lc_valid, lc_sat;
  wire signed [JW_W-1:0] lc_wx, lc_wy, lc_wz;
  wire signed [JV_W-1:0] lc_vx, lc_vy, lc_vz;

  ts_core_law #(.CONFIG(CONFIG), .ROM_FILE(ROTVEC_ROM),
    .TARGET(TARGET), .MUL3(MUL3), .FOLD(FOLD), .CHAIN(CHAIN)) u_law (
    .clk(clk), .rst(rst), .in_start(law_start), .in_mode_b(c_err_b), .in_err_only(c_err_only),
    .in_kp(c_kp), .in_ko(c_ko), .out_busy(law_busy), .out_done(law_done), .out_flags(law_flags),
    .in_tool_q_w(tq_w), .in_tool_q_x(tq_x), .in_tool_q_y(tq_y), .in_tool_q_z(tq_z),
    .in_tool_p_x(tp_x), .in_tool_p_y(tp_y), .in_tool_p_z(tp_z),
    .in_u_q_w(u_qw), .in_u_q_x(u_qx), .in_u_q_y(u_qy), .in_u_q_z(u_qz),
    .in_u_p_x(u_px), .in_u_p_y(u_py), .in_u_p_z(u_pz),
    .in_u_w_x(u_wx), .in_u_w_y(u_wy), .in_u_w_z(u_wz),
    .in_u_v_x(u_vx), .in_u_v_y(u_vy), .in_u_v_z(u_vz),
    .out_ep_x(ep_x), .out_ep_y(ep_y), .out_ep_z(ep_z),
    .out_eo_x(eo_x), .out_eo_y(eo_y), .out_eo_z(eo_z),
    .out_vw_x(vw_x), .out_vw_y(vw_y), .out_vw_z(vw_z),
    .out_vv_x(vv_x), .out_vv_y(vv_y), .out_vv_z(vv_z),
    .in_col_valid(col_v),
    .in_col_w_x(fc_wx), .in_col_w_y(fc_wy), .in_col_w_z(fc_wz),
    .in_col_v_x(fc_vx), .in_col_v_y(fc_vy), .in_col_v_z(fc_vz),
    .out_col_valid(lc_valid),
    .out_col_w_x(lc_wx), .out_col_w_y(lc_wy), .out_col_w_z(lc_wz),
    .out_col_v_x(lc_vx), .out_col_v_y(lc_vy), .out_col_v_z(lc_vz),
    .out_col_sat(lc_sat)
  );

  // ---- columns and V into the solver --------------------------------------------------------------
  reg [JI_W:0] ci;                // next column to issue
  // one column every CI cycles: the solver's six-word write (7 cycles), or the law's column II
  localparam integer CI = (FOLD > 7) ? FOLD : 7;
  localparam integer TM_W = $clog2(CI);
  localparam integer CI_M1 = CI - 1;
  localparam [TM_W-1:0] TM_LAST = CI_M1[TM_W-1:0];
  reg [TM_W-1:0] tm;              // issue interval counter
  reg [JI_W:0] wj;                // columns written into the solver
  reg [2:0] wc;                   // field being written (column or V)
  reg wr_act;                     // a column / V write burst is running
  reg law_ok;                     // the law's evaluation has ended
  reg [6*CD_W-1:0] hold;          // the six words being written, sign-extended to CD_W bits
  reg sv_start;
  wire sv_busy, sv_done;
  wire [NMAX*QD_W-1:0] sv_qd;
  wire [NMAX*ANGLE_W-1:0] sv_qn;
  wire [6*V_W-1:0] sv_r;          // final residual (not an output of the core)
  wire [31:0] sv_flags;
  reg sv_xwe;
  reg [LA_W-1:0] sv_xa;
  reg [CD_W-1:0] sv_xd;

  wire [CD_W-1:0] hold_w;
  ts_sel #(.W(CD_W), .N(6), .IW(3)) u_sel_hold (.in_vec(hold), .in_idx(wc), .out_el(hold_w));
  always @(*) begin
    sv_xwe = 1'b0;
    sv_xa = {LA_W{1'b0}};
    sv_xd = {CD_W{1'b0}};
    if (in_prep) begin
      sv_xwe = 1'b1;
      sv_xa = {1'b0, pjj, 3'b011, psub};
      sv_xd = psub ? {{(CD_W + 1 - QD_W){warm_sel[QD_W-1]}}, warm_sel[QD_W-2:0]}
                   : {{(CD_W + 1 - ANGLE_W){q_sel[ANGLE_W-1]}}, q_sel[ANGLE_W-2:0]};
    end else if (wr_act) begin
      sv_xwe = 1'b1;
      sv_xa = (st == S_V) ? {1'b1, {JI_W{1'b0}}, 1'b0, wc} : {1'b0, wj[JI_W-1:0], 1'b0, wc};
      sv_xd = hold_w;
    end
  end

  ts_core_solve #(.NMAX(NMAX), .CONFIG(CONFIG), .ROM_FILE(RECIP_ROM), .TARGET(TARGET), .MUL3(MUL3)) u_solve (
    .clk(clk), .rst(rst),
    .in_cfg_we(sv_we_q), .in_cfg_addr(ld_q), .in_cfg_data(sv_cd_q),
    .in_x_we(sv_xwe), .in_x_addr(sv_xa), .in_x_data(sv_xd),
    .in_start(sv_start), .in_n(n_c), .out_busy(sv_busy), .out_done(sv_done),
    .out_qd(sv_qd), .out_q_next(sv_qn), .out_r(sv_r), .out_flags(sv_flags)
  );

  // ---- output words --------------------------------------------------------------------------------
  wire [WI_W-1:0] ow_e = ow - n_w2;                // ep/eo/status/count index
  wire [JI_W-1:0] oj_d = ow[JI_W-1:0];
  wire [JI_W-1:0] oj_n = ow[JI_W-1:0] - n_c[JI_W-1:0];   // q_next index
  wire [QD_W-1:0] o_qd;
  wire [ANGLE_W-1:0] o_qn;
  ts_sel #(.W(QD_W), .N(JN), .IW(JI_W)) u_sel_oqd (.in_vec(qd_prev), .in_idx(oj_d), .out_el(o_qd));
  ts_sel #(.W(ANGLE_W), .N(JN), .IW(JI_W)) u_sel_oqn (.in_vec(q_int), .in_idx(oj_n), .out_el(o_qn));
  reg [PE_W-1:0] o_ep;
  reg [RO_W-1:0] o_eo;
  always @(*) begin
    case (ow_e[2:0])
      3'd0: o_ep = ep_x;
      3'd1: o_ep = ep_y;
      default: o_ep = ep_z;
    endcase
    case (ow_e[2:0])
      3'd3: o_eo = eo_x;
      3'd4: o_eo = eo_y;
      default: o_eo = eo_z;
    endcase
    if (bad) m_axis_tdata = (ow == last_out_m1) ? 32'h4000_0000 :
                            (ow == last_out) ? tick_count : 32'd0;
    else if (ow < n_w) m_axis_tdata = {{(33 - QD_W){o_qd[QD_W-1]}}, o_qd[QD_W-2:0]};
    else if (ow < n_w2) m_axis_tdata = {{(33 - ANGLE_W){o_qn[ANGLE_W-1]}}, o_qn[ANGLE_W-2:0]};
    else if (ow_e < 3) m_axis_tdata = {{(33 - PE_W){o_ep[PE_W-1]}}, o_ep[PE_W-2:0]};
    else if (ow_e < 6) m_axis_tdata = {{(33 - RO_W){o_eo[RO_W-1]}}, o_eo[RO_W-2:0]};
    else if (ow_e == 6) m_axis_tdata = status_w;
    else m_axis_tdata = tick_count;
  end

  // ---- sequencer -----------------------------------------------------------------------------------
  // outputs of the engines the core does not use
  wire unused_ok = &{1'b0, fk_busy, law_busy, sv_busy, c_busy, lc_sat, sv_r, fc_px, fc_py, fc_pz,
                     c_vlim, flags_q, si_w[WI_W-1:4], sv_flags[31:18], ctl[1]};

  integer k;
  always @(posedge clk) begin
    if (rst) begin
      st <= S_IDLE; pend <= 1'b0; loaded <= 1'b0; ld <= {LA_W{1'b0}}; ld_fin <= 1'b0; wi <= {WI_W{1'b0}};
      bad <= 1'b0; ctl <= 2'd0; use_int <= 1'b0; qbuf <= {(JN * ANGLE_W){1'b0}};
      q_int <= {(JN * ANGLE_W){1'b0}}; qd_prev <= {(JN * QD_W){1'b0}};
      pj <= {(JI_W + 1){1'b0}}; psub <= 1'b0; cyc <= 32'd0; status_w <= 32'd0; ow <= {WI_W{1'b0}};
      tick_count <= 32'd0; tick_cycles <= 32'd0; flags_set <= 18'd0;
      c_start <= 1'b0; fk_start <= 1'b0; law_start <= 1'b0; sv_start <= 1'b0;
      col_addr <= {JI_W{1'b0}}; col_v <= 1'b0; ci <= {(JI_W + 1){1'b0}}; tm <= {TM_W{1'b0}};
      wj <= {(JI_W + 1){1'b0}}; wc <= 3'd0; wr_act <= 1'b0; law_ok <= 1'b0; hold <= {(6 * CD_W){1'b0}};
      for (k = 0; k < 13; k = k + 1) sp[k] <= 32'd0;
    end else begin
      c_start <= 1'b0; fk_start <= 1'b0; law_start <= 1'b0; sv_start <= 1'b0; col_v <= 1'b0;
      flags_set <= 18'd0;
      if (ctrl_commit) pend <= 1'b1;
      if (ctrl_clear) tick_count <= 32'd0;
      if (st != S_IDLE) cyc <= cyc + 1'b1;

      case (st)
        S_IDLE: begin
          if (pend) begin
            c_start <= 1'b1; pend <= 1'b0; loaded <= 1'b0;
            qd_prev <= {(JN * QD_W){1'b0}}; q_int <= {(JN * ANGLE_W){1'b0}};
            st <= S_CMT;
          end else if (beat_in) begin
            ctl <= s_axis_tdata[1:0];
            use_int <= ctrl_virtual && !s_axis_tdata[1];
            cyc <= 32'd1; bad <= 1'b0; wi <= {{(WI_W - 1){1'b0}}, 1'b1};
            if (s_axis_tlast) begin
              bad <= 1'b1; ow <= {WI_W{1'b0}}; st <= S_OUT;
            end else st <= S_IN;
          end
        end
        S_IN: begin
          if (beat_in) begin
            if ((wi <= n_w) && (wi != 0)) begin
              for (k = 0; k < JN; k = k + 1)
                if ({{(32 - JI_W){1'b0}}, qi} == k) qbuf[k*ANGLE_W +: ANGLE_W] <= s_axis_tdata[ANGLE_W-1:0];
            end
            else if ((wi > n_w) && (wi <= last_in)) sp[si] <= s_axis_tdata;
            if (wi != {WI_W{1'b1}}) wi <= wi + 1'b1;
            if (s_axis_tlast) begin
              if (bad || (wi != last_in)) begin
                bad <= 1'b1; ow <= {WI_W{1'b0}}; st <= S_OUT;
              end else begin
                pj <= {(JI_W + 1){1'b0}}; psub <= 1'b0; st <= S_PREP;
              end
            end else if (wi == last_in) bad <= 1'b1;
          end
        end
        S_CMT: begin
          if (c_done) begin
            ld <= {LA_W{1'b0}};
            st <= c_ok ? S_LOAD : S_IDLE;
          end
        end
        S_LOAD: begin
          if (ld_fin) begin ld_fin <= 1'b0; loaded <= 1'b1; st <= S_IDLE; end
          else begin
            ld <= ld + 1'b1;
            if (ld == {LA_W{1'b1}}) ld_fin <= 1'b1;
          end
        end
        S_PREP: begin
          psub <= ~psub;
          if (psub) begin
            if (pj + 1'b1 == n_c) begin fk_start <= 1'b1; st <= S_FK; end
            pj <= pj + 1'b1;
          end
        end
        S_FK: begin
          if (fk_done) begin
            law_start <= 1'b1; st <= S_LAW; ci <= {(JI_W + 1){1'b0}}; tm <= {TM_W{1'b0}};
            col_addr <= {JI_W{1'b0}}; wj <= {(JI_W + 1){1'b0}}; wr_act <= 1'b0; law_ok <= 1'b0;
          end
        end
        S_LAW: begin
          // column ci is at the FK read port (col_addr) in the cycle tm = 0
          if (tm == TM_LAST) tm <= {TM_W{1'b0}}; else tm <= tm + 1'b1;
          if ((tm == {TM_W{1'b0}}) && (ci < n_c)) begin
            col_v <= 1'b1;
            ci <= ci + 1'b1;
          end
          if (tm == {{(TM_W-1){1'b0}}, 1'b1}) col_addr <= ci[JI_W-1:0];
          if (law_done) law_ok <= 1'b1;
          if (lc_valid) begin
            hold <= {{{(CD_W + 1 - JV_W){lc_vz[JV_W-1]}}, lc_vz[JV_W-2:0]},
                     {{(CD_W + 1 - JV_W){lc_vy[JV_W-1]}}, lc_vy[JV_W-2:0]},
                     {{(CD_W + 1 - JV_W){lc_vx[JV_W-1]}}, lc_vx[JV_W-2:0]},
                     {{(CD_W + 1 - JW_W){lc_wz[JW_W-1]}}, lc_wz[JW_W-2:0]},
                     {{(CD_W + 1 - JW_W){lc_wy[JW_W-1]}}, lc_wy[JW_W-2:0]},
                     {{(CD_W + 1 - JW_W){lc_wx[JW_W-1]}}, lc_wx[JW_W-2:0]}};
            wr_act <= 1'b1; wc <= 3'd0;
          end else if (wr_act) begin
            if (wc == 3'd5) begin wr_act <= 1'b0; wj <= wj + 1'b1; end
            wc <= wc + 1'b1;
          end
          if ((law_ok || law_done) && (wj == n_c) && !wr_act) begin
            hold <= {{{(CD_W + 1 - V_W){vv_z[V_W-1]}}, vv_z[V_W-2:0]},
                     {{(CD_W + 1 - V_W){vv_y[V_W-1]}}, vv_y[V_W-2:0]},
                     {{(CD_W + 1 - V_W){vv_x[V_W-1]}}, vv_x[V_W-2:0]},
                     {{(CD_W + 1 - V_W){vw_z[V_W-1]}}, vw_z[V_W-2:0]},
                     {{(CD_W + 1 - V_W){vw_y[V_W-1]}}, vw_y[V_W-2:0]},
                     {{(CD_W + 1 - V_W){vw_x[V_W-1]}}, vw_x[V_W-2:0]}};
            wr_act <= 1'b1; wc <= 3'd0; st <= S_V;
          end
        end
        S_V: begin
          wc <= wc + 1'b1;
          if (wc == 3'd5) begin wr_act <= 1'b0; sv_start <= 1'b1; st <= S_SOLVE; end
        end
        S_SOLVE: begin
          if (sv_done) begin
            status_w <= sv_flags | {16'd0, law_flags} | {16'd0, fk_flags};
            flags_set <= sv_flags[17:0] | {2'b00, law_flags} | {2'b00, fk_flags};
            for (k = 0; k < NMAX; k = k + 1) begin
              qd_prev[k*QD_W +: QD_W] <= sv_qd[k*QD_W +: QD_W];
              q_int[k*ANGLE_W +: ANGLE_W] <= sv_qn[k*ANGLE_W +: ANGLE_W];
            end
            if (!ctrl_clear) tick_count <= tick_count + 1'b1;
            ow <= {WI_W{1'b0}};
            st <= S_OUT;
          end
        end
        S_OUT: begin
          if (beat_out) begin
            ow <= ow + 1'b1;
            if (ow == last_out) begin
              if (!bad) tick_cycles <= cyc + 1'b1;
              bad <= 1'b0;
              st <= S_IDLE;
            end
          end
        end
        default: st <= S_IDLE;
      endcase
    end
  end

endmodule

`resetall
