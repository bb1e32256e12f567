#!/usr/bin/env python3
"""A changed reply in a shipped session's ascii.log is exit 1 naming ascii.log and the line.

usage: tamper_ascii.py STATION SESSION_DIR
"""
import gzip
import os
import shutil
import subprocess
import sys
import tempfile


def main():
    station, session = sys.argv[1], sys.argv[2]
    with tempfile.TemporaryDirectory() as tmp:
        copy = os.path.join(tmp, "s")
        shutil.copytree(session, copy)
        path = os.path.join(copy, "ascii.log.gz")
        lines = gzip.open(path, "rb").read().split(b"\n")
        rx = [i for i, l in enumerate(lines) if b" rx ascii " in l]
        assert len(rx) > 100, "the session holds too few ASCII replies"
        at = rx[len(rx) // 2]
        fields = lines[at].split(b" ")
        hexed = fields[4]
        fields[4] = hexed[:-1] + (b"0" if hexed[-1:] != b"0" else b"1")  # one nibble of a reply
        lines[at] = b" ".join(fields)
        with gzip.open(path, "wb") as f:
            f.write(b"\n".join(lines))
        r = subprocess.run([station, "replay", copy], capture_output=True, text=True)
        out = r.stdout + r.stderr
        if r.returncode != 1 or "ascii.log" not in out or str(at + 1) not in out:
            print("expected exit 1 naming ascii.log line %d, got %d:\n%s" % (at + 1, r.returncode, out))
            return 1
    print("ok: a changed ASCII reply is named")
    return 0


if __name__ == "__main__":
    sys.exit(main())
