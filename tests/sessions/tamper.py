#!/usr/bin/env python3
"""Issue 19, item 12: a recording that is not the one the run made must not replay "same".

Each tampering below is applied to a fresh copy of a shipped session (tests/sessions/NAME);
`station replay COPY` must exit 1 and name the file (and, for a line-oriented file, the first
line that is not what the run wrote). Bad tolerances are exit 2, the untouched copy exit 0 (so
the harness can pass and each check can fail). Usage: tamper.py STATION SESSION_DIR
"""
import gzip
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

STATION, SESSION = sys.argv[1], sys.argv[2]
failures = []


def path_of(d, name):
    plain = os.path.join(d, name)
    return plain if os.path.exists(plain) else plain + ".gz"


def read_lines(path):
    opener = gzip.open if path.endswith(".gz") else open
    with opener(path, "rb") as f:
        return f.read().split(b"\n")  # a last empty element: the final newline


def write_lines(path, lines):
    data = b"\n".join(lines)
    if path.endswith(".gz"):
        with gzip.open(path, "wb") as f:
            f.write(data)
    else:
        with open(path, "wb") as f:
            f.write(data)


def first_changed_line(old, new):
    """The first line (as digest.txt counts them: newline included) that differs."""
    split = lambda lines: re.findall(rb"[^\n]*\n|[^\n]+$", b"\n".join(lines))
    a, b = split(old), split(new)
    return next((i + 1 for i, (x, y) in enumerate(zip(a, b)) if x != y), min(len(a), len(b)) + 1)


def replay(d, *extra):
    p = subprocess.run([STATION, "replay", d, *extra], capture_output=True, text=True)
    return p.returncode, p.stdout + p.stderr


def check(name, d, code, must_contain):
    rc, out = replay(d)
    ok = rc == code and all(s in out for s in must_contain)
    print(f"{'ok  ' if ok else 'FAIL'} {name}: exit {rc}, expected {code} naming {must_contain}")
    if not ok:
        failures.append(name)
        print("     " + out.strip().replace("\n", "\n     "))


def tamper_lines(name, file, edit):
    """edit(lines) -> lines, on the decompressed lines of `file`; expects FILE:LINE named."""
    d = fresh_copy()
    path = path_of(d, file)
    old = read_lines(path)
    new = edit(list(old))
    assert new != old, f"{name}: the tampering changed nothing"
    write_lines(path, new)
    line = first_changed_line(old, new)
    check(name, d, 1, [f"{os.path.basename(path)}:{line}:"])


def fresh_copy():
    d = os.path.join(tmp, "copy")
    shutil.rmtree(d, ignore_errors=True)
    shutil.copytree(SESSION, d)
    return d


def find(lines, pattern, nth=0):
    hits = [i for i, l in enumerate(lines) if re.search(pattern, l)]
    assert len(hits) > nth, f"no line matches {pattern!r}"
    return hits[nth]


def plus_one_register(device, reg):
    """+1 in the reply of the middle read covering `reg` on `device` (modbus.log)."""

    def edit(lines):
        reads = []
        for i, l in enumerate(lines):
            m = re.search(rb" %s tx modbus-read \S+ .*addr=(\d+) count=(\d+)" % device.encode(), l)
            if m and int(m[1]) <= reg < int(m[1]) + int(m[2]):
                reads.append((i, int(m[1])))
        i, addr = reads[len(reads) // 2]
        j = next(k for k in range(i + 1, len(lines)) if b" %s rx modbus-read " % device.encode() in lines[k])
        f = lines[j].split(b" ")
        data = bytearray.fromhex(f[4].decode())
        at = 3 + 2 * (reg - addr)  # unit, function, byte count, then the registers
        value = (data[at] << 8 | data[at + 1]) + 1 & 0xFFFF
        data[at : at + 2] = value.to_bytes(2, "big")
        f[4] = data.hex().encode()
        lines[j] = b" ".join(f)
        return lines

    return edit


def json_line_edit(pattern, transform, nth=0):
    def edit(lines):
        i = find([l.decode() for l in lines], pattern, nth)
        lines[i] = transform(lines[i])
        return lines

    return edit


def event_spans(lines):
    """(first, last) line of each event object of result.json's "events" (dumped with indent 1:
    ' {' opens an event, ' }' or ' },' closes it)."""
    text = [l.decode() for l in lines]
    start = find(text, r'^ "events": \[')
    spans, i = [], start + 1
    while text[i].startswith(" {"):
        j = i
        while not text[j].startswith(" }"):
            j += 1
        spans.append((i, j))
        i = j + 1
    return spans


def duplicate_event(lines):
    a, b = event_spans(lines)[1]
    block = lines[a : b + 1]
    block[-1] = block[-1].rstrip(b",") + b","
    return lines[:a] + block + lines[a:]


def swap_events(lines):
    (a1, b1), (a2, b2) = event_spans(lines)[1:3]
    first, second = lines[a1 : b1 + 1], lines[a2 : b2 + 1]
    second[-1], first[-1] = second[-1].rstrip(b",") + b",", first[-1].rstrip(b",") + b","
    return lines[:a1] + second + first + lines[b2 + 1 :]


def permute_columns(lines):
    text = [l.decode() for l in lines]
    i = find(text, r'^ "sample_columns": \[')
    lines[i + 2], lines[i + 3] = lines[i + 3], lines[i + 2]
    return lines


def shift_can_time(lines):
    i = len(lines) // 2
    m = re.match(rb"\((\d+\.\d+)\)(.*)", lines[i])
    lines[i] = b"(%.6f)%s" % (float(m[1]) + 0.3, m[2])
    return lines


def flip_byte(lines, at=None):
    i = len(lines) // 3 if at is None else at
    l = bytearray(lines[i])
    k = len(l) // 2
    l[k] = ord("0") if l[k] != ord("0") else ord("1")
    lines[i] = bytes(l)
    return lines


tmp = tempfile.mkdtemp(prefix="station-tamper-")
try:
    check("untouched copy", fresh_copy(), 0, ["same"])
    # The eighteen of issue 19 item 12 (the registers one each).
    if any(b'"ticks_lost": ' in l for l in read_lines(path_of(SESSION, "result.json"))):
        tamper_lines("outage ticks_lost + 100", "result.json", json_line_edit(
            r'"ticks_lost": \d+', lambda l: re.sub(rb"(\d+)$", lambda m: b"%d" % (int(m[1]) + 100), l)))
    else:  # link_faults has outages; this session is run for the other tamperings
        print(f"skip outage ticks_lost + 100: no outage event in {SESSION}")
    tamper_lines("event duplicated", "result.json", duplicate_event)
    tamper_lines("events reordered", "result.json", swap_events)
    tamper_lines("fit warning text changed", "result.json", json_line_edit(
        r'"warnings": ', lambda l: l.replace(b"[]", b'["condition number 1.0e+09"]')
        if b"[]" in l else l + b" "))
    tamper_lines("sample_columns permuted", "result.json", permute_columns)
    tamper_lines("resolved_json changed", "session.toml", json_line_edit(
        r"^resolved_json", lambda l: l.replace(b"39.9", b"39.8", 1)))
    tamper_lines("can.log timestamp + 0.3 s", "can.log", shift_can_time)
    for reg in (104, 110, 200, 310, 2000, 602, 603):
        tamper_lines(f"chamber register {reg} + 1", "modbus.log", plus_one_register("chamber", reg))
    for reg in (100, 6):
        tamper_lines(f"turntable register {reg} + 1", "modbus.log",
                     plus_one_register("turntable", reg))
    # More.
    for log in ("modbus.log", "gpio.log", "can.log", "session.toml", "result.json"):
        tamper_lines(f"a byte of {log} changed", log, flip_byte)
    tamper_lines("the last byte of modbus.log changed", "modbus.log", lambda l: flip_byte(l, -2))
    tamper_lines("a gpio.log line deleted", "gpio.log", lambda l: l[:100] + l[101:])
    tamper_lines("a can.log line appended", "can.log", lambda l: l[:-1] + [l[-2], b""])
    tamper_lines("modbus.log cut short", "modbus.log", lambda l: l[: len(l) // 2])
    tamper_lines("the final newline of can.log removed", "can.log", lambda l: l[:-1])
    tamper_lines("result.json state changed", "result.json", json_line_edit(
        r'^ "state": ', lambda l: re.sub(rb'"[a-z]+",$', b'"completed",', l)
        if b'"completed"' not in l else l.replace(b"completed", b"stopped")))
    tamper_lines("session.toml end state changed", "session.toml", json_line_edit(
        r"^state = ", lambda l: b"state = 'completed'" if b"completed" not in l else b"state = 'stopped'"))
    tamper_lines("a tag of digest.txt changed", "digest.txt", json_line_edit(
        r"^tags modbus.log 65 ", lambda l: l[:-1] + (b"0" if l[-1:] != b"0" else b"1")))
    # Issue 34 point 11: digest.txt has one form (schemas/session.md); an edit that leaves every
    # number as it was (a space, a case, a comment, a CR, an empty line) is named at its line.
    tamper_lines("a space at the end of a digest.txt line", "digest.txt",
                 json_line_edit(r"^file can.log ", lambda l: l + b" "))
    tamper_lines("two spaces between digest.txt fields", "digest.txt",
                 json_line_edit(r"^file gpio.log ", lambda l: l.replace(b" ", b"  ", 1)))
    tamper_lines("a digest.txt tags line in upper case", "digest.txt",
                 json_line_edit(r"^tags modbus.log 65 [0-9a-f]*[a-f]", lambda l: l.upper().replace(
                     b"TAGS MODBUS.LOG", b"tags modbus.log")))
    tamper_lines("a digest.txt SHA-256 in upper case", "digest.txt",
                 json_line_edit(r"^file result.json \d+ [0-9]*[a-f]",
                                lambda l: l[:-64] + l[-64:].upper()))
    tamper_lines("a comment added to digest.txt", "digest.txt",
                 lambda l: l[:4] + [b"# checked by hand"] + l[4:])
    tamper_lines("an empty line added to digest.txt", "digest.txt", lambda l: l[:5] + [b""] + l[5:])
    tamper_lines("a CR at the end of a digest.txt line", "digest.txt",
                 json_line_edit(r"^file session.toml ", lambda l: l + b"\r"))
    tamper_lines("a leading zero in a digest.txt line count", "digest.txt",
                 json_line_edit(r"^file can.log ", lambda l: l.replace(b"can.log ", b"can.log 0", 1)))
    # Bytes after the end of a .gz member: gzip(1) and zlib skip them; they are not the run's.
    for name, extra in (("garbage", b"not the run's bytes\n"), ("zeros", b"\0" * 512)):
        d = fresh_copy()
        gz = path_of(d, "modbus.log")
        assert gz.endswith(".gz"), gz
        with open(gz, "ab") as f:
            f.write(extra)
        check(f"{name} after the end of modbus.log.gz", d, 1,
              ["modbus.log.gz:", "after the end of the compressed data"])
    d = fresh_copy()
    with open(path_of(d, "digest.txt"), "ab") as f:
        f.write(b"trailing")
    check("garbage after the end of digest.txt.gz", d, 1,
          ["digest.txt.gz", "after the end of the compressed data"])
    d = fresh_copy()
    os.remove(path_of(d, "digest.txt"))
    check("digest.txt removed", d, 1, ["digest.txt: missing"])
    d = fresh_copy()
    gz = path_of(d, "gpio.log")
    with open(gz, "r+b") as f:  # a byte inside the deflate stream
        f.seek(os.path.getsize(gz) // 2)
        b = f.read(1)
        f.seek(-1, 1)
        f.write(bytes([b[0] ^ 0x10]))
    check("a byte of gpio.log.gz (compressed) changed", d, 1, ["gpio.log.gz:"])
    d = fresh_copy()
    for name in os.listdir(d):  # decompressed by the user: still the run's bytes
        if name.endswith(".gz"):
            subprocess.run(["gzip", "-d", os.path.join(d, name)], check=True)
    check("every file decompressed", d, 0, ["same"])
    for args in (["--rtol", "nan"], ["--rtol", "-1"], ["--atol", "-1"], ["--atol", "inf"],
                 ["--rtol", "inf"], ["--atol", "nan"]):
        rc, out = replay(fresh_copy(), *args)
        ok = rc == 2
        print(f"{'ok  ' if ok else 'FAIL'} {' '.join(args)}: exit {rc}, expected 2")
        if not ok:
            failures.append(" ".join(args))
finally:
    shutil.rmtree(tmp, ignore_errors=True)
print(f"{len(failures)} failed" + (": " + "; ".join(failures) if failures else ""))
sys.exit(1 if failures else 0)
