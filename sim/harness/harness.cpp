// snapgen co-simulation harness: the Verilated motion core behind a small C API, built into a
// shared library that snapgen-sim loads. One call runs many clocks and writes every clock's
// outputs into a caller's buffer, so the comparison with the model costs no pipe traffic.
//
// The word layouts of the inputs and of each clock's outputs, and the functions that copy
// them, are generated from the port tables of snapgen-sim (sim/src/fabric.rs) into
// snapgen_layout.h.
#include <cstdint>
#include <cstring>
#include "Vtop.h"
#include "verilated.h"
#include "Vtop___024root.h"
#include "snapgen_layout.h"

// The model's evaluation function. `Vtop::eval()` wraps it with per-call bookkeeping
// (message queue, thread-local context) that cost ~35 ns per call here; after the first
// `eval()` (which runs the initial blocks) the harness calls it directly.
void Vtop___024root___eval(Vtop___024root* vlSelf);
#if SNAPGEN_TRACE
#include "verilated_vcd_c.h"
// A trace build goes through eval(): its bookkeeping marks the clock as active, and the VCD
// writer records nothing of a clock that is not marked (only the first dump's values).
#define SNAPGEN_EVAL(t) (t)->eval()
#else
#define SNAPGEN_EVAL(t) Vtop___024root___eval((t)->rootp)
#endif

struct Core {
    VerilatedContext* ctx;
    Vtop* top;
#if SNAPGEN_TRACE
    VerilatedVcdC* vcd;
#endif
    uint64_t cycle;
    uint64_t vcd_from;
    uint64_t vcd_to;
};

static void dump(Core* c, uint64_t t) {
#if SNAPGEN_TRACE
    if (c->vcd && c->cycle >= c->vcd_from && c->cycle <= c->vcd_to) c->vcd->dump(t);
#else
    (void)c;
    (void)t;
#endif
}

extern "C" {

uint32_t snapgen_core_abi(void) { return (SNAPGEN_IN_WORDS << 8) | SNAPGEN_OUT_WORDS; }

void* snapgen_core_new(const char* vcd_path, uint64_t vcd_from, uint64_t vcd_to) {
    Core* c = new Core();
    c->ctx = new VerilatedContext();
    c->top = new Vtop(c->ctx);
    c->cycle = 0;
    c->vcd_from = vcd_from;
    c->vcd_to = vcd_to;
#if SNAPGEN_TRACE
    c->vcd = nullptr;
    if (vcd_path && *vcd_path) {
        c->ctx->traceEverOn(true);
        c->vcd = new VerilatedVcdC();
        c->top->trace(c->vcd, 99);
        c->vcd->open(vcd_path);
    }
#else
    (void)vcd_path;
#endif
    c->top->clock = 0;
    c->top->eval();
    return c;
}

void snapgen_core_free(void* h) {
    Core* c = static_cast<Core*>(h);
#if SNAPGEN_TRACE
    if (c->vcd) {
        c->vcd->close();
        delete c->vcd;
    }
#endif
    c->top->final();
    delete c->top;
    delete c->ctx;
    delete c;
}

void snapgen_core_set(void* h, const uint32_t* in) {
    snapgen_set(static_cast<Core*>(h)->top, in);
}

// Runs n rising clock edges with the inputs last set; out receives SNAPGEN_OUT_WORDS words per clock,
// sampled after each rising edge.
void snapgen_core_run(void* h, uint64_t n, uint32_t* out) {
    Core* c = static_cast<Core*>(h);
    Vtop* t = c->top;
    for (uint64_t i = 0; i < n; ++i) {
        t->clock = 1;
        SNAPGEN_EVAL(t);
        dump(c, 2 * c->cycle + 1);
        snapgen_get(t, out + i * SNAPGEN_OUT_WORDS);
        t->clock = 0;
        SNAPGEN_EVAL(t);
        c->cycle++;
        dump(c, 2 * c->cycle);
    }
}

}  // extern "C"
