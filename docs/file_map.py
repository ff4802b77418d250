#!/usr/bin/env python3
"""The file tables of docs/architecture.md, read from the code: one row per module (a .hpp with its .cpp, or a
lone .cpp), its job the first sentence of the module's opening comment. Run from the repository root:

    python3 docs/file_map.py            # every layer's table, to paste into docs/architecture.md
    python3 docs/file_map.py --check    # exit 1 and name each module that docs/architecture.md does not list

A header whose first sentence does not say what the module does is the thing to fix, not this script."""
import os
import re
import sys

LAYERS = ["io", "signals", "ins", "sim", "receiver", "fusion", "pipelines", "tools"]


def opening_comment(path):
    lines = []
    with open(path, encoding="utf-8") as f:
        for line in f:
            s = line.strip()
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


def main():
    check = "--check" in sys.argv
    doc = open("docs/architecture.md", encoding="utf-8").read() if check else ""
    missing = 0
    for layer in LAYERS:
        rows = list(modules(layer))
        if check:
            for stem, label, _ in rows:
                if f"`{stem}." not in doc and f"`{stem}`" not in doc:
                    print(f"docs/architecture.md does not list {layer}/{label}")
                    missing += 1
            continue
        print(f"### {layer}/\n| file | job |\n|---|---|")
        for _, label, job in rows:
            print(f"| `{label}` | {job} |")
        print()
    return 1 if missing else 0


if __name__ == "__main__":
    sys.exit(main())
