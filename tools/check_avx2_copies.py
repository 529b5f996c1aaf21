#!/usr/bin/env python3
"""Checks that a built libsffd runs AVX instructions only in the CPU kernels' AVX2 copies.

The CPU device compiles each kernel's twin twice: for the build's baseline and, flattened into
runTwinWithAvx2 (kernels/common/cpu_kernel.h), for AVX2, chosen at run time. Were any function of the
twins' headers compiled for AVX2 out of line, the linker could hand that copy to a baseline caller,
and the library would stop with an illegal instruction on a processor without AVX2 (none of this
project's machines). This lists every function of the library with a VEX-encoded instruction
(AVX registers or v-prefixed mnemonics) and fails on any outside those copies.

    tools/check_avx2_copies.py build/libsffd.so [objdump]
"""
import re
import subprocess
import sys


def main():
    lib = sys.argv[1]
    objdump = sys.argv[2] if len(sys.argv) > 2 else "objdump"
    text = subprocess.run([objdump, "-d", "--no-show-raw-insn", "-C", lib], check=True, capture_output=True,
                          text=True).stdout
    function, copies, leaks = None, set(), set()
    header = re.compile(r"^[0-9a-f]+ <(.*)>:$")
    vex = re.compile(r"^\s*[0-9a-f]+:\s+(v[a-z0-9]+\s|.*%[yz]mm)")
    for line in text.splitlines():
        m = header.match(line)
        if m:
            function = m.group(1)
        elif function and vex.match(line):
            (copies if "runTwinWithAvx2<" in function else leaks).add(function)
    for f in sorted(leaks):
        print("AVX instructions outside the AVX2 copies:", f[:200])
    print(f"{len(copies)} functions of AVX2 copies, {len(leaks)} other functions with AVX instructions")
    # The copies must exist where the compiler made them (x86-64 GCC or Clang): else the check checks nothing.
    return 1 if leaks or not copies else 0


if __name__ == "__main__":
    sys.exit(main())
