#!/usr/bin/env python3
"""Checks that includes run one way (docs/architecture.md, "Layers"): every `#include "dir/..."`
of a file under src/ must name its own folder or one that LAYERS allows it, and src/cli may
include nothing of src/ at all (it uses the public headers only). Prints each include that
breaks the rule, as file:line, and exits 1 when there is one.

Usage: scripts/check-layers.py [REPOSITORY]   (default: this script's repository)
"""
import os
import re
import sys

# Folder -> the src/ folders it may include besides its own. Keep in step with the picture in
# docs/architecture.md.
LAYERS = {
    "core": set(),
    "color": {"core"},
    "texture": {"color", "core"},
    "shading": {"texture", "color", "core"},
    "scene": {"color", "core"},
    "image": {"color", "core"},
    "geometry": {"shading", "core"},
    "binning": {"core"},
    "raster": {"shading", "color", "core"},
    "post": {"shading", "color", "core"},
    "pipeline": {"scene", "geometry", "binning", "raster", "post", "image", "core"},
    "cli": set(),
}

# Within src/raster, a mode's folder includes its own files and the factory's declaration;
# the reference mode also shares the sample modes' patterns.
RASTER_SHARED = {"raster/rasterizers.hpp", "raster/samples/sample_pattern.hpp"}

INCLUDE = re.compile(r'^\s*#\s*include\s+"(([a-z_]+)/[^"]*)"')


def breaks_raster_rule(path, included):
    """Whether an include of raster/... from a file of src/raster reaches into another mode."""
    parts = path.split(os.sep)
    mode = parts[parts.index("raster") + 1] if len(parts) > parts.index("raster") + 2 else None
    target = included.split("/")
    if mode is None or len(target) < 3 or target[1] == mode:
        return False
    return included not in RASTER_SHARED


def violations(root):
    """Yields (path, line number, included folder) for every include that breaks LAYERS."""
    src = os.path.join(root, "src")
    for folder in sorted(os.listdir(src)):
        if not os.path.isdir(os.path.join(src, folder)):
            continue
        if folder not in LAYERS:
            yield (os.path.join("src", folder), 0, "anything: a folder LAYERS does not know")
            continue
        allowed = LAYERS[folder] | {folder}
        for dirpath, _, files in os.walk(os.path.join(src, folder)):
            for name in sorted(files):
                path = os.path.join(dirpath, name)
                with open(path, encoding="utf-8") as f:
                    for number, line in enumerate(f, 1):
                        m = INCLUDE.match(line)
                        if not m:
                            continue
                        rel = os.path.relpath(path, root)
                        if m.group(2) not in allowed:
                            yield (rel, number, m.group(2) + "/")
                        elif folder == "raster" and breaks_raster_rule(rel, m.group(1)):
                            yield (rel, number, m.group(1))


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..")
    found = list(violations(os.path.abspath(root)))
    for path, number, included in found:
        print(f"{path}:{number}: includes {included}, which its layer may not "
              "(docs/architecture.md, Layers)")
    if found:
        return 1
    print("includes run one way: every src/ folder includes only the layers below it")
    return 0


if __name__ == "__main__":
    sys.exit(main())
