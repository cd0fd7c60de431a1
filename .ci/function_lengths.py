#!/usr/bin/env python3
"""Prints the longest C++ functions among the given files (name, file:line, lines).

A function is a brace-delimited body at namespace or class scope whose header has the form
`name(...) ... {` (free functions, member functions defined in or out of their class,
constructors). Lambdas and local blocks count toward the function that contains them. The scan
matches braces and skips comments, string and character literals; it does not run the
preprocessor, which is enough for this code base.

With --per-step it prints the longest function on XPBD's per-step path instead: the functions
reachable from XpbdSolver::step through calls by name (an identifier followed by "(") among the
functions of the files given, by default those of sim/solvers/xpbd/ (the solver, its rest
scheduler and its kernels). The reachable set is computed, not listed, so a phase added to the
step is checked without editing this script; calls through the kernels' function table reach
the kernels only where their names match. Exits 1 when a per-step function is longer than --max
lines (default 150).
"""

import argparse
import glob
import os
import re
import sys

KEYWORDS = {
    "if", "for", "while", "switch", "catch", "return", "sizeof", "alignof", "decltype",
    "static_assert", "noexcept", "requires", "throw", "new", "delete", "co_return",
}
IDENT = re.compile(r"[A-Za-z_~][A-Za-z_0-9]*(?:\s*::\s*~?[A-Za-z_][A-Za-z_0-9]*)*\s*$")
CALL = re.compile(r"\b([A-Za-z_][A-Za-z_0-9]*)\s*(?:<[^;{}()]*>)?\s*\(")


def blank(text):
    """The text with comments and literals replaced by spaces (newlines kept)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == 'R' and text.startswith('R"', i):
            m = re.match(r'R"([^(\s]*)\(', text[i:])
            if not m:
                out.append(c)
                i += 1
                continue
            end = ")" + m.group(1) + '"'
            j = text.find(end, i + m.end())
            j = n if j < 0 else j + len(end)
            out.append('""' + re.sub(r"[^\n]", " ", text[i + 2:j]))
            i = j
        elif c in "\"'":
            # A digit separator (1'000) is not a character literal.
            if c == "'" and i > 0 and text[i - 1].isalnum() and i + 1 < n and text[i + 1].isalnum():
                out.append(" ")
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(c + " " * (j - i - 2) + c if j - i >= 2 else c)
            i = j
        else:
            out.append(c)
            i += 1
    return "".join(out)


def functions(path):
    """[(name, line, lines, body)] of the functions defined in path."""
    with open(path, encoding="utf-8", errors="replace") as f:
        text = blank(f.read())
    found = []
    stack = []  # per open brace: "fn", "init" or "block"
    paren = 0
    header_start = 0
    in_fn = 0  # open braces of the current function's body
    fn_start = None
    for i, c in enumerate(text):
        if c == "(":
            paren += 1
        elif c == ")":
            paren = max(0, paren - 1)
        elif c == ";" and paren == 0:
            header_start = i + 1
        elif c == "{":
            if in_fn:
                in_fn += 1
                continue
            if paren > 0:
                stack.append("init")
                continue
            header = text[header_start:i]
            name = function_name(header)
            if name:
                offset = header.find(name.split("::")[0].strip())
                fn_start = (name, text.count("\n", 0, header_start + max(0, offset)) + 1, i)
                in_fn = 1
            else:
                stack.append("block")
                header_start = i + 1
        elif c == "}":
            if in_fn:
                in_fn -= 1
                if in_fn == 0:
                    name, line, body = fn_start
                    last = text.count("\n", 0, i) + 1
                    found.append((name, line, last - line + 1, text[body:i + 1]))
                    header_start = i + 1
                continue
            if stack:
                kind = stack.pop()
                if kind == "block" and paren == 0:
                    header_start = i + 1
    return found


def function_name(header):
    """The function's name when header (the text before a '{') opens a function body."""
    h = re.sub(r"\b(public|private|protected)\s*:", " ", header)
    h = re.sub(r"^\s*#.*$", " ", h, flags=re.M)
    depth = 0
    for j, c in enumerate(h):
        if c == "(":
            if depth == 0:
                before = h[:j]
                if "=" in re.sub(r"operator\s*\S+", "", before) or before.rstrip().endswith("]"):
                    return None
                m = IDENT.search(before)
                if not m:
                    m = re.search(r"operator\s*(\(\)|[^\s(]+)\s*$", before)
                    return re.sub(r"\s+", "", m.group(0)) if m else None
                name = re.sub(r"\s+", "", m.group(0))
                if name.split("::")[-1] in KEYWORDS or name in ("struct", "class", "enum"):
                    return None
                return name
            depth += 1
        elif c == ")":
            depth -= 1
    return None


def per_step(funcs):
    """The functions reachable from XpbdSolver::step by calls by name."""
    by_short = {}
    for f in funcs:
        by_short.setdefault(f[0].split("::")[-1], []).append(f)
    roots = [f for f in funcs if f[0] == "XpbdSolver::step"]
    seen, frontier = set(), list(roots)
    while frontier:
        f = frontier.pop()
        key = (f[0], f[4], f[1])
        if key in seen:
            continue
        seen.add(key)
        for callee in set(CALL.findall(f[3])):
            frontier.extend(by_short.get(callee, []))
    return [f for f in funcs if (f[0], f[4], f[1]) in seen], bool(roots)


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("files", nargs="*", help="C++ files (default with --per-step: "
                    "sim/solvers/xpbd/*.cpp, *.hpp, *.inl)")
    ap.add_argument("--per-step", action="store_true",
                    help="only the functions reachable from XpbdSolver::step")
    ap.add_argument("--top", type=int, default=10, help="how many to print (default 10)")
    ap.add_argument("--max", type=int, default=150,
                    help="with --per-step: exit 1 when a function is longer (default 150)")
    args = ap.parse_args()
    files = args.files
    if not files:
        if not args.per_step:
            ap.error("no files given")
        root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
        files = sorted(p for ext in ("cpp", "hpp", "inl")
                       for p in glob.glob(os.path.join(root, "sim/solvers/xpbd", "*." + ext)))
    funcs = []
    for path in files:
        funcs += [f + (os.path.relpath(path),) for f in functions(path)]
    if args.per_step:
        funcs, ok = per_step(funcs)
        if not ok:
            print("XpbdSolver::step not found in the files given", file=sys.stderr)
            return 2
    funcs.sort(key=lambda f: -f[2])
    for name, line, lines, _, path in funcs[:args.top]:
        print(f"{lines:5d}  {name}  {path}:{line}")
    if args.per_step and funcs:
        name, line, lines, _, path = funcs[0]
        print(f"longest function on the per-step path: {name} ({path}:{line}), {lines} lines")
        if lines > args.max:
            print(f"longer than --max {args.max}", file=sys.stderr)
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
