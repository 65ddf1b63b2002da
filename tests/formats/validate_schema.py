#!/usr/bin/env python3
"""Checks formats/schema/project.schema.json: every sample validates, every bad project fails.

usage: validate_schema.py <schema> <samples folder> <bad projects folder>
Each bad project is a small patch on samples/single-hose.ctproj: {"pointer": "/hoses/0/...",
"value": ...} (or "remove": true) described in bad_projects/*.json.
"""
import copy
import json
import sys
from pathlib import Path

import jsonschema


def set_pointer(document, pointer, value, remove):
    parts = [p.replace("~1", "/").replace("~0", "~") for p in pointer.split("/")[1:]]
    target = document
    for part in parts[:-1]:
        target = target[int(part)] if isinstance(target, list) else target[part]
    last = parts[-1]
    if isinstance(target, list):
        last = int(last)
    if remove:
        del target[last]
    else:
        target[last] = value


def main():
    schema_file, samples, bad = (Path(a) for a in sys.argv[1:4])
    schema = json.loads(schema_file.read_text())
    jsonschema.Draft202012Validator.check_schema(schema)
    validator = jsonschema.Draft202012Validator(schema)
    failures = 0
    sample_files = sorted(samples.glob("*.ctproj"))
    if not sample_files:
        print(f"no samples in {samples}")
        return 1
    for sample in sample_files:
        errors = list(validator.iter_errors(json.loads(sample.read_text())))
        for error in errors:
            print(f"FAIL {sample.name}: /{'/'.join(map(str, error.absolute_path))}: {error.message}")
        failures += bool(errors)
        if not errors:
            print(f"ok   {sample.name} is valid")
    base = json.loads((samples / "single-hose.ctproj").read_text())
    for case in sorted(bad.glob("*.json")):
        patch = json.loads(case.read_text())
        document = copy.deepcopy(base)
        set_pointer(document, patch["pointer"], patch.get("value"), patch.get("remove", False))
        if validator.is_valid(document):
            print(f"FAIL {case.name}: accepted, but {patch['why']}")
            failures += 1
        else:
            print(f"ok   {case.name} rejected ({patch['why']})")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
