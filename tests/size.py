#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""size.py - the house rule on size (docs/development.md): every C source and
header of core/, fit/, cli/, api/, server/ and dem/ at most 500 lines, every function at
most 80 (from the line that names it to its closing brace), unless the comment
just above the function gives a reason that starts with "long:".

usage: tests/size.py [--self-test]
Prints each file or function over its limit; exit status 1 if any.
"""
import glob
import re
import sys

FILE_MAX, FUNC_MAX = 500, 80
DIRS = ["core", "fit", "cli", "api", "server", "server/*", "dem", "dem/cli"]


def over(path, text):
    lines = text.split("\n")
    if lines and lines[-1] == "":
        lines.pop()
    found = []
    if len(lines) > FILE_MAX:
        found.append(f"{path}: {len(lines)} lines (at most {FILE_MAX})")
    start = None
    for i, line in enumerate(lines):
        if start is None and re.match(r"[a-z].*\(", line) and not line.rstrip().endswith(";"):
            start = i
        elif start is not None and line.startswith("}"):
            n = i - start
            above = lines[start - 1] if start > 0 else ""
            if n > FUNC_MAX and "long:" not in above:
                name = re.search(r"(\w+)\s*\(", lines[start]).group(1)
                found.append(f"{path}:{start + 1}: {name} is {n} lines (at most {FUNC_MAX})")
            start = None
        elif start is not None and line.endswith(";") and not line.startswith(("\t", " ")):
            start = None  # a declaration over several lines
    return found


def self_test():
    long_fn = "int f(void)\n{\n" + "\tx();\n" * 85 + "}\n"
    assert over("t.c", long_fn), "a function of 86 lines is over"
    assert not over("t.c", "/* long: a table reads better whole */\n" + long_fn), "a reason exempts it"
    assert over("t.c", "x\n" * 501), "a file of 501 lines is over"
    assert not over("t.c", "x\n" * 500), "500 lines is within"
    assert over("t.h", "x\n" * 501), "a header of 501 lines is over"
    print("size.py: self-test passed")


def main():
    if sys.argv[1:] == ["--self-test"]:
        self_test()
        return 0
    found = []
    for d in DIRS:
        for path in sorted(glob.glob(f"{d}/*.c") + glob.glob(f"{d}/*.h")):
            with open(path, encoding="utf-8") as f:
                found += over(path, f.read())
    for line in found:
        print(line)
    print(f"size.py: {len(found)} over the limits")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
