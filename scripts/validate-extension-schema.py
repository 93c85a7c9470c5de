#!/usr/bin/env python3
"""Validates the ANIMORDER_animated_triangle_orders objects of glTF JSON files against the
schemas of docs/extension/schema (Debian's python3-jsonschema). Usage:
    validate-extension-schema.py FILE.gltf...
Exit 0 when every file has the root object and every extension object conforms, else 1 with one
line per problem."""
import json
import pathlib
import sys
import warnings

import jsonschema

NAME = "ANIMORDER_animated_triangle_orders"
SCHEMAS = pathlib.Path(__file__).resolve().parent.parent / "docs" / "extension" / "schema"


def validator(file_name, store):
    schema = store[file_name]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        resolver = jsonschema.RefResolver(base_uri="", referrer=schema, store=store)
        return jsonschema.Draft202012Validator(schema, resolver=resolver)


def main(paths):
    store = {}
    for p in SCHEMAS.glob("*.json"):
        s = json.loads(p.read_text())
        store[s["$id"]] = s
    root = validator("glTF." + NAME + ".schema.json", store)
    prim = validator("mesh.primitive." + NAME + ".schema.json", store)
    problems = []
    for path in paths:
        gltf = json.loads(pathlib.Path(path).read_text())
        if NAME not in gltf.get("extensionsUsed", []):
            problems.append(f"{path}: {NAME} is not in extensionsUsed")
        if NAME in gltf.get("extensionsRequired", []):
            problems.append(f"{path}: {NAME} must not be in extensionsRequired")
        ext = gltf.get("extensions", {}).get(NAME)
        if ext is None:
            problems.append(f"{path}: no root {NAME} object")
        else:
            problems += [f"{path}: root: {e.message}" for e in root.iter_errors(ext)]
        found = 0
        for m, mesh in enumerate(gltf.get("meshes", [])):
            for p, primitive in enumerate(mesh.get("primitives", [])):
                obj = primitive.get("extensions", {}).get(NAME)
                if obj is not None:
                    found += 1
                    problems += [f"{path}: meshes[{m}].primitives[{p}]: {e.message}" for e in prim.iter_errors(obj)]
        if found == 0:
            problems.append(f"{path}: no primitive carries {NAME}")
    for p in problems:
        print(p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
