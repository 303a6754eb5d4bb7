#!/usr/bin/env python3
"""Renders the shared glTF sample models lit, next to each publisher's screenshot, into
docs/gallery.md and docs/images/gallery/NAME.png (small PNGs).

Not part of the test suite: it needs ../shared/models/gltf (the Khronos sample models, see
../shared/models/README.md) and skips cleanly, with the reason, when a model is missing or
does not load. The screenshots are linked where they are, not copied: their licences vary
per model (each folder's LICENSE.md).

Each model is framed by its bounding box like benchmarks/report.py does (camera on +z looking
at the box centre, the bounding sphere filling the vertical field of view) and lit by the
rig below (KHR_lights_punctual units; the file's materials, pbr unless KHR_materials_unlit):

    key   directional, travelling (0.5, -0.7, -0.6), white, intensity 3
    fill  directional, travelling (-0.6, -0.2, -0.5), (0.8, 0.85, 1), intensity 1
    ambient (1, 1, 1), intensity 0.25

Usage: scripts/gallery.py [--covrast build/release/covrast] [--models ../shared/models/gltf]
                          [--size 256x192] [--filter REGEX]
"""

import argparse
import json
import math
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

LIGHT_RIG = [
    {"type": "directional", "direction": [0.5, -0.7, -0.6], "color": [1, 1, 1], "intensity": 3.0},
    {"type": "directional", "direction": [-0.6, -0.2, -0.5], "color": [0.8, 0.85, 1.0],
     "intensity": 1.0},
    {"type": "ambient", "color": [1, 1, 1], "intensity": 0.25},
]


def find_model_file(folder):
    """The model's .gltf or .glb: from glTF/, else glTF-Binary/, else any other variant folder;
    None if there is none."""
    variants = ["glTF", "glTF-Binary"] + sorted(
        v for v in os.listdir(folder) if v.startswith("glTF-") and v != "glTF-Binary")
    for variant in variants:
        directory = os.path.join(folder, variant)
        if not os.path.isdir(directory):
            continue
        for name in sorted(os.listdir(directory)):
            if name.endswith((".gltf", ".glb")):
                return os.path.join(directory, name)
    return None


def find_screenshot(folder):
    """The publisher's small screenshot (screenshot-x150.*, else screenshot.*), or None."""
    directory = os.path.join(folder, "screenshot")
    if not os.path.isdir(directory):
        return None
    names = sorted(os.listdir(directory))
    for prefix in ("screenshot-x150.", "screenshot."):
        for name in names:
            if name.startswith(prefix):
                return os.path.join(directory, name)
    return None


def info(covrast, scene_path):
    out = subprocess.run([covrast, "info", "--json", scene_path], capture_output=True, text=True)
    if out.returncode != 0:
        raise RuntimeError(out.stderr.strip().splitlines()[-1] if out.stderr else "info failed")
    return json.loads(out.stdout)


def framed_scene(covrast, model_file, size, path):
    """Writes the lit, framed scene of one model to path; returns its `info` JSON."""
    scene = {
        "width": size[0], "height": size[1], "background": [0.18, 0.18, 0.2],
        "camera": {"eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0], "fovy_deg": 40,
                   "near": 0.1, "far": 100},
        "lights": LIGHT_RIG,
        "meshes": [{"gltf": os.path.abspath(model_file)}],
    }
    with open(path, "w") as f:
        json.dump(scene, f)
    described = info(covrast, path)
    if not described.get("triangles") or not described.get("bounds"):
        raise RuntimeError("no triangles")
    lo, hi = described["bounds"]["min"], described["bounds"]["max"]
    centre = [(a + b) / 2 for a, b in zip(lo, hi)]
    radius = max(0.5 * math.dist(lo, hi), 1e-6)
    distance = 1.05 * radius / math.sin(math.radians(40) / 2)
    scene["camera"] = {"eye": [centre[0], centre[1], centre[2] + distance], "target": centre,
                       "up": [0, 1, 0], "fovy_deg": 40,
                       "near": max(distance - 1.5 * radius, 1e-3 * distance),
                       "far": distance + 1.5 * radius}
    with open(path, "w") as f:
        json.dump(scene, f)
    return described


def render_model(covrast, name, model_file, size, tmp, images_dir):
    """Renders one model; returns (image path, warnings text) or raises RuntimeError."""
    scene_path = os.path.join(tmp, name + ".json")
    described = framed_scene(covrast, model_file, size, scene_path)
    out_png = os.path.join(images_dir, name + ".png")
    run = subprocess.run([covrast, "render", scene_path, "-o", out_png, "--quiet"],
                         capture_output=True, text=True)
    if run.returncode != 0:
        raise RuntimeError(run.stderr.strip().splitlines()[-1])
    # Warnings name the file by its full path: the model's folder says enough.
    folder = os.path.dirname(os.path.dirname(os.path.abspath(model_file))) + os.sep
    return out_png, "; ".join(w.replace(folder, "") for w in described.get("warnings", []))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--covrast", default=os.path.join(ROOT, "build/release/covrast"))
    parser.add_argument("--models", default=os.path.join(ROOT, "..", "shared", "models", "gltf"))
    parser.add_argument("--size", default="256x192")
    parser.add_argument("--filter", default="")
    opts = parser.parse_args()
    size = tuple(int(v) for v in opts.size.split("x"))
    if not os.path.isdir(opts.models):
        print(f"gallery: {opts.models} not found, nothing to do")
        return 0
    docs = os.path.join(ROOT, "docs")
    images_dir = os.path.join(docs, "images", "gallery")
    os.makedirs(images_dir, exist_ok=True)
    rows, skipped = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for name in sorted(os.listdir(opts.models)):
            folder = os.path.join(opts.models, name)
            if not os.path.isdir(folder) or not re.search(opts.filter, name):
                continue
            safe = re.sub(r"[^A-Za-z0-9_-]", "_", name)
            model_file = find_model_file(folder)
            if model_file is None:
                skipped.append((name, "no glTF/ or glTF-Binary/ variant"))
                continue
            try:
                image, warnings = render_model(opts.covrast, safe, model_file, size, tmp,
                                               images_dir)
            except RuntimeError as e:
                # Messages name files by their full path: the model's folder says enough.
                skipped.append((name, str(e).replace(os.path.abspath(folder) + os.sep, "")))
                continue
            shot = find_screenshot(folder)
            rows.append((name, os.path.relpath(image, docs),
                         os.path.relpath(shot, docs) if shot else None, warnings))
            print(f"gallery: {name}")
    write_markdown(os.path.join(docs, "gallery.md"), rows, skipped, size)
    return 0


def write_markdown(path, rows, skipped, size):
    lines = [
        "# Gallery: the glTF sample models, lit",
        "",
        "Written by `scripts/gallery.py` (not part of the test suite). Left: covrast, coverage "
        f"mode, {size[0]}x{size[1]}, the file's materials, textures (docs/textures.md) and "
        "alpha modes (docs/transparency.md) under the script's light rig. Right: the publisher's screenshot, linked from `../shared/models/gltf` "
        "(not copied; licences vary per model). Framing, lights and materials differ from the "
        "publishers' viewers, so compare shapes and shading, not exact colours.",
        "",
        "| model | covrast | publisher | warnings |",
        "|---|---|---|---|",
    ]
    for name, image, shot, warnings in rows:
        shot_cell = f"![{name} screenshot]({shot})" if shot else "(none)"
        lines.append(f"| {name} | ![{name}]({image}) | {shot_cell} | {warnings} |")
    if skipped:
        lines += ["", "Skipped:", ""]
        lines += [f"- {name}: {reason}" for name, reason in skipped]
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    sys.exit(main())
