//! The command executor and axis state machine (docs/PROTOCOL.md; the reference, clock for
//! clock, is `snapgen_model::io::executor::Executor`).
//!
//! On each frame with a good CRC it checks the command (code, length, arguments, then the axis
//! state), applies its effect (a segment write, a count, a start, a stop, a configuration
//! register, the amplifier, an error reset) and queues its reply; a bad CRC or a dropped
//! frame queues a NAK with sequence 0. A command with an effect whose code, sequence and CRC
//! equal the last such command's is a retry: its reply is queued again, nothing else happens.
//! A frame that arrives with the reply queue full is dropped unanswered and flagged.
//!
//! Its ports that cross into the motion core are the core's `command` inputs and `status`
//! outputs, and its configuration outputs are the parameters read outside it (groups `core`,
//! `io`, `servo`), each declared from the contract's lists (`snapgen_spec`). Its logic is the
//! template `hdl/verilog/executor.v`, filled from the contract's tables
//! ([`crate::template`]). rust-hdl's own simulator does not run it (its outputs stay at their
//! defaults there): what is checked is the Verilog, against the model, on every clock of the
//! I/O top's co-simulation (`snapgen-sim`).

use rust_hdl::prelude::*;
use snapgen_model::timing::Dividers;
use snapgen_spec::codes::command_spec;
use snapgen_spec::fields::{field, Field, CONFIG_FIELDS, LOAD_SEGMENT_FIELDS, SWAP_AT_FIELDS};
use snapgen_spec::params::{Param, Settable, PARAMS};
use snapgen_spec::rules::SWAP_MIN_LEAD;
use snapgen_spec::{code, COMMANDS};

use crate::frame_rx::{PAYLOAD_BITS, PAYLOAD_BYTES};
use crate::protocol_v::{self, LocalParam, KIND_BITS};
use crate::template::{fill, Holes};
use crate::{hdl_type, D_BITS};

/// The executor's template.
const TEMPLATE: &str = include_str!("../verilog/executor.v");

/// The executor's ports: its own, the core's `command` inputs (as outputs) and `status`
/// outputs (as inputs), and the parameters read outside it (groups `core`, `io`, `servo`, as
/// outputs; the `host` group's registers are its own). Called in two steps: with the core's
/// port list, then with the parameter list.
macro_rules! executor_block {
    (
        own { $($own:tt)* }
        clock: $cdoc:literal;
        inputs {
            reset { $($r:tt)* }
            config { $($c:tt)* }
            encoder { $($e:tt)* }
            command { $($cmd:tt)* }
        }
        outputs {
            registers { $($x:tt)* }
            status { $($st:tt)* }
            report { $($rp:tt)* }
            debug { $($d:tt)* }
        }
    ) => {
        snapgen_spec::with_params!(executor_block! {
            @params own { $($own)* } command { $($cmd)* } status { $($st)* }
        });
    };
    (
        @params
        own {
            inputs { $( $(#[$im:meta])* $i:ident : $it:ty, )* }
            outputs { $( $(#[$om:meta])* $o:ident : $ot:ty, )* }
        }
        command { $( $c:ident : $ck:ident [$cb:expr] $ct:ty, $cdoc:literal; )* }
        status { $( $s:ident : $sk:ident [$sb:expr] $st:ty, $sdoc:literal; )* }
        core { $( $cvar:ident = $ccode:literal, $cname:literal, $creg:ident : $cty:ty,
            $cbits:expr, $csign:ident, $creset:ident $(($crv:expr))?, $cset:ident,
            $cmeaning:literal; )* }
        io { $( $ivar:ident = $icode:literal, $iname:literal, $ireg:ident : $ity:ty,
            $ibits:expr, $isign:ident, $ireset:ident $(($irv:expr))?, $iset:ident,
            $imeaning:literal; )* }
        host { $($host:tt)* }
        servo { $( $svar:ident = $scode:literal, $sname:literal, $sreg:ident : $sty:ty,
            $sbits:expr, $ssign:ident, $sreset:ident $(($srv:expr))?, $sset:ident,
            $smeaning:literal; )* }
    ) => {
        /// The executor.
        #[derive(LogicBlock)]
        pub struct Executor {
            /// Fabric clock.
            pub clock: Signal<In, Clock>,
            $( $(#[$im])* pub $i: Signal<In, $it>, )*
            $( #[doc = concat!("Core: ", $sdoc)] pub $s: Signal<In, hdl_type!($sk, $sb)>, )*
            $( #[doc = concat!("Core: ", $cdoc)] pub $c: Signal<Out, hdl_type!($ck, $cb)>, )*
            $( #[doc = $cname] pub $creg: Signal<Out, Bits<{ ($cbits) as usize }>>, )*
            $( #[doc = $iname] pub $ireg: Signal<Out, Bits<{ ($ibits) as usize }>>, )*
            $( #[doc = $sname] pub $sreg: Signal<Out, Bits<{ ($sbits) as usize }>>, )*
            $( $(#[$om])* pub $o: Signal<Out, $ot>, )*
            _design: Design,
        }

        impl Executor {
            fn build(design: Design) -> Self {
                Executor {
                    clock: Default::default(),
                    $( $i: Default::default(), )*
                    $( $s: Default::default(), )*
                    $( $c: Default::default(), )*
                    $( $creg: Default::default(), )*
                    $( $ireg: Default::default(), )*
                    $( $sreg: Default::default(), )*
                    $( $o: Default::default(), )*
                    _design: design,
                }
            }

            /// Marks every output as driven (by the Verilog).
            fn connect_outputs(&mut self) {
                $( self.$c.connect(); )*
                $( self.$creg.connect(); )*
                $( self.$ireg.connect(); )*
                $( self.$sreg.connect(); )*
                $( self.$o.connect(); )*
            }
        }
    };
}

snapgen_spec::with_motion_core_ports!(executor_block! {
    own {
        inputs {
            /// Synchronous reset.
            reset: Bit,
            /// Pulse: a frame with a good CRC.
            frame: Bit,
            /// Pulse: a frame with a bad CRC.
            bad_crc: Bit,
            /// Pulse: a partial frame was dropped.
            dropped: Bit,
            /// Pulse: UART framing error.
            line_error: Bit,
            /// The frame's command.
            cmd: Bits<8>,
            /// Its sequence number.
            seq: Bits<8>,
            /// Its payload length.
            len: Bits<8>,
            /// Its last payload bytes, the last one in bits 7:0.
            payload: Bits<PAYLOAD_BITS>,
            /// The CRC it carried.
            crc: Bits<16>,
            /// The reply queue is full.
            queue_full: Bit,
            /// Positive limit switch (filtered, polarity applied).
            limit_pos: Bit,
            /// Negative limit switch.
            limit_neg: Bit,
            /// Emergency stop.
            estop: Bit,
            /// The encoder's count of illegal transitions.
            encoder_errors: Bits<16>,
            /// The controller: the following error is beyond its limit.
            following_fault: Bit,
            /// The controller skipped a sample.
            servo_overrun_in: Bit,
            /// The parameter the reply transmitter's CONFIG reply names after this edge
            /// (combinational); `read_value` gives its value two clocks later.
            read_param: Bits<8>,
        }
        outputs {
            /// TELEMETRY_PERIOD and WATCHDOG_MS are the executor's own; the value, on the
            /// clock before, of the parameter `read_param` named on the clock before that
            /// (registered twice: the parameter one-hot, then the value; 0 for an unknown one).
            read_value: Bits<D_BITS>,
            /// The axis state (the status block's byte).
            state: Bits<8>,
            /// Why in ErrorStop (the status block's byte).
            error: Bits<8>,
            /// The amplifier is enabled.
            amplifier: Bit,
            /// A UART framing error was seen.
            uart_error: Bit,
            /// A frame was dropped with the reply queue full.
            reply_overflow: Bit,
            /// The encoder's error count at the last RESET command (an encoder error shows
            /// while the count differs).
            encoder_errors_seen: Bits<16>,
            /// The controller skipped a sample (since reset or the last RESET command).
            servo_overrun: Bit,
            /// Frames with a bad CRC.
            bad_crc_count: Bits<16>,
            /// Frames with a bad length, an unknown command, or cut short.
            bad_frames_count: Bits<16>,
            /// Pulse: queue a reply.
            reply: Bit,
            /// Its kind.
            reply_kind: Bits<{ KIND_BITS as usize }>,
            /// The command it answers.
            reply_cmd: Bits<8>,
            /// Its sequence number.
            reply_seq: Bits<8>,
            /// The NAK reason or the CONFIG parameter.
            reply_aux: Bits<8>,
            /// Pulse: send telemetry.
            telemetry: Bit,
        }
    }
});

/// What the Verilog is generated for: the tick divider and input polarity after reset, and
/// the watchdog's clocks per millisecond.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Design {
    dividers: Dividers,
    input_polarity: u8,
}

impl Executor {
    /// An executor for a design with these dividers (the tick divider after reset and the
    /// watchdog's clocks per millisecond) and input polarity after reset.
    pub fn new(dividers: Dividers, input_polarity: u8) -> Self {
        Executor::build(Design {
            dividers,
            input_polarity,
        })
    }
}

impl Default for Executor {
    fn default() -> Self {
        Executor::new(crate::defaults::default_dividers(), 0)
    }
}

impl Logic for Executor {
    fn update(&mut self) {}

    fn connect(&mut self) {
        self.connect_outputs();
    }

    fn hdl(&self) -> Verilog {
        Verilog::Custom(executor_verilog(
            &self._design.dividers,
            self._design.input_polarity,
        ))
    }
}

/// `|value[D_BITS-2:k]`: the CONFIGURE value is above `max = 2^k − 1` (its sign bit is
/// checked apart).
fn above_max(param: Param) -> String {
    let max = param.max();
    let k = (max + 1).trailing_zeros();
    assert_eq!(
        max + 1,
        1i128 << k,
        "{}: a maximum of 2^k - 1",
        param.name()
    );
    if k >= D_BITS as u32 - 1 {
        "1'b0".to_string()
    } else {
        format!("(|cfg_value[D_BITS-2:{k}])")
    }
}

/// A received payload field of command `cmd`, as the template names it.
fn payload_field(name: &str, bits: &str, cmd: u8, f: Field) -> String {
    let n = command_spec(cmd).expect("a command of the table").len as usize;
    assert!(n <= PAYLOAD_BYTES);
    format!(
        "wire [{bits}-1:0] {name} = {};",
        protocol_v::received_field("payload", n, f.offset, f.bytes)
    )
}

/// The executor's Verilog body: its template, filled.
pub fn executor_verilog(d: &Dividers, input_polarity: u8) -> String {
    let mut table = String::new();
    for c in COMMANDS {
        table.push_str(&format!(
            "CMD_{0}: begin known = 1'b1; want_len = LEN_{0}; has_effect = 1'b{1}; end\n",
            c.name,
            u8::from(c.effect)
        ));
    }
    let fields = [
        payload_field(
            "seg_index",
            "8",
            code::LOAD_SEGMENT,
            field(&LOAD_SEGMENT_FIELDS, "index"),
        ),
        payload_field(
            "seg_ticks",
            "TICK_BITS",
            code::LOAD_SEGMENT,
            field(&LOAD_SEGMENT_FIELDS, "ticks"),
        ),
        payload_field(
            "seg_snap",
            "D_BITS",
            code::LOAD_SEGMENT,
            field(&LOAD_SEGMENT_FIELDS, "snap"),
        ),
        "wire [7:0] arg0 = payload[7:0];   // the byte of a one-byte payload".to_string(),
        payload_field(
            "cfg_param",
            "8",
            code::CONFIGURE,
            field(&CONFIG_FIELDS, "param"),
        ),
        payload_field(
            "cfg_value",
            "D_BITS",
            code::CONFIGURE,
            field(&CONFIG_FIELDS, "value"),
        ),
        payload_field(
            "swap_tick",
            "TIME_BITS",
            code::SWAP_AT,
            field(&SWAP_AT_FIELDS, "tick"),
        ),
    ]
    .join("\n");
    // Parameters: known, when settable, above the maximum, the register and its moves.
    let names = |f: &dyn Fn(&snapgen_spec::ParamSpec) -> bool| {
        let v: Vec<String> = PARAMS
            .iter()
            .filter(|p| f(p))
            .map(|p| format!("(q == P_{})", p.name))
            .collect();
        if v.is_empty() {
            "1'b0".to_string()
        } else {
            v.join(" || ")
        }
    };
    let functions = format!(
        "function automatic param_known(input [7:0] q);\n   param_known = {};\nendfunction\n\n\
         function automatic param_at_rest(input [7:0] q);   // set only while the axis is at rest\n   param_at_rest = {};\nendfunction\n\n\
         function automatic param_disabled(input [7:0] q);  // set only while Disabled\n   param_disabled = {};\nendfunction",
        names(&|_| true),
        names(&|p| p.settable == Settable::AtRest),
        names(&|p| p.settable == Settable::Disabled),
    );
    let (mut over, mut set, mut regs, mut holds, mut select) = (
        String::new(),
        String::new(),
        String::new(),
        String::new(),
        String::new(),
    );
    let (mut resets, mut clocked, mut outs, mut read, mut read_select) = (
        String::new(),
        String::new(),
        String::new(),
        String::new(),
        String::new(),
    );
    for (k, p) in PARAMS.iter().enumerate() {
        let (name, bits) = (p.register, p.bits);
        let pn = format!("P_{}", p.name);
        over.push_str(&format!("{pn}: cfg_over = {};\n", above_max(p.param)));
        select.push_str(&format!("pre_cfg_sel[{k}] <= cfg_param == {pn};\n"));
        set.push_str(&format!(
            "if (cfg_sel_q[{k}]) n_{name} = cfg_value_q[{bits}-1:0];\n"
        ));
        regs.push_str(&format!(
            "reg [{bits}-1:0] {name}_q = {bits}'d0, n_{name};   // {}\n",
            p.name
        ));
        holds.push_str(&format!("n_{name} = {name}_q;\n"));
        let design = match p.param {
            Param::TickDivider => i128::from(d.tick_div),
            Param::InputPolarity => i128::from(input_polarity),
            _ => 0,
        };
        resets.push_str(&format!("{name}_q <= {bits}'d{};\n", p.reset_value(design)));
        clocked.push_str(&format!("{name}_q <= n_{name};\n"));
        read_select.push_str(&format!("{pn}: read_sel_q[{k}] <= 1'b1;\n"));
        read.push_str(&format!(
            "| ({{D_BITS{{read_sel_q[{k}]}}}} & {})\n",
            if bits as usize == D_BITS {
                format!("{name}_q")
            } else {
                format!("{{{}'d0, {name}_q}}", D_BITS as u32 - bits)
            }
        ));
        // The parameters read outside the executor leave it; its own stay.
        if p.group != "host" {
            outs.push_str(&format!("{name} = {name}_q;\n"));
        }
    }
    let holes = Holes::new()
        .block("payload_fields", fields)
        .block("command_table", table)
        .block("param_functions", functions)
        .block("param_over", over)
        .block("param_registers", regs)
        .block("param_holds", holds)
        .block("param_select", select)
        .block("param_set", set)
        .block("param_resets", resets)
        .block("param_clocked", clocked)
        .block("param_outputs", outs)
        .block("param_read_select", read_select)
        .block("param_read", read);
    let body = fill("executor.v", TEMPLATE, &holes).expect("the executor's template is filled");
    let mut params = protocol_v::localparams();
    params.retain(|q| q.name != "MAX_SEGMENTS");
    params.extend([
        LocalParam::new("CLOCKS_PER_MS", 32, u64::from(d.clocks_per_ms)),
        LocalParam::new("SWAP_MIN_LEAD", 64, SWAP_MIN_LEAD as u64),
        // The bits SWAP_MIN_LEAD needs: the lateness check compares those and zero-detects
        // the rest.
        LocalParam::new(
            "LEAD_BITS",
            32,
            u64::from(u64::BITS - (SWAP_MIN_LEAD as u64).leading_zeros()),
        ),
        LocalParam::new("PARAM_COUNT", 32, PARAMS.len() as u64),
        // Compared with a byte of the payload.
        LocalParam::new(
            "MAX_SEGMENTS",
            8,
            u64::from(snapgen_spec::widths::MAX_SEGMENTS),
        ),
    ]);
    protocol_v::with_localparams(&params, &body)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn executor_is_synthesizable() {
        crate::synth_check::synth_block("executor", Executor::default());
    }

    #[test]
    fn every_code_comes_from_the_protocol_table() {
        let v = executor_verilog(&crate::defaults::default_dividers(), 0);
        for c in COMMANDS {
            assert!(
                v.contains(&format!("localparam [7:0] CMD_{} = 8'd{};", c.name, c.code)),
                "{}",
                c.name
            );
        }
        // No command code typed as a literal in a case label.
        assert!(!v.contains("8'h0"), "a literal code");
        for p in PARAMS {
            assert!(v.contains(&format!("reg [{}-1:0] {}_q", p.bits, p.register)));
        }
    }
}
