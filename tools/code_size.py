#!/usr/bin/env python3
"""Largest files and functions of the C++ sources: the limits docs/architecture.md sets (files <= 800 lines,
functions <= 120 lines in dem/, continuum/, compare/, study/ and io/).

    tools/code_size.py                 # the 10 largest files and functions, and every one over the limits
    tools/code_size.py --check         # exit 1 when a file or function is over its limit

A function is a brace block at namespace or class level whose opening line holds a ')' (a definition, not a
struct or namespace); its length counts from the line of its name to its closing brace. Lambdas and local
classes count in the function that holds them. Strings, characters and comments are skipped.
"""
import argparse
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
CHECKED = ["dem", "continuum", "compare", "study", "io"]
FILE_LIMIT, FUNCTION_LIMIT = 800, 120


def strip(text):
    """The text with comments, strings and character literals blanked (newlines kept)."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i)); i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j])); i = j
        elif text.startswith('R"', i):
            m = re.match(r'R"([^(]*)\(', text[i:])
            end = text.find(")" + m.group(1) + '"', i) if m else -1
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j])); i = j
        elif c in "\"'":
            if c == "'" and i > 0 and (text[i - 1].isalnum()):  # digit separator 1'000
                out.append(" "); i += 1; continue
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            out.append(" " * (j + 1 - i)); i = j + 1
        else:
            out.append(c); i += 1
    return "".join(out)


def functions(path):
    text = strip(path.read_text(errors="replace"))
    lines = text.split("\n")
    result, stack = [], []  # stack of (kind, start line, name)
    pending = ""  # text since the last ; { or } at the current level
    pending_line = 0
    for ln, line in enumerate(lines, 1):
        for ch in line:
            if ch == "{":
                head = pending.strip()
                inside_function = any(k == "function" for k, _, _ in stack)
                kind = "block"
                if not inside_function:
                    if re.search(r"\b(namespace|struct|class|union|enum)\b[^()]*$", head) or head.endswith("="):
                        kind = "scope"
                    elif ")" in head and not re.match(r"^(if|for|while|switch|catch|do)\b", head):
                        kind = "function"
                    else:
                        kind = "scope" if not head or re.search(r"\b(extern)\b", head) else "block"
                name = ""
                if kind == "function":
                    m = re.search(r"([~\w:<>]+)\s*\([^()]*(\([^()]*\)[^()]*)*\)[^()]*$", head.replace("\n", " "))
                    name = m.group(1) if m else head[:60]
                stack.append((kind, pending_line or ln, name))
                pending, pending_line = "", 0
            elif ch == "}":
                if stack:
                    kind, start, name = stack.pop()
                    if kind == "function":
                        result.append((ln - start + 1, start, name))
                pending, pending_line = "", 0
            elif ch == ";":
                pending, pending_line = "", 0
            else:
                if not pending.strip() and not ch.isspace():
                    pending_line = ln
                pending += ch
        pending += "\n"
    return result


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--check", action="store_true", help="exit 1 when something is over its limit")
    ap.add_argument("--top", type=int, default=10)
    ap.add_argument("dirs", nargs="*", default=CHECKED)
    a = ap.parse_args()
    files, funcs = [], []
    for d in a.dirs:
        for p in sorted((ROOT / d).rglob("*")):
            if p.suffix not in (".cpp", ".hpp", ".h", ".cc") or "build" in p.parts:
                continue
            rel = p.relative_to(ROOT)
            files.append((len(p.read_text(errors="replace").splitlines()), str(rel)))
            for length, start, name in functions(p):
                funcs.append((length, f"{rel}:{start}", name))
    files.sort(reverse=True); funcs.sort(reverse=True)
    print(f"largest files ({', '.join(a.dirs)}):")
    for n, f in files[: a.top]:
        print(f"  {n:5d}  {f}")
    print("longest functions:")
    for n, where, name in funcs[: a.top]:
        print(f"  {n:5d}  {name}  ({where})")
    over = [f for f in files if f[0] > FILE_LIMIT] + [f for f in funcs if f[0] > FUNCTION_LIMIT]
    for o in over:
        print("over the limit:", *o[1:], f"({o[0]} lines)")
    return 1 if a.check and over else 0


if __name__ == "__main__":
    sys.exit(main())
