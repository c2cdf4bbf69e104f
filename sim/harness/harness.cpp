// snapgen co-simulation harness: a Verilated design — the motion core (behind the input
// registers of sim/src/wrapper.rs) or the I/O top — behind a small C API, built into a shared
// library that snapgen-sim loads (sim/src/verilated.rs). One call runs many clocks, with the
// inputs held (snapgen_sim_run) or each clock's own (snapgen_sim_run_each), and writes every
// clock's outputs into the caller's buffer, so the comparison with the model costs no pipe
// traffic.
//
// snapgen_layout.h is generated from the design's port tables (sim/src/layout.rs): the word
// layouts of the inputs and of a clock's outputs, the functions that copy them, the inputs at
// rest (SNAPGEN_IDLE) and the ABI word the loader checks (SNAPGEN_ABI).
#include <cstdint>
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

struct Sim {
    VerilatedContext* ctx;
    Vtop* top;
#if SNAPGEN_TRACE
    VerilatedVcdC* vcd;
#endif
    uint64_t cycle;
    uint64_t vcd_from;
    uint64_t vcd_to;
};

static void dump(Sim* s, uint64_t t) {
#if SNAPGEN_TRACE
    if (s->vcd && s->cycle >= s->vcd_from && s->cycle <= s->vcd_to) s->vcd->dump(t);
#else
    (void)s;
    (void)t;
#endif
}

// One clock: the rising edge, the outputs after it, the falling edge.
static inline void clock(Sim* s, uint32_t* out) {
    Vtop* t = s->top;
    t->clock = 1;
    SNAPGEN_EVAL(t);
    dump(s, 2 * s->cycle + 1);
    snapgen_get(t, out);
    t->clock = 0;
    SNAPGEN_EVAL(t);
    s->cycle++;
    dump(s, 2 * s->cycle);
}

extern "C" {

uint32_t snapgen_sim_abi(void) { return SNAPGEN_ABI; }

void* snapgen_sim_new(const char* vcd_path, uint64_t vcd_from, uint64_t vcd_to) {
    Sim* s = new Sim();
    s->ctx = new VerilatedContext();
    s->top = new Vtop(s->ctx);
    s->cycle = 0;
    s->vcd_from = vcd_from;
    s->vcd_to = vcd_to;
#if SNAPGEN_TRACE
    s->vcd = nullptr;
    if (vcd_path && *vcd_path) {
        s->ctx->traceEverOn(true);
        s->vcd = new VerilatedVcdC();
        s->top->trace(s->vcd, 99);
        s->vcd->open(vcd_path);
    }
#else
    (void)vcd_path;
#endif
    snapgen_set(s->top, SNAPGEN_IDLE);
    s->top->clock = 0;
    s->top->eval();
    return s;
}

void snapgen_sim_free(void* h) {
    Sim* s = static_cast<Sim*>(h);
#if SNAPGEN_TRACE
    if (s->vcd) {
        s->vcd->close();
        delete s->vcd;
    }
#endif
    s->top->final();
    delete s->top;
    delete s->ctx;
    delete s;
}

// Applies inputs (SNAPGEN_IN_WORDS words), held until changed.
void snapgen_sim_set(void* h, const uint32_t* in) { snapgen_set(static_cast<Sim*>(h)->top, in); }

// Runs n clocks with the inputs held; out receives SNAPGEN_OUT_WORDS words per clock, sampled
// after each rising edge.
void snapgen_sim_run(void* h, uint64_t n, uint32_t* out) {
    Sim* s = static_cast<Sim*>(h);
    for (uint64_t i = 0; i < n; ++i) clock(s, out + i * SNAPGEN_OUT_WORDS);
}

// Runs n clocks: clock i takes the inputs in[i * SNAPGEN_IN_WORDS ..] before its rising edge and
// writes the outputs after it to out[i * SNAPGEN_OUT_WORDS ..].
void snapgen_sim_run_each(void* h, uint64_t n, const uint32_t* in, uint32_t* out) {
    Sim* s = static_cast<Sim*>(h);
    for (uint64_t i = 0; i < n; ++i) {
        snapgen_set(s->top, in + i * SNAPGEN_IN_WORDS);
        clock(s, out + i * SNAPGEN_OUT_WORDS);
    }
}

}  // extern "C"
