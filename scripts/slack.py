#!/usr/bin/env python3
"""Every endpoint's routed slack, from the SDF nextpnr-ecp5 writes (`--sdf FILE`).

nextpnr reports the one worst path of a clock; closing timing on a design whose failing
endpoints lie in several blocks wants all of them. This reads the SDF's cell delays (IOPATH)
and routed interconnect delays (INTERCONNECT), finds the latest arrival at every flip-flop
input and LUT-RAM write port by a longest-path search from every flip-flop output (nextpnr's
own figures: clock-to-out, routing, logic, setup; constants arrive never), and groups the
endpoints with less than THRESHOLD ns of slack by their source block and destination block
(the hierarchical name without its last part). Its worst slack is nextpnr's: 1/Fmax − period.

    slack.py ROUTED.sdf PERIOD_NS [THRESHOLD_NS] [--list N]

Prints one line per (source block, destination block) pair, worst first, then the count and the
worst slack; with --list N, the N worst endpoints with their sources.
"""
import collections
import re
import sys

CELL = re.compile(r'\(CELL\s*\(CELLTYPE "([^"]*)"\)\s*\(INSTANCE ([^)]*)\)(.*?)\n    \)\n', re.S)
IOPATH = re.compile(r"\(IOPATH (\S+) (\S+) \((\d+):(\d+):(\d+)\)")
INTERCONNECT = re.compile(r"\(INTERCONNECT (\S+) (\S+) \((\d+):(\d+):(\d+)\)")
SETUP = re.compile(r"\(SETUPHOLD (\S+) \(posedge CLK\) \((\d+):(\d+):(\d+)\)")
# LUT-RAM write ports: the end of a path (their read addresses pass through to the data out).
RAM_WRITE = {"WAD0", "WAD1", "WAD2", "WAD3", "WD", "WD0", "WD1", "WRE"}


def unescape(name):
    return name.replace("\\", "")


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    listing = 0
    if "--list" in sys.argv:
        listing = int(sys.argv[sys.argv.index("--list") + 1])
        args.remove(str(listing))
    if len(args) < 2:
        sys.exit(__doc__)
    text = open(args[0]).read()
    period = float(args[1]) * 1000.0  # the SDF's unit: ps (TIMESCALE 1ps)
    threshold = float(args[2]) * 1000.0 if len(args) > 2 else 0.0
    if "(TIMESCALE 1ps)" not in text:
        sys.exit(f"{args[0]}: not an SDF in picoseconds as nextpnr writes it")

    kind = {}
    arcs = collections.defaultdict(list)  # (cell, output) -> [(input, delay)]
    setup = {}
    for m in CELL.finditer(text):
        cell = unescape(m.group(2).strip())
        kind[cell] = m.group(1)
        for a in IOPATH.finditer(m.group(3)):
            arcs[(cell, a.group(2))].append((a.group(1), int(a.group(5))))
        for s in SETUP.finditer(m.group(3)):
            setup[(cell, s.group(1))] = int(s.group(4))
    feeds = collections.defaultdict(list)  # (cell, input) -> [(cell, output, delay)]
    for a in INTERCONNECT.finditer(text):
        src_cell, src_port = unescape(a.group(1)).rsplit("/", 1)
        dst_cell, dst_port = unescape(a.group(2)).rsplit("/", 1)
        feeds[(dst_cell, dst_port)].append((src_cell, src_port, int(a.group(5))))
    arc_inputs = collections.defaultdict(set)
    for (cell, _), ins in arcs.items():
        arc_inputs[cell].update(i for i, _ in ins)

    sys.setrecursionlimit(1_000_000)
    never = (-(10**12), None)
    memo = {}

    def at_output(cell, port):
        """Latest arrival at an output pin and the flip-flop the path starts at."""
        key = (cell, port)
        if key in memo:
            return memo[key]
        memo[key] = never  # (a combinational loop arrives never)
        if cell.startswith("$PACKER"):
            result = never  # a constant 0 or 1
        elif kind.get(cell) == "TRELLIS_FF":
            result = (max((d for i, d in arcs.get(key, []) if i == "CLK"), default=0), cell)
        else:
            result = never
            for port_in, delay in arcs.get(key, []):
                t, start = at_input(cell, port_in)
                if t + delay > result[0]:
                    result = (t + delay, start)
        memo[key] = result
        return result

    def at_input(cell, port):
        best = never
        for src_cell, src_port, delay in feeds.get((cell, port), []):
            t, start = at_output(src_cell, src_port)
            if t + delay > best[0]:
                best = (t + delay, start)
        return best

    ends = []
    for (cell, port) in list(feeds):
        if port in ("CLK", "WCK"):
            continue
        t = kind.get(cell)
        is_end = t == "TRELLIS_FF" or (
            t in ("TRELLIS_COMB", "TRELLIS_RAMW") and port in RAM_WRITE and port not in arc_inputs[cell]
        )
        if not is_end:
            continue
        arrival, start = at_input(cell, port)
        if start is None:
            continue  # fed by constants or by inputs only
        ends.append((period - arrival - setup.get((cell, port), 0), cell, port, start))
    if not ends:
        sys.exit(f"{args[0]}: no register-to-register path")
    ends.sort()

    def block(name):
        return name.rsplit(".", 1)[0] if "." in name else "(top)"

    groups = collections.defaultdict(list)
    short = [e for e in ends if e[0] < threshold]
    for e in short:
        groups[(block(e[3]), block(e[1]))].append(e)
    for (src, dst), es in sorted(groups.items(), key=lambda kv: kv[1][0][0]):
        slack, cell, port, start = es[0]
        print(f"{len(es):5d} endpoints, worst {slack / 1000:+.2f} ns: {src} -> {dst}"
              f"   (e.g. {start} -> {cell}.{port})")
    for slack, cell, port, start in ends[:listing]:
        print(f"  {slack / 1000:+.3f} ns  {start} -> {cell}.{port}")
    print(f"{len(short)} of {len(ends)} endpoints below {threshold / 1000:+.2f} ns of slack; "
          f"worst {ends[0][0] / 1000:+.3f} ns")


if __name__ == "__main__":
    main()
