// snapgen virtual-board harness: the Verilated I/O top (UART, encoder, PWM, LEDs) behind a
// small C API, built into a shared library that snapgen-sim loads. One call runs many clocks
// with per-clock pin levels in and out, so the host side can play UART and encoder signals.
#include <cstdint>
#include "Vtop.h"
#include "verilated.h"
#include "Vtop___024root.h"

// See harness.cpp: after the first eval() the generated _eval is called directly.
void Vtop___024root___eval(Vtop___024root* vlSelf);

struct Board {
    VerilatedContext* ctx;
    Vtop* top;
};

extern "C" {

uint32_t snapgen_io_abi(void) { return 0x10001; }

void* snapgen_io_new(void) {
    Board* b = new Board();
    b->ctx = new VerilatedContext();
    b->top = new Vtop(b->ctx);
    b->top->clock = 0;
    b->top->uart_rx = 1;
    b->top->eval();
    return b;
}

void snapgen_io_free(void* h) {
    Board* b = static_cast<Board*>(h);
    b->top->final();
    delete b->top;
    delete b->ctx;
    delete b;
}

// Runs n clocks. in[i]: bit 0 reset, bit 1 uart_rx, bit 2 enc_a, bit 3 enc_b, bit 4 enc_i.
// out[i]: bit 0 uart_tx, bit 1 pwm, bit 2 dir, bits 3..6 LEDs (idle, busy, fault, heartbeat);
// pos[i]: the reference position in output LSBs. Sampled after each rising edge.
void snapgen_io_run(void* h, uint64_t n, const uint8_t* in, uint8_t* out, int32_t* pos) {
    Vtop* t = static_cast<Board*>(h)->top;
    for (uint64_t i = 0; i < n; ++i) {
        t->reset = in[i] & 1;
        t->uart_rx = (in[i] >> 1) & 1;
        t->enc_a = (in[i] >> 2) & 1;
        t->enc_b = (in[i] >> 3) & 1;
        t->enc_i = (in[i] >> 4) & 1;
        t->clock = 1;
        Vtop___024root___eval(t->rootp);
        out[i] = (uint8_t)(t->uart_tx | (t->pwm << 1) | (t->dir << 2) | (t->led_idle << 3) |
                           (t->led_busy << 4) | (t->led_fault << 5) | (t->led_heartbeat << 6));
        pos[i] = (int32_t)t->ref_position;
        t->clock = 0;
        Vtop___024root___eval(t->rootp);
    }
}

}  // extern "C"
