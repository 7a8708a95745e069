#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
"""Validate lumx bundle manifests against schema/bundle-manifest.schema.json (Debian: python3-jsonschema).

Usage: validate.py MANIFEST_OR_BUNDLE... ; exit status 0 when every manifest is valid, 1 otherwise.
Each error is printed as "file: /json/pointer: message".
"""
import json
import os
import sys

import jsonschema

SCHEMA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "bundle-manifest.schema.json")


def main(paths):
    with open(SCHEMA, encoding="utf-8") as f:
        validator = jsonschema.Draft202012Validator(json.load(f))
    failed = False
    for path in paths:
        if os.path.isdir(path):
            path = os.path.join(path, "manifest.json")
        try:
            with open(path, encoding="utf-8") as f:
                manifest = json.load(f)
        except (OSError, ValueError) as e:
            print(f"{path}: {e}")
            failed = True
            continue
        for error in sorted(validator.iter_errors(manifest), key=lambda e: list(e.absolute_path)):
            pointer = "/" + "/".join(str(p) for p in error.absolute_path)
            print(f"{path}: {pointer}: {error.message}")
            failed = True
    return 1 if failed else 0


if __name__ == "__main__":
    if len(sys.argv) < 2:
        print(__doc__.strip(), file=sys.stderr)
        sys.exit(2)
    sys.exit(main(sys.argv[1:]))
