#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The file tables of docs/architecture.md, read from the code: one row per module (a .hpp with its .cpp, or a
lone .cpp), its job the first sentence of the module's opening comment. Run from the repository root:

    python3 docs/file_map.py            # every layer's table
    python3 docs/file_map.py --write    # the tables of docs/architecture.md's "Modules" rewritten in place
    python3 docs/file_map.py --check    # exit 1 when a table there differs from the code (ctest docs.file_map)

A header whose first sentence does not say what the module does is the thing to fix, not this script."""
import os
import re
import sys

LAYERS = ["io", "signals", "ins", "sim", "receiver", "fusion", "pipelines", "config", "tools", "python"]
DOC = "docs/architecture.md"


def opening_comment(path):
    lines = []
    with open(path, encoding="utf-8") as f:
        for line in f:
            s = line.strip()
            if s.startswith("//") and "SPDX-License-Identifier" in s:
                continue  # the licence tag, not the module's description
            if s.startswith("//"):
                lines.append(s[2:].strip())
            elif lines or (s and not s.startswith("#")):
                break
    return " ".join(lines)


ABBREVIATIONS = ("eq.", "eqs.", "e.g.", "i.e.", "Fig.", "no.", "sec.", "ed.", "vs.", "approx.")


def first_sentence(text, limit=230):
    """Up to the first full stop that ends a sentence; a short title before a colon takes what follows too."""
    end = 0
    for m in re.finditer(r"[.:;](\s|$)", text):
        head = text[: m.start() + 1]
        if head.endswith(ABBREVIATIONS):
            continue
        if text[m.start()] in ":;" and len(head) < 45:
            continue
        end = m.start() + 1
        break
    s = (text[:end] if end else text).rstrip(":;")
    if len(s) > limit:
        s = s[: limit - 4].rsplit(" ", 1)[0] + " ..."
    return s.replace("|", "\\|")


def modules(layer):
    stems = {}
    for f in sorted(os.listdir(layer)):
        m = re.match(r"(.+?)\.(hpp|cpp|hpp\.in)$", f)
        if m:
            stems.setdefault(m.group(1), []).append(f)
    for stem, files in sorted(stems.items()):
        header = next((f for f in files if f.endswith(".hpp") or f.endswith(".hpp.in")), None)
        source = header or files[0]
        suffixes = "/".join(f[len(stem):] for f in files)
        yield stem, stem + suffixes, first_sentence(opening_comment(os.path.join(layer, source)))


def table(layer):
    lines = ["| file | job |", "|---|---|"]
    lines += [f"| `{label}` | {job} |" for _, label, job in modules(layer)]
    return lines


def with_tables(doc_lines):
    """The document with the table under each "### <layer>/" heading of "## Modules" made from the code; a layer
    without a heading there is an error (its heading and prose are written by hand)."""
    out, missing = list(doc_lines), []
    start = out.index("## Modules")
    for layer in LAYERS:
        try:
            at = out.index(f"### {layer}/", start)
        except ValueError:
            missing.append(layer)
            continue
        first = at + 1
        while first < len(out) and not out[first].startswith("|"):
            if out[first].startswith("#"):
                break
            first += 1
        last = first
        while last < len(out) and out[last].startswith("|"):
            last += 1
        out[first:last] = table(layer)
    return out, missing


def main():
    if "--write" in sys.argv or "--check" in sys.argv:
        os.chdir(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
        lines = open(DOC, encoding="utf-8").read().split("\n")
        new, missing = with_tables(lines)
        for layer in missing:
            print(f"{DOC}: no '### {layer}/' section under '## Modules'")
        if "--write" in sys.argv:
            open(DOC, "w", encoding="utf-8").write("\n".join(new))
            return 1 if missing else 0
        stale = [l for l in new if l not in lines] + [l for l in lines if l.startswith("| `") and l not in new]
        for l in stale:
            print(f"{DOC}: differs from the code: {l[:110]}")
        if stale:
            print("run `python3 docs/file_map.py --write` and review the rows (a header's first sentence is the row)")
        return 1 if missing or stale else 0
    for layer in LAYERS:
        print(f"### {layer}/")
        print("\n".join(table(layer)))
        print()
    return 0


if __name__ == "__main__":
    sys.exit(main())
