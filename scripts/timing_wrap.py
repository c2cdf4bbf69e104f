#!/usr/bin/env python3
"""A routed-timing harness around one generated block, for place and route on its own.

A block such as snapgen_interpolator has far more port bits than a package has pins, so it
cannot be placed as it is. The harness `timing_top` feeds every input from one long shift
register (loaded from one pin) and reduces every output into one registered pin: every path of
the block stays (nothing is constant), and the harness's own paths are one register to the next.

    timing_wrap.py BLOCK.v MODULE > harness.v   (the block's file, then the harness)

The port list is read from the block's own declarations (`input wire [N:0] name;`), so it is
never typed twice.
"""
import re
import sys


def main() -> None:
    path, module = sys.argv[1], sys.argv[2]
    text = open(path).read()
    head = re.search(r"module " + re.escape(module) + r"\((.*?)\);", text, re.S)
    if not head:
        sys.exit(f"{path}: no module {module}")
    ins, outs = [], []
    for name in (p.strip() for p in head.group(1).split(",")):
        decl = re.search(r"(input|output)\s+(?:wire|reg)\s*(?:\[(\d+):0\])?\s*" + re.escape(name) + r";", text)
        if not decl:
            sys.exit(f"{path}: no declaration of port {name}")
        width = int(decl.group(2)) + 1 if decl.group(2) else 1
        if name == "clock":
            continue
        (ins if decl.group(1) == "input" else outs).append((name, width))
    total = sum(w for _, w in ins)
    lines = [
        "// Routed-timing harness (scripts/timing_wrap.py): every input from one shift register,",
        "// every output reduced into one registered pin.",
        "module timing_top(input wire clock, input wire serial_in, output reg serial_out);",
        f"reg [{total - 1}:0] chain = {total}'d0;",
        f"always @(posedge clock) chain <= {{chain[{total - 2}:0], serial_in}};",
    ]
    at = 0
    for name, width in ins:
        lines.append(f"wire [{width - 1}:0] in_{name} = chain[{at + width - 1}:{at}];")
        at += width
    for name, width in outs:
        lines.append(f"wire [{width - 1}:0] out_{name};")
    conns = [".clock(clock)"] + [f".{n}(in_{n})" for n, _ in ins] + [f".{n}(out_{n})" for n, _ in outs]
    lines.append(f"{module} block(" + ", ".join(conns) + ");")
    lines.append("always @(posedge clock) serial_out <= ^{" + ", ".join(f"out_{n}" for n, _ in outs) + "};")
    lines.append("endmodule")
    sys.stdout.write(text + "\n" + "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
