#!/usr/bin/env python3
"""Keeps docs/ARCHITECTURE.md's table "Decisions and the one file that makes each" true.

Each row names a decision, the one file that makes it and a Python regular expression that only
that file may contain among the non-test sources (station/, drivers/, sim_devices/,
compensation/: *.cpp, *.hpp, *.h). A row whose pattern matches another file, or not its own,
fails. Usage: decisions.py REPO_ROOT
"""
import pathlib
import re
import sys

ROOTS = ("station", "drivers", "sim_devices", "compensation")
HEADING = "### Decisions and the one file that makes each"


def rows(doc: str):
    """(decision, file, pattern) of each row of the table under HEADING."""
    lines = doc[doc.index(HEADING):].splitlines()[1:]
    table = [l for l in lines if l.startswith("|")]
    out = []
    for line in table[2:]:  # heading and rule
        cells = [c.strip().replace("\\|", "|") for c in re.split(r"(?<!\\)\|", line)[1:-1]]
        if len(cells) != 3:
            raise SystemExit(f"ARCHITECTURE.md: row not 3 cells: {line}")
        decision, file, pattern = cells
        out.append((decision, file.strip("`"), re.compile(pattern.strip("`"))))
    if not out:
        raise SystemExit("ARCHITECTURE.md: the decisions table is empty")
    return out


def main() -> int:
    root = pathlib.Path(sys.argv[1])
    sources = {}
    for top in ROOTS:
        for p in sorted((root / top).rglob("*")):
            if p.suffix in (".cpp", ".hpp", ".h") and p.is_file():
                sources[p.relative_to(root).as_posix()] = p.read_text(errors="replace")
    bad = 0
    for decision, file, pattern in rows((root / "docs/ARCHITECTURE.md").read_text()):
        where = sorted(f for f, text in sources.items() if pattern.search(text))
        if where != [file]:
            bad += 1
            print(f"FAIL {decision}: /{pattern.pattern}/ is in {where or 'no file'}, "
                  f"expected only {file}")
        else:
            print(f"ok   {decision}: {file}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
