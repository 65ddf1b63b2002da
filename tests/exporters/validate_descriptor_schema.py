#!/usr/bin/env python3
"""Checks formats/schema/descriptor.schema.json against real exports.

    validate_descriptor_schema.py SCHEMA FILE…   (FILE: *.hoses.json, *.glb, *.gltf)

Every sidecar descriptor and every embedded CHAINTUBE_hose_rig extension must validate, must
contain no null anywhere (tinygltf would write an empty list as null), and the extension must be
in extensionsUsed but not extensionsRequired. Then known-bad variants of the first descriptor
(an empty list turned into null, a missing unit, a negative rest length, an unknown member, a
newer major version) must be rejected, so the schema is shown to be able to fail.
"""
import copy
import json
import struct
import sys

import jsonschema


def load(path):
    with open(path, "rb") as stream:
        data = stream.read()
    if data[:4] == b"glTF":
        length = struct.unpack_from("<I", data, 12)[0]
        return json.loads(data[20:20 + length])
    return json.loads(data)


def nulls(value, pointer=""):
    if value is None:
        yield pointer or "/"
    elif isinstance(value, dict):
        for key, item in value.items():
            yield from nulls(item, f"{pointer}/{key}")
    elif isinstance(value, list):
        for index, item in enumerate(value):
            yield from nulls(item, f"{pointer}/{index}")


def main():
    schema = json.load(open(sys.argv[1]))
    jsonschema.Draft202012Validator.check_schema(schema)
    validator = jsonschema.Draft202012Validator(schema)
    failures = []
    descriptors = []
    for path in sys.argv[2:]:
        document = load(path)
        if path.endswith(".json"):
            descriptor = document
        else:
            if "CHAINTUBE_hose_rig" not in document.get("extensionsUsed", []):
                failures.append(f"{path}: CHAINTUBE_hose_rig missing from extensionsUsed")
            if "CHAINTUBE_hose_rig" in document.get("extensionsRequired", []):
                failures.append(f"{path}: CHAINTUBE_hose_rig must not be in extensionsRequired")
            descriptor = document.get("extensions", {}).get("CHAINTUBE_hose_rig")
            if descriptor is None:
                failures.append(f"{path}: no embedded CHAINTUBE_hose_rig")
                continue
        for error in validator.iter_errors(descriptor):
            failures.append(f"{path}: /{'/'.join(map(str, error.absolute_path))}: {error.message}")
        for pointer in nulls(descriptor):
            failures.append(f"{path}: {pointer}: null (an empty list written as null?)")
        descriptors.append(descriptor)
        print(f"checked {path}: {len(descriptor['hoses'])} hoses")
    if not descriptors:
        failures.append("no descriptors given")
    else:
        base = descriptors[0]
        bad = []
        variant = copy.deepcopy(base)
        variant["hoses"][0]["attachments"] = None
        bad.append(("attachments null", variant))
        variant = copy.deepcopy(base)
        del variant["units"]
        bad.append(("units missing", variant))
        variant = copy.deepcopy(base)
        variant["hoses"][0]["restLengths"][0] = -0.01
        bad.append(("negative rest length", variant))
        variant = copy.deepcopy(base)
        variant["hoses"][0]["colour"] = [1, 0, 0, 1]
        bad.append(("unknown member", variant))
        variant = copy.deepcopy(base)
        variant["version"] = "2.0"
        bad.append(("newer major version", variant))
        for name, variant in bad:
            if validator.is_valid(variant):
                failures.append(f"the schema accepts a bad descriptor ({name})")
    for failure in failures:
        print("FAIL " + failure)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
