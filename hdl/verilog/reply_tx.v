// The reply transmitter (its reference is snapgen_model::io::reply_tx::ReplyTx). Template:
// snapgen_hdl fills the values in double braces from the payload layouts (snapgen_spec::fields)
// and the line //@ crc_function with the CRC step, and puts the codes and kinds it names in front of it as localparams.
//
// When idle it takes the reply queue's head, or else a pending telemetry frame, and writes the
// frame (start byte, length, code, sequence, payload, CRC low then high) into the transmit FIFO
// one byte per clock while the FIFO is not full. The payload is held in a shift register and
// sent from its low byte. It is read from the live values {{PAYLOAD_DELAY}} clocks after the start (its
// first byte is written three clocks after that at the earliest), a CONFIG reply's value from the
// executor's read_value, registered the clock before from the parameter read_param names:
// a pipeline, so that no path runs from the reply queue through the parameters' multiplexer
// into the payload in one clock.

// ---- The reply launched on this clock: its kind, length and code -----------------------------
wire launch_head = !active_q && head_valid;
wire launch_telemetry = !active_q && !head_valid && (pending_q || telemetry);
wire [KIND_BITS-1:0] kind = launch_head ? head_kind : K_TELEMETRY;
reg [7:0] new_len;
reg [7:0] new_code;
always @(*) begin
   case (kind)
   K_IDENTITY: begin new_len = 8'd{{ID_BYTES}}; new_code = RC_IDENTITY; end
   K_ACK: begin new_len = 8'd{{ACK_BYTES}}; new_code = RC_ACK; end
   K_NAK: begin new_len = 8'd{{NAK_BYTES}}; new_code = RC_NAK; end
   K_STATUS: begin new_len = 8'd{{STATUS_BYTES}}; new_code = RC_STATUS; end
   K_STATE: begin new_len = 8'd{{STATE_BYTES}}; new_code = RC_STATE; end
   K_CONFIG: begin new_len = 8'd{{CONFIG_BYTES}}; new_code = RC_CONFIG; end
   default: begin new_len = 8'd{{STATUS_BYTES}}; new_code = RC_TELEMETRY; end   // telemetry
   endcase
end

// ---- The reply being written (registered at its start) and its payload (byte 0 in bits 7:0) ---
reg [KIND_BITS-1:0] kind_q = {KIND_BITS{1'b0}};
reg [7:0] cmd_q = 8'd0;                          // the command it answers
reg [7:0] aux_q = 8'd0;                          // the NAK reason or the CONFIG parameter
reg [1:0] load_q = 2'd0;                         // clocks until the payload is read
wire [{{ID_TOP}}:0] identity_payload = {{IDENTITY}};
wire [{{STATE_TOP}}:0] state_payload = {{STATE}};
wire [{{CONFIG_TOP}}:0] config_payload = {{CONFIG}};
reg [{{PAYLOAD_TOP}}:0] new_payload;
always @(*) begin
   case (kind_q)
   K_IDENTITY: new_payload = {{ID_PADDED}};
   K_ACK: new_payload = {{ACK_PADDED}};
   K_NAK: new_payload = {{NAK_PADDED}};
   K_STATUS: new_payload = {{STATUS_PADDED}};
   K_STATE: new_payload = {{STATE_PADDED}};
   K_CONFIG: new_payload = {{CONFIG_PADDED}};
   default: new_payload = {{STATUS_PADDED}};     // telemetry: the status block
   endcase
end

// ---- The frame being written ---------------------------------------------------------------
reg active_q = 1'b0;
reg [7:0] index_q = 8'd0;                        // byte of the frame written next
reg [7:0] len_q = 8'd0;
reg [7:0] code_q = 8'd0;
reg [7:0] seq_q = 8'd0;
reg [{{PAYLOAD_TOP}}:0] payload_q = {{PAYLOAD_BITS}}'d0;   // the bytes not yet written, next in 7:0
reg [15:0] crc_q = 16'd0;
reg pending_q = 1'b0;                            // a telemetry frame waits
reg [7:0] end_q = 8'd0;                          // index of the CRC's low byte: len + 4
// What the byte written next is, registered with its index (so the payload's shift and the
// CRC's update are enabled by registers and the FIFO's full flag alone): a payload byte, the
// CRC's low byte, the CRC's high byte (the frame's last).
reg at_payload_q = 1'b0, at_crc_lo_q = 1'b0, at_last_q = 1'b0;
wire writing = !reset && active_q && !fifo_full;
wire [7:0] index_next = index_q + 8'd1;
reg [7:0] data;
always @(*) begin
   if (index_q == 8'd0) data = START_BYTE;
   else if (index_q == 8'd1) data = len_q;
   else if (index_q == 8'd2) data = code_q;
   else if (index_q == 8'd3) data = seq_q;
   else if (at_payload_q) data = payload_q[7:0];
   else if (at_crc_lo_q) data = crc_q[7:0];
   else data = crc_q[15:8];
end

//@ crc_function
always @(posedge clock) begin
   if (reset) begin
      active_q <= 1'b0;
      index_q <= 8'd0;
      pending_q <= 1'b0;
      load_q <= 2'd0;
      at_payload_q <= 1'b0;
   end else begin
      // The payload, {{PAYLOAD_DELAY}} clocks after the start (the shift below starts at index 4).
      if (load_q == 2'd1) payload_q <= new_payload;
      if (load_q != 2'd0) load_q <= load_q - 2'd1;
      if (!active_q) begin
         if (launch_head || launch_telemetry) begin
            active_q <= 1'b1;
            index_q <= 8'd0;
            at_payload_q <= 1'b0;
            at_crc_lo_q <= 1'b0;
            at_last_q <= 1'b0;
            len_q <= new_len;
            end_q <= new_len + 8'd4;
            code_q <= new_code;
            seq_q <= launch_head ? head_seq : 8'd0;
            kind_q <= kind;
            cmd_q <= head_cmd;
            aux_q <= head_aux;
            load_q <= 2'd{{PAYLOAD_DELAY}};
            crc_q <= CRC_INIT;
         end
      end else if (writing) begin
         // (The CRC covers bytes 1 to len + 3: every byte but the start and the CRC's own.)
         if ((index_q != 8'd0) && !at_crc_lo_q && !at_last_q) crc_q <= crc16_step(crc_q, data);
         index_q <= index_next;
         at_payload_q <= (index_next >= 8'd4) && (index_next < end_q);
         at_crc_lo_q <= index_next == end_q;
         at_last_q <= index_q == end_q;
         if (at_last_q) active_q <= 1'b0;
      end
      if (launch_telemetry) pending_q <= 1'b0;
      else if (telemetry) pending_q <= 1'b1;
   end
   // A payload byte written: the payload shifts (at_payload_q is set only while a frame is
   // written: cleared at its start, after its payload and on reset, so its enable is that
   // register and the FIFO's full flag alone).
   if (!reset && at_payload_q && !fifo_full) payload_q <= payload_q >> 8;
end

always @(*) begin
   pop = !reset && launch_head;
   // The parameter after this edge (the executor registers it decoded, as aux_q takes it).
   read_param = (!reset && (launch_head || launch_telemetry)) ? head_aux : aux_q;
   fifo_write = writing;
   fifo_data = data;
end
