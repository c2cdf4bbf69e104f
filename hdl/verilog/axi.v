// The AXI4-Lite top (reference: snapgen_model::io::axi, clock for clock): the station
// (snapgen_io_station, in snapgen_io.v) behind an AXI4-Lite slave, the same command executor
// as the UART's. The register map is the spec's (snapgen_spec::axi, docs/AXI.md).
//
//   * Write: s_axi_awready is high while no write address is held, s_axi_wready while no write
//     data is; each is held on its handshake, in either order. On the clock after both are
//     held, with no response waiting, the write takes effect and s_axi_bvalid rises (OKAY, or
//     SLVERR for an address outside the map or a register that is not writable: nothing
//     changes); s_axi_bvalid falls on the clock s_axi_bready is high.
//   * Read: s_axi_arready is high while no read data waits; on the handshake the register is
//     read into s_axi_rdata (a read of REPLY takes the station's waiting reply byte) and
//     s_axi_rvalid rises; it falls on the clock s_axi_rready is high.
//   * A COMMAND write (byte lane 0 strobed) hands its byte to the station on the next clock.
//   * SNAPSHOT latches the status block and the chain's registers on the clock of its write.
//   * Interrupt causes DONE, FAULT and SWAP are latched from the station's status until
//     written 1 in IRQ_STATUS; REPLY is the level "a reply byte waits"; irq is registered.
//
// Only byte lane 0 of a write is used (every writable field lies in bits 7:0); the address's
// low two bits are ignored (word access).
//
// Template: snapgen_hdl writes the //@ lines and the capitalised holes from the spec's register map and
// port lists.

//@ localparams

// The station and what it gives the slave.
//@ wires
reg link_valid_q = 1'b0;
reg [7:0] link_data_q = 8'd0;
wire reply_take;

//@ station

// Write channel: the address and the data, each held on its handshake.
reg aw_full_q = 1'b0;
reg [{{WORD_MSB}}:0] aw_word_q = {{WORD_BITS}}'d0;
reg w_full_q = 1'b0;
reg [7:0] w_data_q = 8'd0;
reg w_lane0_q = 1'b0;
reg b_valid_q = 1'b0;
reg [1:0] b_resp_q = 2'd0;
// Read channel.
reg r_valid_q = 1'b0;
reg [31:0] r_data_q = 32'd0;
reg [1:0] r_resp_q = 2'd0;
// Interrupt.
reg [3:0] irq_enable_q = 4'd0;
reg [2:0] irq_latched_q = 3'd0;
reg was_done_q = 1'b0;
reg was_fault_q = 1'b0;
reg was_swap_pending_q = 1'b0;
reg irq_q = 1'b0;
// The snapshot, each value widened to whole words (the registers sign-extended).
//@ snapshot_regs

// The outputs: the slave's from its registers, the station's pins through.
always @(*) begin
   s_axi_awready = ~aw_full_q;
   s_axi_wready = ~w_full_q;
   s_axi_bvalid = b_valid_q;
   s_axi_bresp = b_resp_q;
   s_axi_arready = ~r_valid_q;
   s_axi_rvalid = r_valid_q;
   s_axi_rdata = r_data_q;
   s_axi_rresp = r_resp_q;
   irq = irq_q;
   //@ pins
end

wire write_fire = aw_full_q & w_full_q & ~b_valid_q;
wire read_fire = s_axi_arvalid & ~r_valid_q;
wire [{{WORD_MSB}}:0] read_word = s_axi_araddr[{{ADDR_MSB}}:2];
assign reply_take = read_fire & (read_word == WORD_REPLY);

// What a write of the held address may do.
reg write_ok;
always @(*) begin
   case (aw_word_q)
      //@ writable
      default: write_ok = 1'b0;
   endcase
end

// IRQ_STATUS as a read returns it: the latched causes and the REPLY level.
wire [3:0] irq_status = {station_reply_ready, irq_latched_q};

// The register a read addresses.
reg [31:0] read_data;
reg [1:0] read_resp;
always @(*) begin
   read_data = 32'd0;
   read_resp = RESP_OKAY;
   case (read_word)
      //@ readable
      default: read_resp = RESP_SLVERR;
   endcase
end

// Interrupt causes, from the station's status.
wire done_now = station_status[{{DONE_BIT}}];
wire fault_now = station_status[{{STATE_MSB}}:{{STATE_LSB}}] == {{ERROR_STOP}};
wire swap_pending_now = station_status[{{SWAP_PENDING_BIT}}];
wire [2:0] irq_events = {~swap_pending_now & was_swap_pending_q, fault_now & ~was_fault_q,
                         done_now & ~was_done_q};
wire irq_clear = write_fire & (aw_word_q == WORD_IRQ_STATUS) & w_lane0_q;

always @(posedge clock) begin
   if (reset) begin
      aw_full_q <= 1'b0;
      aw_word_q <= {{WORD_BITS}}'d0;
      w_full_q <= 1'b0;
      w_data_q <= 8'd0;
      w_lane0_q <= 1'b0;
      b_valid_q <= 1'b0;
      b_resp_q <= 2'd0;
      r_valid_q <= 1'b0;
      r_data_q <= 32'd0;
      r_resp_q <= 2'd0;
      link_valid_q <= 1'b0;
      link_data_q <= 8'd0;
      irq_enable_q <= 4'd0;
      irq_latched_q <= 3'd0;
      was_done_q <= 1'b0;
      was_fault_q <= 1'b0;
      was_swap_pending_q <= 1'b0;
      irq_q <= 1'b0;
      //@ snapshot_reset
   end else begin
      // Write.
      link_valid_q <= write_fire & (aw_word_q == WORD_COMMAND) & w_lane0_q;
      if (write_fire & (aw_word_q == WORD_COMMAND) & w_lane0_q) link_data_q <= w_data_q;
      if (write_fire & (aw_word_q == WORD_IRQ_ENABLE) & w_lane0_q)
         irq_enable_q <= w_data_q[3:0];
      if (write_fire & (aw_word_q == WORD_SNAPSHOT)) begin
         //@ snapshot_latch
      end
      if (write_fire) b_resp_q <= write_ok ? RESP_OKAY : RESP_SLVERR;
      b_valid_q <= write_fire | (b_valid_q & ~s_axi_bready);
      aw_full_q <= ~write_fire & (aw_full_q | s_axi_awvalid);
      if (~aw_full_q & s_axi_awvalid) aw_word_q <= s_axi_awaddr[{{ADDR_MSB}}:2];
      w_full_q <= ~write_fire & (w_full_q | s_axi_wvalid);
      if (~w_full_q & s_axi_wvalid) begin
         w_data_q <= s_axi_wdata[7:0];
         w_lane0_q <= s_axi_wstrb[0];
      end
      // Read.
      if (read_fire) begin
         r_data_q <= read_data;
         r_resp_q <= read_resp;
      end
      r_valid_q <= read_fire | (r_valid_q & ~s_axi_rready);
      // Interrupt.
      irq_latched_q <= (irq_latched_q & ~(irq_clear ? w_data_q[2:0] : 3'd0)) | irq_events;
      was_done_q <= done_now;
      was_fault_q <= fault_now;
      was_swap_pending_q <= swap_pending_now;
      irq_q <= |(irq_status & irq_enable_q);
   end
end
