#!/usr/bin/env python3
"""Renders the shared glTF sample models lit, next to each publisher's screenshot, into
docs/gallery.md and docs/images/gallery/NAME.png (small PNGs).

Not part of the test suite: it needs ../shared/models/gltf (the Khronos sample models, see
../shared/models/README.md) and skips cleanly, with the reason, when a model is missing or
does not load. The screenshots are linked where they are, not copied: their licences vary
per model (each folder's LICENSE.md).

Each model is framed by its bounding box like benchmarks/report.py does (camera on +z looking
at the box centre, the bounding sphere filling the vertical field of view), with the file's
materials, lit as the glTF viewers light a model: by an environment (docs/environments.md),
tone-mapped with khronos-pbr-neutral. docs/gallery.md uses the built-in studio environment
(what `covrast render model.glb` uses); docs/gallery-environments.md renders each model once
per environment file of ../shared/environments (when present), beside the screenshot. Each
image's render time (the whole `covrast render` process, 2 threads) is in the table.

Usage: scripts/gallery.py [--covrast build/release/covrast] [--models ../shared/models/gltf]
                          [--environments ../shared/environments] [--size 256x192]
                          [--filter REGEX]
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

import time


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


def framed_scene(covrast, model_file, size, path, environment):
    """Writes the lit, framed scene of one model to path; returns its `info` JSON."""
    scene = {
        "width": size[0], "height": size[1], "background": [0.18, 0.18, 0.2],
        "camera": {"eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0], "fovy_deg": 40,
                   "near": 0.1, "far": 100},
        "environment": ({"builtin": "studio"} if environment is None
                        else {"file": os.path.abspath(environment)}),
        "tone_map": "khronos-pbr-neutral",
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


def render_model(covrast, name, model_file, size, tmp, images_dir, environment=None):
    """Renders one model; returns (image path, warnings text, seconds) or raises
    RuntimeError."""
    scene_path = os.path.join(tmp, name + ".json")
    described = framed_scene(covrast, model_file, size, scene_path, environment)
    out_png = os.path.join(images_dir, name + ".png")
    start = time.monotonic()
    run = subprocess.run([covrast, "render", scene_path, "-o", out_png, "--quiet", "--threads",
                          "2"], capture_output=True, text=True)
    seconds = time.monotonic() - start
    if run.returncode != 0:
        raise RuntimeError(run.stderr.strip().splitlines()[-1])
    # Warnings name the file by its full path: the model's folder says enough.
    folder = os.path.dirname(os.path.dirname(os.path.abspath(model_file))) + os.sep
    warnings = "; ".join(w.replace(folder, "") for w in described.get("warnings", []))
    return out_png, warnings, seconds


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--covrast", default=os.path.join(ROOT, "build/release/covrast"))
    parser.add_argument("--models", default=os.path.join(ROOT, "..", "shared", "models", "gltf"))
    parser.add_argument("--environments",
                        default=os.path.join(ROOT, "..", "shared", "environments"))
    parser.add_argument("--size", default="256x192")
    parser.add_argument("--filter", default="")
    opts = parser.parse_args()
    size = tuple(int(v) for v in opts.size.split("x"))
    if not os.path.isdir(opts.models):
        print(f"gallery: {opts.models} not found, nothing to do")
        return 0
    environments = []
    if os.path.isdir(opts.environments):
        environments = sorted(os.path.join(opts.environments, f)
                              for f in os.listdir(opts.environments)
                              if f.lower().endswith((".hdr", ".exr")))
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
                studio = render_model(opts.covrast, safe, model_file, size, tmp, images_dir)
                lit = []
                for env in environments:
                    env_name = os.path.splitext(os.path.basename(env))[0]
                    lit.append(render_model(opts.covrast, safe + "-" + env_name, model_file, size,
                                            tmp, images_dir, env))
            except RuntimeError as e:
                # Messages name files by their full path: the model's folder says enough.
                skipped.append((name, str(e).replace(os.path.abspath(folder) + os.sep, "")))
                continue
            shot = find_screenshot(folder)
            rows.append({"name": name, "studio": studio, "lit": lit,
                         "shot": os.path.relpath(shot, docs) if shot else None})
            print(f"gallery: {name} ({studio[2]:.2f} s)")
    write_studio_page(os.path.join(docs, "gallery.md"), docs, rows, skipped, size)
    if environments:
        write_environments_page(os.path.join(docs, "gallery-environments.md"), docs, rows,
                                environments, size)
    return 0


def image_cell(docs, name, rendered):
    image, _, seconds = rendered
    return f"![{name}]({os.path.relpath(image, docs)})<br>{seconds:.2f} s"


def write_studio_page(path, docs, rows, skipped, size):
    total = sum(row["studio"][2] for row in rows)
    lines = [
        "# Gallery: the glTF sample models, lit",
        "",
        "Written by `scripts/gallery.py` (not part of the test suite). Left: covrast, coverage "
        f"mode, {size[0]}x{size[1]}, the file's materials, textures (docs/textures.md) and "
        "alpha modes (docs/transparency.md), lit by the built-in studio environment "
        "(docs/environments.md) and tone-mapped with khronos-pbr-neutral, with the time of the "
        f"whole `covrast render` process on 2 threads ({total:.1f} s for the {len(rows)} "
        "models). Right: the publisher's screenshot, linked from `../shared/models/gltf` "
        "(not copied; licences vary per model). Framing and environments differ from the "
        "publishers' viewers, so compare shapes and shading, not exact colours. "
        "[gallery-environments.md](gallery-environments.md) renders the shared HDR "
        "environments.",
        "",
        "| model | covrast | publisher | warnings |",
        "|---|---|---|---|",
    ]
    for row in rows:
        shot_cell = f"![{row['name']} screenshot]({row['shot']})" if row["shot"] else "(none)"
        lines.append(f"| {row['name']} | {image_cell(docs, row['name'], row['studio'])} | "
                     f"{shot_cell} | {row['studio'][1]} |")
    if skipped:
        lines += ["", "Skipped:", ""]
        lines += [f"- {name}: {reason}" for name, reason in skipped]
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def write_environments_page(path, docs, rows, environments, size):
    names = [os.path.basename(e) for e in environments]
    lines = [
        "# Gallery: the glTF sample models in the shared environments",
        "",
        "Written by `scripts/gallery.py` (not part of the test suite): each model lit by each "
        "equirectangular environment of `../shared/environments` (CC0 HDRs, not copied), "
        f"coverage mode, {size[0]}x{size[1]}, khronos-pbr-neutral, with the time of the whole "
        "`covrast render` process (2 threads, the environment file read and prepared each "
        "time), beside the publisher's screenshot.",
        "",
        "| model | " + " | ".join(names) + " | publisher |",
        "|---|" + "---|" * len(names) + "---|",
    ]
    for row in rows:
        shot_cell = f"![{row['name']} screenshot]({row['shot']})" if row["shot"] else "(none)"
        cells = " | ".join(image_cell(docs, row["name"], lit) for lit in row["lit"])
        lines.append(f"| {row['name']} | {cells} | {shot_cell} |")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    sys.exit(main())
