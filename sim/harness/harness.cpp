// snapgen co-simulation harness: the Verilated motion core behind a small C API, built into a
// shared library that snapgen-sim loads. One call runs many clocks and writes every clock's
// outputs into a caller's buffer, so the comparison with the model costs no pipe traffic.
//
// Input words (uint32): see IN_* below. Output words per clock: see OUT_* below.
#include <cstdint>
#include <cstring>
#include "Vtop.h"
#include "verilated.h"
#include "Vtop___024root.h"

// The model's evaluation function. `Vtop::eval()` wraps it with per-call bookkeeping
// (message queue, thread-local context) that cost ~35 ns per call here; after the first
// `eval()` (which runs the initial blocks) the harness calls it directly.
void Vtop___024root___eval(Vtop___024root* vlSelf);
#if SNAPGEN_TRACE
#include "verilated_vcd_c.h"
#endif

enum {
    IN_RESET = 0, IN_TICK_DIV, IN_START, IN_STOP, IN_WRITE_ENABLE, IN_WRITE_ADDRESS,
    IN_WRITE_TICKS, IN_WRITE_SNAP0, IN_WRITE_SNAP1, IN_WRITE_SNAP2, IN_WRITE_SNAP3,
    IN_COUNT_ENABLE, IN_COUNT_VALUE, IN_CRUISE_VALUE, IN_SOFT_STOP, IN_WORDS
};
enum {
    OUT_X0 = 0, OUT_V0 = 4, OUT_A0 = 8, OUT_J0 = 12, OUT_POSITION = 16, OUT_FLAGS = 17,
    OUT_TICK_COUNT = 18, OUT_WORDS = 19
};

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

static void copy4(uint32_t* dst, const VlWide<4>& src) {
    for (int k = 0; k < 4; ++k) dst[k] = src[k];
}

static void dump(Core* c, uint64_t t) {
#if SNAPGEN_TRACE
    if (c->vcd && c->cycle >= c->vcd_from && c->cycle <= c->vcd_to) c->vcd->dump(t);
#else
    (void)c;
    (void)t;
#endif
}

extern "C" {

uint32_t snapgen_core_abi(void) { return (IN_WORDS << 8) | OUT_WORDS; }

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
    Vtop* t = static_cast<Core*>(h)->top;
    t->reset = in[IN_RESET] & 1;
    t->tick_div = in[IN_TICK_DIV];
    t->start = in[IN_START] & 1;
    t->stop = in[IN_STOP] & 1;
    t->write_enable = in[IN_WRITE_ENABLE] & 1;
    t->write_address = in[IN_WRITE_ADDRESS] & 0x1f;
    t->write_ticks = in[IN_WRITE_TICKS];
    for (int k = 0; k < 4; ++k) t->write_snap[k] = in[IN_WRITE_SNAP0 + k];
    t->count_enable = in[IN_COUNT_ENABLE] & 1;
    t->count_value = in[IN_COUNT_VALUE] & 0x3f;
    t->cruise_value = in[IN_CRUISE_VALUE] & 0x3f;
    t->soft_stop = in[IN_SOFT_STOP] & 1;
}

// Runs n rising clock edges with the inputs last set; out receives OUT_WORDS words per clock,
// sampled after each rising edge.
void snapgen_core_run(void* h, uint64_t n, uint32_t* out) {
    Core* c = static_cast<Core*>(h);
    Vtop* t = c->top;
    for (uint64_t i = 0; i < n; ++i) {
        t->clock = 1;
        Vtop___024root___eval(t->rootp);
        dump(c, 2 * c->cycle + 1);
        uint32_t* o = out + i * OUT_WORDS;
        copy4(o + OUT_X0, t->x);
        copy4(o + OUT_V0, t->v);
        copy4(o + OUT_A0, t->a);
        copy4(o + OUT_J0, t->j);
        o[OUT_POSITION] = t->position;
        o[OUT_FLAGS] = (uint32_t)t->segment | ((uint32_t)t->busy << 8) |
                       ((uint32_t)t->done << 9) | ((uint32_t)t->aborted << 10) |
                       ((uint32_t)t->tick << 11) | ((uint32_t)t->active_bank << 12) |
                       ((uint32_t)t->standby_count << 16);
        o[OUT_TICK_COUNT] = t->tick_count;
        t->clock = 0;
        Vtop___024root___eval(t->rootp);
        c->cycle++;
        dump(c, 2 * c->cycle);
    }
}

}  // extern "C"
