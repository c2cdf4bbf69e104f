// snapgen I/O-top harness: the Verilated I/O top (UART command interface, motion core,
// encoder, PWM, limit switches, emergency stop, amplifier enable, LEDs, status block) behind a
// small C API, built into a shared library that snapgen-sim loads. One call runs many clocks
// with every clock's pins in and every clock's outputs out, so the host side (a UART peer, an
// encoder, switches, or the device model in lockstep) costs no pipe traffic.
//
// The word layouts of a clock's inputs and outputs, and the functions that copy them, are
// generated from the port tables of snapgen-sim (sim/src/io.rs) into snapgen_layout.h.
#include <cstdint>
#include "Vtop.h"
#include "verilated.h"
#include "Vtop___024root.h"
#include "snapgen_layout.h"

// See harness.cpp: after the first eval() the generated _eval is called directly.
void Vtop___024root___eval(Vtop___024root* vlSelf);
#if SNAPGEN_TRACE
#include "verilated_vcd_c.h"
// See harness.cpp: a trace build goes through eval(), or the VCD records no clock.
#define SNAPGEN_EVAL(t) (t)->eval()
#else
#define SNAPGEN_EVAL(t) Vtop___024root___eval((t)->rootp)
#endif

struct Board {
    VerilatedContext* ctx;
    Vtop* top;
#if SNAPGEN_TRACE
    VerilatedVcdC* vcd;
#endif
    uint64_t cycle;
    uint64_t vcd_from;
    uint64_t vcd_to;
};

static void dump(Board* b, uint64_t t) {
#if SNAPGEN_TRACE
    if (b->vcd && b->cycle >= b->vcd_from && b->cycle <= b->vcd_to) b->vcd->dump(t);
#else
    (void)b;
    (void)t;
#endif
}

extern "C" {

uint32_t snapgen_io_abi(void) { return 0x20000 | (SNAPGEN_IN_WORDS << 8) | SNAPGEN_OUT_WORDS; }

void* snapgen_io_new(const char* vcd_path, uint64_t vcd_from, uint64_t vcd_to) {
    Board* b = new Board();
    b->ctx = new VerilatedContext();
    b->top = new Vtop(b->ctx);
    b->cycle = 0;
    b->vcd_from = vcd_from;
    b->vcd_to = vcd_to;
#if SNAPGEN_TRACE
    b->vcd = nullptr;
    if (vcd_path && *vcd_path) {
        b->ctx->traceEverOn(true);
        b->vcd = new VerilatedVcdC();
        b->top->trace(b->vcd, 99);
        b->vcd->open(vcd_path);
    }
#else
    (void)vcd_path;
#endif
    b->top->clock = 0;
    b->top->uart_rx = 1;
    b->top->eval();
    return b;
}

void snapgen_io_free(void* h) {
    Board* b = static_cast<Board*>(h);
#if SNAPGEN_TRACE
    if (b->vcd) {
        b->vcd->close();
        delete b->vcd;
    }
#endif
    b->top->final();
    delete b->top;
    delete b->ctx;
    delete b;
}

// Runs n clocks: clock i takes the pins in[i * SNAPGEN_IN_WORDS ..] before its rising edge and
// writes the outputs after it to out[i * SNAPGEN_OUT_WORDS ..].
void snapgen_io_run(void* h, uint64_t n, const uint32_t* in, uint32_t* out) {
    Board* b = static_cast<Board*>(h);
    Vtop* t = b->top;
    for (uint64_t i = 0; i < n; ++i) {
        snapgen_set(t, in + i * SNAPGEN_IN_WORDS);
        t->clock = 1;
        SNAPGEN_EVAL(t);
        dump(b, 2 * b->cycle + 1);
        snapgen_get(t, out + i * SNAPGEN_OUT_WORDS);
        t->clock = 0;
        SNAPGEN_EVAL(t);
        b->cycle++;
        dump(b, 2 * b->cycle);
    }
}

}  // extern "C"
