#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""docs/cli.md from the program itself: `ultratrack --help` and every subcommand's `--help` (and its own
subcommands'), so the flag reference cannot drift from the code. Run from anywhere:

    python3 docs/cli_reference.py build/tools/ultratrack            # print
    python3 docs/cli_reference.py build/tools/ultratrack --write    # rewrite docs/cli.md
    python3 docs/cli_reference.py build/tools/ultratrack --check    # exit 1 when docs/cli.md differs (ctest docs.cli)
"""
import os
import re
import subprocess
import sys

DOC = os.path.join(os.path.dirname(os.path.abspath(__file__)), "cli.md")


def help_text(program, *args):
    out = subprocess.run([program, *args, "--help"], capture_output=True, text=True, check=True).stdout
    # The usage line names the program as it was called; the reference names it as a user types it.
    return re.sub(r"^Usage: \S+", "Usage: ultratrack", out, flags=re.M).rstrip() + "\n"


def subcommands(top_help):
    names, inside = [], False
    for line in top_help.splitlines():
        if line.startswith("Subcommands:"):
            inside = True
        elif inside and line.startswith("  ") and line.strip():
            names.append(line.split()[0])
        elif inside and line.strip() and not line.startswith(" "):
            inside = False
    return names


def document(program):
    top = help_text(program)
    parts = ["# Command-line reference",
             "",
             "Printed from the program by `python3 docs/cli_reference.py build/tools/ultratrack --write`; ctest",
             "`docs.cli` fails when this page and the program differ. Exit codes: 0 done, 2 bad input (one line naming",
             "the file and the problem), 3 ran to the end without a result (e.g. no fix), 1 anything else.",
             "",
             "```", top.rstrip(), "```", ""]
    for name in subcommands(top):
        text = help_text(program, name)
        parts += [f"## {name}", "", "```", text.rstrip(), "```", ""]
        for sub in subcommands(text):  # a command with subcommands of its own (campaign run, report, ...)
            parts += [f"### {name} {sub}", "", "```", help_text(program, name, sub).rstrip(), "```", ""]
    return "\n".join(parts)


def main():
    if len(sys.argv) < 2:
        print(__doc__)
        return 2
    text = document(sys.argv[1])
    if "--write" in sys.argv:
        open(DOC, "w", encoding="utf-8").write(text)
    elif "--check" in sys.argv:
        current = open(DOC, encoding="utf-8").read() if os.path.exists(DOC) else ""
        if current != text:
            print("docs/cli.md differs from the program's --help: run "
                  "`python3 docs/cli_reference.py build/tools/ultratrack --write`")
            return 1
    else:
        print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
