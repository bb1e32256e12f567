#!/usr/bin/env python3
"""Validates TOML files against a JSON Schema: validate_toml.py SCHEMA FILE...

Uses Python's tomllib and the jsonschema package (Debian: python3-jsonschema). Prints one line
per error naming the file and the JSON path; exit status 1 when any file fails.
"""
import json
import sys
import tomllib

import jsonschema


def main(argv):
    with open(argv[1], encoding="utf-8") as f:
        schema = json.load(f)
    validator = jsonschema.Draft202012Validator(schema)
    failed = 0
    for path in argv[2:]:
        with open(path, "rb") as f:
            doc = tomllib.load(f)
        for err in validator.iter_errors(doc):
            where = "/".join(str(p) for p in err.absolute_path) or "(root)"
            print(f"{path}: {where}: {err.message}")
            failed = 1
    return failed


if __name__ == "__main__":
    sys.exit(main(sys.argv))
