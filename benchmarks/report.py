#!/usr/bin/env python3
"""Quality-versus-cost report for covrast (issues 5 and 10): writes docs/benchmarks.md.

Renders every benchmark scene in every anti-aliasing mode with the covrast command line, and
for each mode records
  - the median `render_ms` of `covrast render SCENE --stats --repeat K` at the scene's own size,
  - the error against the `reference` mode (64 x 64 samples per pixel, double precision) from
    `covrast compare --json`: RMSE in linear light and the largest channel error in 8-bit sRGB.
The reference is slow (seconds per 640x360 frame), so the error figures are measured at a
smaller size (`--error-size`, default 640x360: every mode is rendered a second time at the
scene's size scaled down to fit that box). The report holds a table per scene, an
error-versus-time log-log plot per scene (matplotlib, when available), enlarged crops of one
edge region, a section on the post-process `fxaa` (the aliased frame filtered by FXAA 3.11)
against aliased and coverage, and headline checks computed from the numbers: per scene,
whether coverage is (a) no slower than msaa:4 and (b) within 0.7x ssaa:16's RMSE and no
worse than its largest error.

Three sets of scenes:
  - the bundled benchmark scenes (scenes/overlap.json, sphere_grid.json, slivers.json);
  - generated real-content scenes: `covrast-scenegen --real DIR` (next to the covrast binary,
    or `--scenegen`) writes DIR/<name>.json; every JSON it writes is a scene. A generator
    without that option is detected (non-zero exit or no files) and the set is skipped;
  - sample models from ../shared/models (`--models`): every OBJ there and the glTF models in
    gltf/<Name>/, each framed by its bounding box with per-triangle colours. By default the
    OBJ models and DEFAULT_GLTF_MODELS below; `--models-filter REGEX` picks models by name
    from all of them, `--all-models` takes every one. A model that fails to load or has no
    triangles is skipped with its reason; a missing folder leaves the set out.
The generated scenes and the models are rendered at `--model-size` (default 640x360), where
the reference takes seconds rather than minutes.

Python standard library only, plus Debian's python3-matplotlib for the plots: the full report
installs it with apt-get when it is missing; `--quick` never installs anything and skips the
plots when matplotlib cannot be imported. Crops are cut and enlarged here (PNG read and written
with zlib), so ImageMagick is not needed.

  benchmarks/report.py                          # full report into docs/ (about 10 minutes)
  benchmarks/report.py --out /tmp/r --models-filter 'Duck|teapot' --no-real
  benchmarks/report.py --quick --out /tmp/r     # 96x54, 1 frame, two scenes: a few seconds

Exit status: 0 when every scene has a row for every mode and every render and comparison
succeeded; 1 otherwise (the report is still written, with the failures in it); 2 on bad usage.
Skipped models and a generator without `--real` are not failures.
"""

import argparse
import datetime
import json
import math
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import time
import zlib

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

MODES = [
    "aliased",
    "fxaa",
    "coverage",
    "coverage-blend",
    "msaa:4",
    "msaa:8",
    "msaa:16",
    "ssaa:2",
    "ssaa:4",
    "ssaa:8",
    "ssaa:16",
    "ssaa-cmj:4",
    "ssaa-cmj:16",
    "reference",
]
CROP_MODES = ["aliased", "fxaa", "coverage", "coverage-blend", "msaa:4", "ssaa:4", "ssaa:16",
              "reference"]
SSAA_SERIES = ["ssaa:2", "ssaa:4", "ssaa:8", "ssaa:16"]
MSAA_SERIES = ["msaa:4", "msaa:8", "msaa:16"]
REFERENCE_SAMPLES = 64 * 64

# (name, path relative to the repository, what the scene stresses)
SCENES = [
    ("overlap", "scenes/overlap.json", "fill-bound: large interpenetrating triangles"),
    ("sphere_grid", "scenes/sphere_grid.json", "setup-bound: 100 spheres of 5,000 triangles"),
    ("slivers", "scenes/slivers.json", "thin triangles, near-horizontal and near-vertical edges"),
]
QUICK_SCENES = ["overlap", "slivers"]

# The glTF sample models of the default run (with every OBJ model): the ones with the most
# triangles, ReciprocatingSaw (198k, dense CAD) down to Fox (576), plus BoxTextured as the
# trivial case. Left out by default, to keep the full report near 10 minutes:
# MetalRoughSpheresNoTextures (1.04M triangles, its reference frame alone takes about 40 s at
# 640x360) and the small feature tests (up to 524 triangles). `--all-models` or
# `--models-filter` add them.
DEFAULT_GLTF_MODELS = [
    "ReciprocatingSaw",
    "ClearCoatTest",
    "DamagedHelmet",
    "NegativeScaleTest",
    "Lantern",
    "CesiumMan",
    "Duck",
    "Avocado",
    "Fox",
    "BoxTextured",
]
# Which file of a glTF model folder is used: the first of these sub-folders that holds a file
# with that extension. glTF-Binary and plain glTF first; the embedded and quantized variants
# only for models published without those (Lantern, MeshPrimitiveModes, MultipleScenes,
# AnimatedMorphCube). Draco-compressed files are never used: covrast cannot decode them.
GLTF_VARIANTS = [
    ("glTF-Binary", ".glb"),
    ("glTF", ".gltf"),
    ("glTF-Embedded", ".gltf"),
    ("glTF-Quantized", ".gltf"),
]
MODEL_SIZE = (640, 360)

# Headline checks: coverage must cost at most TIME_FACTOR x TIME_RIVAL's time and at most
# FINE_TIME_FACTOR x FINE_TIME_RIVAL's (a fraction of 256-sample supersampling's cost), and
# against the reference have an RMSE of at most RMSE_FACTOR x the best QUALITY_RIVALS' and a
# largest error no worse than the best of theirs (each measure taken from whichever
# 256-sample pattern does better).
TIME_RIVAL = "msaa:4"
TIME_FACTOR = 2.0
FINE_TIME_RIVAL = "ssaa:16"
FINE_TIME_FACTOR = 0.5
QUALITY_RIVALS = ["ssaa:16", "ssaa-cmj:16"]
QUALITY_RIVAL = "best ssaa:16/ssaa-cmj:16"
RMSE_FACTOR = 0.7


class Failure(Exception):
    """A covrast run that failed; the message is one line for the report."""


def log(text):
    print(text, flush=True)


# ---------------------------------------------------------------------------------------------
# Running covrast


def run_covrast(covrast, args):
    """Runs covrast and returns its stdout; raises Failure with the first stderr line."""
    proc = subprocess.run([covrast] + args, capture_output=True, text=True)
    if proc.returncode != 0:
        lines = [l for l in proc.stderr.splitlines() if l.strip()] or ["(no message)"]
        raise Failure(f"exit {proc.returncode}: {lines[0]}")
    return proc.stdout


def last_json_line(text):
    for line in reversed(text.splitlines()):
        if line.startswith("{"):
            return json.loads(line)
    raise Failure("no JSON line in the output")


def scene_info(covrast, scene_path):
    return last_json_line(run_covrast(covrast, ["info", scene_path, "--json"]))


def render(covrast, scene_path, out_png, mode, size, repeat, threads):
    """One `covrast render --stats`; returns the parsed statistics line."""
    args = ["render", scene_path, "-o", out_png, "--mode", mode, "--quiet", "--stats"]
    args += ["--repeat", str(repeat), "--threads", str(threads), "--size", f"{size[0]}x{size[1]}"]
    return last_json_line(run_covrast(covrast, args))


def compare(covrast, a_png, b_png):
    return last_json_line(run_covrast(covrast, ["compare", a_png, b_png, "--json"]))


# ---------------------------------------------------------------------------------------------
# PNG (8-bit RGB/RGBA, not interlaced) read and write, for the crops


def read_png_rgb(path):
    """Returns (width, height, rows) with rows a list of bytearrays of RGB triples."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise Failure(f"{path}: not a PNG")
    pos, idat, header = 8, [], None
    while pos + 8 <= len(data):
        (length,) = struct.unpack(">I", data[pos : pos + 4])
        kind = data[pos + 4 : pos + 8]
        body = data[pos + 8 : pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"IEND":
            break
        pos += 12 + length
    if header is None:
        raise Failure(f"{path}: no IHDR chunk")
    width, height, depth, color_type, _, _, interlace = header
    channels = {2: 3, 6: 4}.get(color_type)
    if depth != 8 or channels is None or interlace != 0:
        raise Failure(f"{path}: only 8-bit RGB/RGBA non-interlaced PNGs are read here")
    raw = zlib.decompress(b"".join(idat))
    stride = width * channels
    prior = bytearray(stride)
    rows = []
    for y in range(height):
        at = y * (stride + 1)
        kind, row = raw[at], bytearray(raw[at + 1 : at + 1 + stride])
        step = channels
        if kind == 1:
            for i in range(step, stride):
                row[i] = (row[i] + row[i - step]) & 255
        elif kind == 2:
            row = bytearray((a + b) & 255 for a, b in zip(row, prior))
        elif kind == 3:
            for i in range(stride):
                left = row[i - step] if i >= step else 0
                row[i] = (row[i] + ((left + prior[i]) >> 1)) & 255
        elif kind == 4:
            for i in range(stride):
                a = row[i - step] if i >= step else 0
                c = prior[i - step] if i >= step else 0
                b = prior[i]
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                row[i] = (row[i] + pred) & 255
        prior = row
        if channels == 4:
            rgb = bytearray(width * 3)
            rgb[0::3], rgb[1::3], rgb[2::3] = row[0::4], row[1::4], row[2::4]
            row = rgb
        rows.append(bytes(row))
    return width, height, rows


def write_png_rgb(path, width, height, rows):
    def chunk(kind, body):
        crc = struct.pack(">I", zlib.crc32(kind + body))
        return struct.pack(">I", len(body)) + kind + body + crc

    raw = b"".join(b"\x00" + bytes(r) for r in rows)
    png = b"\x89PNG\r\n\x1a\n"
    png += chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 9))
    png += chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(png)


def crop_enlarge(rows, x0, y0, w, h, scale):
    """Nearest-neighbour enlargement of the w x h region at (x0, y0) by an integer factor."""
    out = []
    for y in range(y0, y0 + h):
        src = rows[y][3 * x0 : 3 * (x0 + w)]
        line = b"".join(src[3 * i : 3 * i + 3] * scale for i in range(w))
        out.extend([line] * scale)
    return out


def edge_window(aliased_rows, reference_rows, width, height, win_w, win_h):
    """The win_w x win_h window with the largest summed |aliased - reference| (all channels):
    where the edges are. Summed-area table; the first maximum in row-major order wins."""
    sat = [[0] * (width + 1) for _ in range(height + 1)]
    for y in range(height):
        a, r = aliased_rows[y], reference_rows[y]
        run = 0
        above, here = sat[y], sat[y + 1]
        for x in range(width):
            i = 3 * x
            run += abs(a[i] - r[i]) + abs(a[i + 1] - r[i + 1]) + abs(a[i + 2] - r[i + 2])
            here[x + 1] = above[x + 1] + run
    best, best_xy = -1, (0, 0)
    for y in range(height - win_h + 1):
        top, bottom = sat[y], sat[y + win_h]
        for x in range(width - win_w + 1):
            s = bottom[x + win_w] - bottom[x] - top[x + win_w] + top[x]
            if s > best:
                best, best_xy = s, (x, y)
    return best_xy


# ---------------------------------------------------------------------------------------------
# Plots (matplotlib, possibly in another interpreter: Debian's module lives in /usr/bin/python3)


def interpreter_with_matplotlib():
    for interp in dict.fromkeys([sys.executable, "/usr/bin/python3"]):
        if interp and os.path.exists(interp):
            probe = subprocess.run([interp, "-c", "import matplotlib"], capture_output=True)
            if probe.returncode == 0:
                return interp
    return None


def install_matplotlib():
    """apt-get install python3-matplotlib (as root, or through sudo). Returns a message."""
    if os.geteuid() == 0:
        prefix = []
    elif shutil.which("sudo"):
        prefix = ["sudo"]
    else:
        return "not root and no sudo, so python3-matplotlib was not installed"
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    cmd = prefix + ["apt-get", "install", "-y", "--no-install-recommends", "python3-matplotlib"]
    log("installing python3-matplotlib: " + " ".join(cmd))
    proc = subprocess.run(cmd, env=env, capture_output=True, text=True)
    if proc.returncode != 0:
        log("apt-get install failed, trying apt-get update first")
        subprocess.run(prefix + ["apt-get", "update"], env=env, capture_output=True)
        proc = subprocess.run(cmd, env=env, capture_output=True, text=True)
    if proc.returncode != 0:
        tail = (proc.stderr.strip().splitlines() or ["?"])[-1]
        return f"apt-get install python3-matplotlib failed: {tail}"
    return ""


def draw_plot(spec_path):
    """Run by the interpreter that has matplotlib: one log-log error-versus-time plot."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    with open(spec_path) as f:
        spec = json.load(f)
    points = {p["mode"]: p for p in spec["points"]}
    fig, ax = plt.subplots(figsize=(7.5, 5), dpi=100)
    for series, style in ((SSAA_SERIES, "C0-"), (MSAA_SERIES, "C2-")):
        xs = [points[m]["ms"] for m in series if m in points]
        ys = [points[m]["rmse"] for m in series if m in points]
        if len(xs) > 1:
            ax.plot(xs, ys, style, linewidth=1, alpha=0.5)
    for mode, p in points.items():
        family = mode.split(":")[0]
        marker, color, size = {
            "coverage": ("*", "C3", 160),
            "coverage-blend": ("*", "C1", 100),
            "aliased": ("s", "k", 40),
            "fxaa": ("P", "C6", 60),
            "msaa": ("^", "C2", 40),
            "ssaa": ("o", "C0", 40),
            "ssaa-grid": ("D", "C4", 40),
            "ssaa-cmj": ("D", "C5", 40),
        }.get(family, ("o", "C7", 40))
        ax.scatter([p["ms"]], [p["rmse"]], marker=marker, color=color, s=size, zorder=3)
        ax.annotate(mode, (p["ms"], p["rmse"]), textcoords="offset points", xytext=(6, 4),
                    fontsize=8)
    ax.set_xscale("log")
    ax.set_yscale("log")
    plain = matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}")
    ax.xaxis.set_major_formatter(plain)
    ax.xaxis.set_minor_formatter(plain)
    ax.tick_params(axis="x", which="minor", labelsize=7)
    ax.set_xlabel(f"render_ms at {spec['time_size']} (median of {spec['repeat']})")
    ax.set_ylabel(f"RMSE vs reference, linear light, at {spec['error_size']}")
    ax.set_title(spec["title"])
    ax.grid(True, which="both", linewidth=0.3, alpha=0.5)
    fig.tight_layout()
    fig.savefig(spec["out"])
    plt.close(fig)


# ---------------------------------------------------------------------------------------------
# Measuring


def parse_size(text):
    m = re.fullmatch(r"(\d+)[xX](\d+)", text)
    if not m or int(m.group(1)) < 1 or int(m.group(2)) < 1:
        raise argparse.ArgumentTypeError(f"expected WxH, got '{text}'")
    return int(m.group(1)), int(m.group(2))


def fit_size(size, box):
    """size scaled down (never up), keeping its aspect ratio, to fit inside box."""
    scale = min(1.0, box[0] / size[0], box[1] / size[1])
    return max(1, round(size[0] * scale)), max(1, round(size[1] * scale))


def samples_text(mode):
    kind, _, n = mode.partition(":")
    if kind in ("ssaa", "ssaa-grid", "ssaa-cmj"):
        return f"{int(n) ** 2} ({n}x{n})"
    if kind == "msaa":
        return f"{n} (shaded once)"
    if kind == "aliased":
        return "1"
    if kind == "fxaa":
        return "1 + FXAA post-process"
    if kind == "reference":
        return f"{REFERENCE_SAMPLES} (64x64)"
    return "exact area"


def safe_name(text):
    """text with every run of characters other than letters, digits, '_', '.' and '-' replaced
    by '_': usable in file names and benchmark names ('Box With Spaces' -> 'Box_With_Spaces')."""
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text)


def gltf_file(folder):
    """The glTF file used for one model folder (see GLTF_VARIANTS), or None."""
    for variant, ext in GLTF_VARIANTS:
        sub = os.path.join(folder, variant)
        if os.path.isdir(sub):
            files = sorted(f for f in os.listdir(sub) if f.lower().endswith(ext))
            if files:
                return os.path.join(sub, files[0])
    return None


def find_models(models_dir):
    """Every sample model under models_dir. Returns (models, skipped): models a list of dicts
    {name, file, key} (key is the scene's mesh key, "obj" or "gltf"), OBJ files of models_dir
    first, then the folders of models_dir/gltf, each sorted by name; skipped a list of
    (name, reason) for the glTF folders without a usable file."""
    models, skipped = [], []
    for entry in sorted(os.listdir(models_dir)):
        if entry.lower().endswith(".obj"):
            models.append({"name": safe_name(entry[: -len(".obj")]),
                           "file": os.path.abspath(os.path.join(models_dir, entry)),
                           "key": "obj"})
    gltf_dir = os.path.join(models_dir, "gltf")
    if os.path.isdir(gltf_dir):
        for entry in sorted(os.listdir(gltf_dir)):
            folder = os.path.join(gltf_dir, entry)
            if not os.path.isdir(folder):
                continue
            path = gltf_file(folder)
            if path is None:
                variants = ", ".join(f"{v}/*{e}" for v, e in GLTF_VARIANTS)
                skipped.append((safe_name(entry), f"no {variants} file"))
                continue
            name = safe_name(entry)
            if any(m["name"] == name for m in models):
                name += "_gltf"  # an OBJ model of the same name came first
            models.append({"name": name, "file": os.path.abspath(path), "key": "gltf"})
    return models, skipped


def select_models(models, opts):
    """The models to measure: those whose name matches --models-filter (searched, case
    sensitive) when it is given, all with --all-models, else every OBJ model and the glTF
    models of DEFAULT_GLTF_MODELS."""
    if opts.models_filter:
        pattern = re.compile(opts.models_filter)
        return [m for m in models if pattern.search(m["name"])]
    if opts.all_models:
        return list(models)
    default = {safe_name(n) for n in DEFAULT_GLTF_MODELS}
    return [m for m in models if m["key"] == "obj" or m["name"] in default]


def write_json(path, data):
    """Writes data as JSON to path."""
    with open(path, "w") as f:
        json.dump(data, f)


def framed_model_scene(covrast, model, size, tmp):
    """Writes a scene JSON showing one model with per-triangle colours at size, and returns its
    path. Camera on +z looking at the centre of the bounding box (from `covrast info --json`),
    far enough for the bounding sphere (radius r, half the box diagonal) to fit the vertical
    field of view: distance = 1.05 r / sin(fovy/2). Same framing as benchmarks/bench_frame.cpp.
    Raises Failure (the reason to skip the model) when it does not load or has no triangles."""
    path = os.path.join(tmp, f"model-{model['name']}.json")
    scene = {
        "width": size[0],
        "height": size[1],
        "background": [0.02, 0.02, 0.02],
        "camera": {"eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0], "fovy_deg": 40,
                   "near": 0.1, "far": 100},
        "meshes": [{model["key"]: model["file"], "color": "per_triangle"}],
    }
    write_json(path, scene)
    info = scene_info(covrast, path)
    if not info.get("triangles") or not info.get("bounds"):
        raise Failure("no triangles")
    lo, hi = info["bounds"]["min"], info["bounds"]["max"]
    centre = [(a + b) / 2 for a, b in zip(lo, hi)]
    radius = max(0.5 * math.dist(lo, hi), 1e-6)
    distance = 1.05 * radius / math.sin(math.radians(40) / 2)
    scene["camera"] = {
        "eye": [centre[0], centre[1], centre[2] + distance],
        "target": centre,
        "up": [0, 1, 0],
        "fovy_deg": 40,
        "near": max(distance - 1.5 * radius, 1e-3 * distance),
        "far": distance + 1.5 * radius,
    }
    write_json(path, scene)
    return path


def model_scenes(opts, tmp, notes):
    """The framed scenes of the selected sample models (see find_models, select_models), as
    scene dicts; appends to notes (shown with the headline) what was measured, what was left
    out and why."""
    # Shown relative to the repository (e.g. ../shared/models), never as this machine's path.
    models_dir = os.path.relpath(opts.models, REPO)
    if not os.path.isdir(opts.models):
        notes.append(f"Sample models: not found (`{models_dir}` does not exist), so the model "
                     "scenes are left out.")
        log(f"models: {models_dir} not found, skipped")
        return []
    models, skipped = find_models(opts.models)
    if not models:
        notes.append(f"Sample models: none found in `{models_dir}`, so the model scenes are "
                     "left out.")
        log(f"models: none in {models_dir}, skipped")
        return []
    chosen = select_models(models, opts)
    left_out = [m["name"] for m in models if m not in chosen]
    scenes = []
    for model in chosen:
        try:
            path = framed_model_scene(opts.covrast, model, opts.model_size, tmp)
        except Failure as e:
            skipped.append((model["name"], str(e)))
            continue
        shown = os.path.relpath(model["file"], opts.models)
        scenes.append({"name": f"model-{model['name']}", "path": path, "size": None,
                       "what": f"Sample model `{shown}` (in `{models_dir}`), framed by its "
                               "bounding box, per-triangle colours"})
    how = (f"`--models-filter {opts.models_filter}`" if opts.models_filter else
           "`--all-models`" if opts.all_models else
           "the default selection: every OBJ model and the glTF models " +
           ", ".join(DEFAULT_GLTF_MODELS))
    size = opts.size or opts.model_size
    text = (f"Sample models from `{models_dir}`, framed by their bounding boxes with "
            f"per-triangle colours at {size[0]}x{size[1]}: "
            f"{len(scenes)} measured ({how}).")
    if left_out:
        text += f" Not selected: {', '.join(left_out)}."
    if skipped:
        text += " Skipped: " + "; ".join(f"{n} ({why})" for n, why in skipped) + "."
    notes.append(text)
    for name, why in skipped:
        log(f"model {name}: skipped ({why})")
    return scenes


def real_scenes(opts, tmp, notes):
    """The generated real-content scenes: runs `covrast-scenegen --real DIR` and returns a
    scene dict per JSON file it wrote into DIR. A generator that lacks the option (non-zero
    exit status, or no JSON written) gives no scenes and a note (shown with the headline)
    saying so."""
    scenegen = opts.scenegen
    if not os.access(scenegen, os.X_OK):
        notes.append(f"Generated real-content scenes: skipped, `{scenegen}` is not an executable.")
        log(f"real scenes: {scenegen} not found, skipped")
        return []
    out = os.path.join(tmp, "real")
    os.makedirs(out, exist_ok=True)
    proc = subprocess.run([scenegen, "--real", out], capture_output=True, text=True)
    files = sorted(f for f in os.listdir(out) if f.endswith(".json"))
    if proc.returncode != 0 or not files:
        lines = [l for l in proc.stderr.splitlines() if l.strip()]
        why = (f"exit status {proc.returncode}" + (f": {lines[0].strip()}" if lines else "")
               if proc.returncode != 0 else "it wrote no JSON file")
        notes.append("Generated real-content scenes: skipped, `covrast-scenegen --real DIR` is "
                     f"not supported by this build ({why}).")
        log(f"real scenes: covrast-scenegen --real not supported ({why}), skipped")
        return []
    if opts.quick:
        notes.append(f"Generated real-content scenes: `covrast-scenegen --real` wrote {len(files)} "
                     f"({', '.join(files)}); not rendered in quick mode.")
        return []
    scenes = []
    for f in files:
        stem = f[: -len(".json")]
        scenes.append({"name": f"real-{safe_name(stem)}", "path": os.path.join(out, f),
                       "size": opts.model_size,
                       "what": f"Generated scene `{f}` (`covrast-scenegen --real DIR`)"})
    size = opts.size or opts.model_size
    notes.append(f"Generated real-content scenes: {len(files)} written by `covrast-scenegen "
                 f"--real DIR` ({', '.join(f[:-5] for f in files)}), rendered at "
                 f"{size[0]}x{size[1]}.")
    return scenes


def empty_result(scene):
    """A result dict for the scene with no measurements yet."""
    return dict(scene, triangles=0, time_size=(0, 0), error_size=(0, 0), threads=None,
                rows={}, images={})


def measure_scene(opts, scene, tmp):
    """Renders one scene in every mode. The scene is a dict: name, path, what, and size (the
    size to render at unless --size is given, or None for the scene file's own). Returns the
    scene dict extended with sizes, triangle count, rows and images; a failed mode's row holds
    its error."""
    covrast, name, path = opts.covrast, scene["name"], scene["path"]
    info = scene_info(covrast, path)
    native = (info["width"], info["height"])
    time_size = opts.size or scene["size"] or native
    error_size = time_size if opts.error_size is None else fit_size(time_size, opts.error_size)
    same = error_size == time_size
    work = os.path.join(tmp, name)
    os.makedirs(work, exist_ok=True)
    result = empty_result(scene)
    result.update(triangles=info["triangles"], time_size=time_size, error_size=error_size)
    sz = lambda s: f"{s[0]}x{s[1]}"  # noqa: E731
    log(f"== {name}: timing at {sz(time_size)}, error at {sz(error_size)}")

    # The reference image first: every comparison needs it.
    ordered = ["reference"] + [m for m in MODES if m != "reference"]
    for mode in ordered:
        tag = mode.replace(":", "")
        row = {"mode": mode, "samples": samples_text(mode)}
        result["rows"][mode] = row
        try:
            # The reference takes seconds per frame: timed on --reference-repeat frames.
            repeat = opts.reference_repeat if mode == "reference" else opts.repeat
            timed_png = os.path.join(work, f"time-{tag}.png")
            stats = render(covrast, path, timed_png, mode, time_size, repeat, opts.threads)
            row["ms"], row["frames"] = stats["render_ms"], stats["frames"]
            row["post_ms"] = stats.get("post_ms", 0.0)  # the fxaa post-process, in "ms"
            row["overflows_timed"] = stats.get("fragment_overflows", 0)
            result["threads"] = stats["threads"]
            image = timed_png
            if not same:
                image = os.path.join(work, f"error-{tag}.png")
                stats = render(covrast, path, image, mode, error_size, 1, opts.threads)
            # Coverage mode merges fragments when a pixel's A-buffer list is full (an
            # approximation); counted on the image that is compared.
            row["overflows"] = stats.get("fragment_overflows", 0)
            result["images"][mode] = image
            if mode != "reference":
                if "reference" not in result["images"]:
                    raise Failure("no reference image to compare with")
                cmp = compare(covrast, image, result["images"]["reference"])
                row["rmse"], row["max_diff"] = cmp["rmse_linear"], cmp["max_diff_srgb8"]
            else:
                row["rmse"], row["max_diff"] = 0.0, 0
            log(f"  {mode:<15} {row['ms']:10.2f} ms  rmse {row['rmse']:.3e}  max {row['max_diff']}")
        except Failure as e:
            row["error"] = str(e)
            log(f"  {mode:<15} FAILED: {e}")
    return result


def make_crops(result, images_dir, quick):
    """Writes one enlarged crop per CROP_MODES mode of the same edge region; returns the
    list of (mode, file name) and the region, or a note when it cannot."""
    images = result["images"]
    missing = [m for m in CROP_MODES if m not in images]
    if missing:
        return [], None, "crops skipped: no image for " + ", ".join(missing)
    decoded = {m: read_png_rgb(images[m]) for m in CROP_MODES}
    width, height, _ = decoded["reference"]
    win_w, win_h = min(40, width), min(24, height)
    scale = 6 if quick else 8
    x0, y0 = edge_window(decoded["aliased"][2], decoded["reference"][2], width, height, win_w,
                         win_h)
    files = []
    for mode in CROP_MODES:
        w, h, rows = decoded[mode]
        if (w, h) != (width, height):
            return [], None, f"crops skipped: {mode} image is {w}x{h}, reference {width}x{height}"
        file = f"bench-{result['name']}-crop-{mode.replace(':', '')}.png"
        write_png_rgb(os.path.join(images_dir, file), win_w * scale, win_h * scale,
                      crop_enlarge(rows, x0, y0, win_w, win_h, scale))
        files.append((mode, file))
    return files, (x0, y0, win_w, win_h, scale), ""


# ---------------------------------------------------------------------------------------------
# The report


def fmt_ms(ms):
    return f"{ms:.0f}" if ms >= 100 else (f"{ms:.1f}" if ms >= 10 else f"{ms:.2f}")


def fmt_rmse(x):
    return "0" if x == 0 else f"{x:.2e}"


def ok(row):
    return "error" not in row and "rmse" in row


def ssaa_comparison(results):
    """Sentences computed from the numbers: coverage against the cheapest ssaa:N that matches
    its RMSE, one per scene, then a count over scenes (a list of strings)."""
    sentences, matched, total, faster = [], 0, 0, 0
    for r in results:
        rows = r["rows"]
        cov = rows.get("coverage", {})
        if not ok(cov):
            sentences.append(f"On `{r['name']}` the coverage mode failed: no comparison.")
            continue
        total += 1
        text = (f"On `{r['name']}` coverage reaches RMSE {fmt_rmse(cov['rmse'])} in "
                f"{fmt_ms(cov['ms'])} ms")
        ssaa = [rows[m] for m in SSAA_SERIES if ok(rows.get(m, {}))]
        match = next((s for s in ssaa if s["rmse"] <= cov["rmse"]), None)
        if match is None and ssaa:
            best = ssaa[-1]
            times = (f"{best['rmse'] / cov['rmse']:.1f}x coverage's" if cov["rmse"] > 0 else
                     "coverage's is 0: the same image as the reference")
            text += (f"; no ssaa mode up to {best['mode']} matches it ({best['mode']}: RMSE "
                     f"{fmt_rmse(best['rmse'])}, {times}, in {fmt_ms(best['ms'])} ms)")
        elif match is not None:
            n = int(match["mode"].split(":")[1])
            matched += 1
            ratio = match["ms"] / cov["ms"] if cov["ms"] > 0 else float("inf")
            faster += ratio > 1
            text += (f", which ssaa needs {n}x{n} samples and {fmt_ms(match['ms'])} ms to match "
                     f"({match['mode']}: RMSE {fmt_rmse(match['rmse'])}, {ratio:.1f}x "
                     "coverage's time)")
        al = rows.get("aliased", {})
        if ok(al):
            text += f"; aliased has RMSE {fmt_rmse(al['rmse'])} in {fmt_ms(al['ms'])} ms"
        worst = max((rows[m] for m in SSAA_SERIES if ok(rows.get(m, {}))),
                    key=lambda s: int(s["mode"].split(":")[1]), default=None)
        text += f". Coverage's largest single-channel error is {cov['max_diff']}/255"
        if worst is not None:
            text += f" ({worst['mode']}: {worst['max_diff']}/255)"
        if cov.get("overflows"):
            text += (f", and its A-buffer merged fragments {cov['overflows']:,} times on list "
                     f"overflow at {r['error_size'][0]}x{r['error_size'][1]}")
        sentences.append(text + ".")
    if total and matched == 0:
        sentences.append(
            f"Over the {total} scenes, no ssaa mode up to 16x16 matches coverage's RMSE.")
    elif total:
        sentences.append(
            f"Over the {total} scenes, ssaa up to 16x16 matches coverage's RMSE in {matched}, and "
            f"where it does it is slower than coverage in {faster} of {matched}.")
    return sentences


def fxaa_comparison(results):
    """Sentences computed from the numbers: FXAA (a post-process on the aliased frame) against
    aliased and coverage, over the scenes where all three rendered, then what it cannot fix
    (a list of strings)."""
    rmse_vs_aliased, rmse_vs_coverage, post_ms, time_ratio, better = [], [], [], [], 0
    for r in results:
        rows = r["rows"]
        fx, al, cov = rows.get("fxaa", {}), rows.get("aliased", {}), rows.get("coverage", {})
        if not (ok(fx) and ok(al) and ok(cov)) or al["rmse"] <= 0 or cov["rmse"] <= 0:
            continue
        rmse_vs_aliased.append(fx["rmse"] / al["rmse"])
        rmse_vs_coverage.append(fx["rmse"] / cov["rmse"])
        post_ms.append(fx["post_ms"])
        time_ratio.append(fx["ms"] / al["ms"] if al["ms"] > 0 else float("inf"))
        better += fx["rmse"] < al["rmse"]
    sentences = []
    if rmse_vs_aliased:
        def median(xs):
            xs = sorted(xs)
            return 0.5 * (xs[(len(xs) - 1) // 2] + xs[len(xs) // 2])
        n = len(rmse_vs_aliased)
        sentences.append(
            f"Over {n} scenes, FXAA lowers aliased's RMSE on {better} (median ratio "
            f"{median(rmse_vs_aliased):.2f}, range {min(rmse_vs_aliased):.2f} to "
            f"{max(rmse_vs_aliased):.2f}); its RMSE is a median {median(rmse_vs_coverage):.0f}x "
            f"coverage's. The post-process (`post_ms`, SIMD kernels, in parallel over rows) "
            f"takes a median {fmt_ms(median(post_ms))} ms, and `fxaa` a median "
            f"{median(time_ratio):.1f}x aliased's frame time.")
    sentences += [
        "What FXAA cannot fix ([fxaa.md](fxaa.md)): it sees one sample per pixel, so geometry "
        "that misses the pixel centres (sub-pixel detail, gaps) is not in its input; thin "
        "slivers stay broken dashes, each dash blurred (a 1-pixel line loses 41 % of its "
        "contrast) instead of spread over its true area; the fan of `slivers` and the default "
        "scene, where several slivers share a pixel, stays noisy, lightly blurred; and it "
        "slightly softens straight edges.",
        "TAA needs motion and a history of frames; for a single still frame it reduces to "
        "jittered supersampling, which `ssaa:N` and `ssaa-cmj:N` already are.",
    ]
    return sentences


def scene_checks(r):
    """The headline criteria for one scene result. Returns a dict with the numbers and, for
    "time", "rmse", "max" and "quality", True, False or None (a row it needs is missing or
    failed):
      time:    coverage's time <= TIME_FACTOR x TIME_RIVAL's and <= FINE_TIME_FACTOR x
               FINE_TIME_RIVAL's (all at the scene's timed size); "ratio" and "fine_ratio" hold
               coverage's time over each;
      rmse:    coverage's RMSE <= RMSE_FACTOR x the lowest RMSE of QUALITY_RIVALS (against the
               reference);
      max:     coverage's largest channel error <= the lowest of QUALITY_RIVALS';
      quality: rmse and max."""
    rows = r["rows"]
    cov = rows.get("coverage", {})
    fast = rows.get(TIME_RIVAL, {})
    slow = rows.get(FINE_TIME_RIVAL, {})
    rivals = [rows.get(name, {}) for name in QUALITY_RIVALS]
    fine = ({"rmse": min(x["rmse"] for x in rivals),
             "max_diff": min(x["max_diff"] for x in rivals)}
            if all(ok(x) for x in rivals) else {"error": "a 256-sample mode failed"})
    def timed(row):
        return "error" not in row and row.get("ms", 0) > 0

    compared = ok(cov) and ok(fine)
    check = {"time": None, "rmse": None, "max": None, "quality": None, "ratio": None,
             "fine_ratio": None, "cov": cov, "fast": fast, "slow": slow, "fine": fine}
    if timed(cov) and timed(fast) and timed(slow):
        check["ratio"] = cov["ms"] / fast["ms"]
        check["fine_ratio"] = cov["ms"] / slow["ms"]
        check["time"] = check["ratio"] <= TIME_FACTOR and check["fine_ratio"] <= FINE_TIME_FACTOR
    if compared:
        check["rmse"] = cov["rmse"] <= RMSE_FACTOR * fine["rmse"]
        check["max"] = cov["max_diff"] <= fine["max_diff"]
        check["quality"] = check["rmse"] and check["max"]
    return check


def yes_no(value):
    """A table cell for a criterion: yes, **no** (bold, so that failures stand out) or n/a."""
    return "n/a" if value is None else ("yes" if value else "**no**")


def cell_ms(row):
    """A table cell with a mode's time, or 'failed'."""
    return fmt_ms(row["ms"]) if "ms" in row and "error" not in row else "failed"


def cell_rmse(row):
    """A table cell with a mode's RMSE against the reference, or 'failed'."""
    return fmt_rmse(row["rmse"]) if ok(row) else "failed"


def cell_max(row):
    """A table cell with a mode's largest channel error against the reference, or 'failed'."""
    return str(row["max_diff"]) if ok(row) else "failed"


def count_line(label, results, checks, key):
    """One sentence: on how many scenes criterion `key` holds, and where it does not."""
    held = [r["name"] for r, c in zip(results, checks) if c[key] is True]
    failed = [r["name"] for r, c in zip(results, checks) if c[key] is False]
    unknown = [r["name"] for r, c in zip(results, checks) if c[key] is None]
    text = f"{label}: holds on {len(held)} of {len(results)} scenes"
    text += (f", does not hold on {len(failed)} (" + ", ".join(f"`{n}`" for n in failed) + ")"
             if failed else ", fails on none")
    if unknown:
        text += (f", and cannot be checked on {len(unknown)} (a mode failed: " +
                 ", ".join(f"`{n}`" for n in unknown) + ")")
    return text + "."


def checks_section(results):
    """Markdown lines for the headline checks: the criteria, a line per criterion counting
    where it holds, and a table with yes/no per criterion per scene."""
    checks = [scene_checks(r) for r in results]
    lines = [
        "Two checks per scene, both computed from the tables below:",
        "",
        f"- **(a) time**: coverage costs at most {TIME_FACTOR:g}x covrast's own `{TIME_RIVAL}` "
        f"**and** at most {FINE_TIME_FACTOR:g}x its `{FINE_TIME_RIVAL}` (256 samples per pixel; "
        "median `render_ms`, at the scene's timed size);",
        f"- **(b) quality**: against `reference`, coverage's RMSE is at most {RMSE_FACTOR}x "
        f"`{QUALITY_RIVAL}`'s **and** its largest channel error is no larger than "
        f"`{QUALITY_RIVAL}`'s.",
        "",
    ]
    both = [r["name"] for r, c in zip(results, checks) if c["time"] and c["quality"]]
    ratios = sorted(c["ratio"] for c in checks if c["ratio"] is not None)
    fine_ratios = sorted(c["fine_ratio"] for c in checks if c["fine_ratio"] is not None)

    def median(values):
        n = len(values)
        return (values[n // 2] if n % 2 else 0.5 * (values[n // 2 - 1] + values[n // 2])) if n else 0

    lines += [
        "- " + count_line("(a) time", results, checks, "time"),
        f"  - coverage / `{TIME_RIVAL}`: median {median(ratios):.2f}, largest "
        f"{max(ratios, default=0):.2f} (target <= {TIME_FACTOR:g}); coverage / "
        f"`{FINE_TIME_RIVAL}`: median {median(fine_ratios):.2f}, largest "
        f"{max(fine_ratios, default=0):.2f} (target <= {FINE_TIME_FACTOR:g})",
        "- " + count_line("(b) quality", results, checks, "quality"),
        "  - " + count_line(f"its RMSE part (<= {RMSE_FACTOR}x)", results, checks, "rmse"),
        "  - " + count_line("its max-error part", results, checks, "max"),
        f"- Both (a) and (b) hold on {len(both)} of {len(results)} scenes" +
        (": " + ", ".join(f"`{n}`" for n in both) if both else "") + ".",
        "",
        f"| scene | triangles | size | coverage ms | {TIME_RIVAL} ms | / {TIME_RIVAL} | "
        f"{FINE_TIME_RIVAL} ms | / {FINE_TIME_RIVAL} | (a) time | "
        f"coverage RMSE | {QUALITY_RIVAL} RMSE | RMSE ratio | coverage max | "
        f"{QUALITY_RIVAL} max | (b) RMSE | (b) max | (b) quality |",
        "|---|---:|---|---:|---:|---:|---:|---:|:-:|---:|---:|---:|---:|---:|:-:|:-:|:-:|",
    ]
    for r, c in zip(results, checks):
        cov, fast, fine = c["cov"], c["fast"], c["fine"]
        size = f"{r['time_size'][0]}x{r['time_size'][1]}"
        if r["error_size"] != r["time_size"]:
            size += f" (error {r['error_size'][0]}x{r['error_size'][1]})"
        ratio = (f"{cov['rmse'] / fine['rmse']:.3f}" if ok(cov) and ok(fine) and fine["rmse"] > 0
                 else "")
        def cell_ratio(value):
            return f"{value:.2f}" if value is not None else "n/a"

        cells = [f"`{r['name']}`", f"{r['triangles']:,}", size, cell_ms(cov), cell_ms(fast),
                 cell_ratio(c["ratio"]), cell_ms(c["slow"]), cell_ratio(c["fine_ratio"]),
                 yes_no(c["time"]), cell_rmse(cov), cell_rmse(fine), ratio, cell_max(cov),
                 cell_max(fine), yes_no(c["rmse"]), yes_no(c["max"]), yes_no(c["quality"])]
        lines.append("| " + " | ".join(cells) + " |")
    lines += ["", f"*RMSE ratio: coverage's RMSE over {QUALITY_RIVAL}'s (at most {RMSE_FACTOR} "
              "passes). Max: the largest single-channel error against the reference, in "
              "8-bit sRGB units.*"]
    return lines


def machine_info():
    model, cpus = "unknown", str(os.cpu_count() or "?")
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
        for line in out.splitlines():
            key, _, value = line.partition(":")
            if key.strip() == "Model name":
                model = value.strip()
            elif key.strip() == "CPU(s)":
                cpus = value.strip()
    except OSError:
        pass
    return model, cpus


def git_commit():
    try:
        head = subprocess.run(["git", "-C", REPO, "rev-parse", "--short", "HEAD"],
                              capture_output=True, text=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", REPO, "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True).stdout.strip()
    except OSError:
        return "unknown"
    if not head:
        return "unknown"
    return head + (" (with uncommitted changes)" if dirty else "")


def command_line(opts):
    """The report.py command that reproduces this run's choices (paths left out)."""
    cmd = "benchmarks/report.py" + (" --quick" if opts.quick else "")
    if opts.repeat != (1 if opts.quick else 5):
        cmd += f" --repeat {opts.repeat}"
    if opts.size_given:
        cmd += f" --size {opts.size[0]}x{opts.size[1]}"
    if opts.model_size != MODEL_SIZE:
        cmd += f" --model-size {opts.model_size[0]}x{opts.model_size[1]}"
    if opts.models_filter:
        cmd += f" --models-filter '{opts.models_filter}'"
    elif opts.all_models:
        cmd += " --all-models"
    if opts.no_models and not opts.quick:
        cmd += " --no-models"
    if opts.no_real and not opts.quick:
        cmd += " --no-real"
    if opts.scenes:
        cmd += f" --scenes {opts.scenes}"
    return cmd


def write_report(opts, results, plots, crops, set_notes, notes, md_path):
    """Writes the Markdown report: headline checks with the notes on the scene sets, the
    comparison with supersampling, the method with the other notes, then a section per scene
    (table, plot, crops)."""
    model, cpus = machine_info()
    load = " ".join(f"{x:.1f}" for x in os.getloadavg())
    threads = next((r["threads"] for r in results if r["threads"] is not None), "?")
    sz = lambda s: f"{s[0]}x{s[1]}"  # noqa: E731
    now = datetime.datetime.now(datetime.timezone.utc)
    all_threads = ", all hardware threads" if opts.threads == 0 else ""
    lines = [
        "# Benchmarks: quality versus cost",
        "",
        f"Generated by `{command_line(opts)}`; do not edit by hand, rerun the script.",
        "Every mode of every scene is timed with `covrast render SCENE --stats --repeat K` and",
        "compared with the `reference` mode (64x64 stratified samples per pixel in double",
        "precision) with `covrast compare --json`.",
        "",
        "## Headline checks",
        "",
    ]
    lines += checks_section(results)
    lines += ["", "Scenes: the bundled benchmark scenes (`scenes/`), then the generated "
              "real-content scenes (`real-*`), then the sample models (`model-*`)."]
    lines += [""] + [f"- {n}" for n in set_notes]
    lines += ["", "## Coverage against supersampling", ""]
    lines += [f"- {t}" for t in ssaa_comparison(results)]
    lines += ["", "## FXAA, a post-process filter", ""]
    lines += [f"- {t}" for t in fxaa_comparison(results)]
    lines += [
        "",
        "## Method",
        "",
        f"- Machine: {model}, {cpus} CPUs (lscpu); load average when the report finished: {load}.",
        "  The machine is shared with other work, so times vary between runs, by up to 2x.",
        f"- Commit: {git_commit()}; date: {now:%Y-%m-%d %H:%M UTC}.",
        f"- Threads: {threads} (`--threads {opts.threads}`{all_threads}); tile 64.",
        f"- Time (ms): the median `render_ms` of K = {opts.repeat} frames at the size in the",
        "  scene's heading (the whole frame, without loading or PNG encoding).",
        f"  The reference is timed on {opts.reference_repeat} frame(s) only: it is slow.",
        f"- Sizes: the bundled scenes at their own size; the generated scenes and the sample "
        f"models at `--model-size {sz(opts.model_size)}`" +
        (f"; everything at `--size {sz(opts.size)}` in this run." if opts.size else "."),
    ]
    if any(r["error_size"] != r["time_size"] for r in results):
        lines += [
            "- Error: the reference at the scenes' own sizes would dominate the run, so a scene",
            "  timed at a larger size than the error size (`--error-size "
            f"{sz(opts.error_size)}`) is rendered a",
            "  second time in every mode at its size scaled down to fit that box, and compared",
            "  there; the others are compared on the timed images. The error figures therefore",
            "  may describe a scene at a lower resolution than its times, where a larger share",
            "  of the pixels lies on edges.",
        ]
    else:
        lines += ["- Error: measured on the same images as the times."]
    lines += [
        "- RMSE: root mean square difference over all pixels and channels, in linear light",
        "  [0, 1]; max error: the largest difference of one channel, in 8-bit sRGB units.",
        "- The reference is itself sampled: its coverage error is up to 2.4e-3 of a pixel",
        "  (docs/supersampling.md), so RMSEs near 1e-3 and below are at the floor of this",
        "  measurement.",
        "- Samples per pixel: `msaa:K` tests coverage and depth at K samples but shades once per",
        "  pixel; `coverage` and `coverage-blend` use no samples (exact area per pixel); `fxaa`",
        "  is the aliased frame filtered by FXAA 3.11 (preset 12, docs/fxaa.md), its time",
        "  includes the post-process.",
        "- A-buffer overflows: coverage mode's `fragment_overflows` (`--stats`), the number of",
        "  times a pixel's fragment list was full and fragments were merged (an approximation),",
        "  in the timed image and, when the sizes differ, in the compared one.",
    ]
    lines += [f"- {n}" for n in notes]
    lines.append("")

    for r in results:
        name = r["name"]
        split = r["error_size"] != r["time_size"]
        overflow_head = "A-buffer overflows" + (" (timed / compared)" if split else "")
        lines += [
            f"## {name}",
            "",
            f"{r['what']}; {r['triangles']:,} triangles. Time at {sz(r['time_size'])}, error at "
            f"{sz(r['error_size'])}.",
            "",
            "| mode | samples per pixel | ms | RMSE (linear) | max error (/255) | "
            f"{overflow_head} |",
            "|---|---|---:|---:|---:|---:|",
        ]
        for mode in MODES:
            row = r["rows"].get(mode)
            if row is None:
                continue
            if "error" in row:
                lines.append(f"| `{mode}` | {row['samples']} | failed: {row['error']} | | | |")
                continue
            ms = fmt_ms(row["ms"])
            if mode == "reference" and row["frames"] != opts.repeat:
                ms += f" ({row['frames']} frame)"
            rmse = "(ground truth)" if mode == "reference" else fmt_rmse(row["rmse"])
            max_diff = "" if mode == "reference" else str(row["max_diff"])
            overflows = ""
            if mode == "coverage":
                overflows = f"{row['overflows_timed']:,}"
                if split:
                    overflows += f" / {row['overflows']:,}"
            cells = [f"`{mode}`", row["samples"], ms, rmse, max_diff, overflows]
            lines.append("| " + " | ".join(cells) + " |")
        lines.append("")
        plot = plots.get(name)
        if plot:
            lines += [f"![error versus time, {name}](images/{plot})", "",
                      "*RMSE against render time, log-log; the reference (RMSE 0) is not drawn. "
                      "Lines join the ssaa:N and msaa:K series.*", ""]
        files, region, note = crops.get(name, ([], None, "crops not made"))
        if files:
            x0, y0, w, h, scale = region
            lines += ["| " + " | ".join(m for m, _ in files) + " |",
                      "|" + "---|" * len(files),
                      "| " + " | ".join(f"![{m}](images/{f})" for m, f in files) + " |",
                      "",
                      f"*{w}x{h} pixels at ({x0}, {y0}) of the {sz(r['error_size'])} images, "
                      f"enlarged {scale}x (nearest neighbour): the window where aliased differs "
                      "most from the reference.*", ""]
        elif note:
            lines += [f"*{note}.*", ""]

    with open(md_path, "w") as f:
        f.write("\n".join(lines).rstrip("\n") + "\n")


def check_report(md_path, results):
    """Every scene section must have a table row for every mode, and every scene a row in the
    headline checks; returns the problems."""
    with open(md_path) as f:
        text = f.read()
    problems = []
    sections = re.split(r"^## ", text, flags=re.M)
    by_name = {s.split("\n", 1)[0].strip(): s for s in sections}
    for r in results:
        section = by_name.get(r["name"])
        if section is None:
            problems.append(f"{r['name']}: no section")
            continue
        for mode in MODES:
            if not re.search(r"^\| `" + re.escape(mode) + r"` \|", section, flags=re.M):
                problems.append(f"{r['name']}: no row for {mode}")
        for mode, row in r["rows"].items():
            if "error" in row:
                problems.append(f"{r['name']}: {mode} failed: {row['error']}")
    checks = by_name.get("Headline checks", "")
    for r in results:
        if not re.search(r"^\| `" + re.escape(r["name"]) + r"` \|", checks, flags=re.M):
            problems.append(f"{r['name']}: no row in the headline checks")
    return problems


def parse_options():
    """The command line, checked and with the defaults of --quick filled in."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--covrast", default=os.path.join(REPO, "build", "release", "covrast"),
                        help="the covrast executable (default build/release/covrast)")
    parser.add_argument("--scenegen", help="the covrast-scenegen executable for the generated "
                        "scenes (default: covrast-scenegen next to --covrast)")
    parser.add_argument("--out", help="output directory for benchmarks.md and images/ "
                        "(default docs/; required with --quick)")
    parser.add_argument("--quick", action="store_true",
                        help="96x54 for everything, 1 frame, two scenes, no models: a smoke test")
    parser.add_argument("--repeat", type=int, help="frames per timing (default 5, quick 1)")
    parser.add_argument("--reference-repeat", type=int, default=1,
                        help="frames when timing the reference (default 1)")
    parser.add_argument("--size", type=parse_size, help="render every scene at WxH")
    parser.add_argument("--model-size", type=parse_size, default=MODEL_SIZE,
                        help="WxH of the sample models and the generated scenes (default "
                        f"{MODEL_SIZE[0]}x{MODEL_SIZE[1]})")
    parser.add_argument("--error-size", default=None,
                        help="WxH box for the error images, or 'full' "
                        "(default 640x360; quick: full)")
    parser.add_argument("--threads", type=int, default=0, help="covrast --threads (0 = all)")
    parser.add_argument("--models", default=os.path.join(os.path.dirname(REPO), "shared", "models"),
                        help="folder of the sample models: *.obj and gltf/<Name>/ "
                        "(default ../shared/models)")
    parser.add_argument("--models-filter", metavar="REGEX",
                        help="only the models whose name (OBJ file stem or glTF folder, "
                        "spaces as '_') matches REGEX, chosen from all of them")
    parser.add_argument("--all-models", action="store_true",
                        help="every model, not only the OBJ models and DEFAULT_GLTF_MODELS")
    parser.add_argument("--no-models", action="store_true", help="leave out the sample models")
    parser.add_argument("--no-real", action="store_true",
                        help="leave out the scenes of covrast-scenegen --real")
    parser.add_argument("--scenes", help="comma-separated subset of the bundled scenes " +
                        ",".join(s[0] for s in SCENES))
    parser.add_argument("--plot-spec", help=argparse.SUPPRESS)
    opts = parser.parse_args()
    if opts.plot_spec:
        return opts

    opts.size_given = opts.size
    if opts.quick:
        if not opts.out:
            parser.error("--quick needs --out DIR (it must not overwrite docs/)")
        opts.size = opts.size or (96, 54)
        opts.repeat = opts.repeat or 1
        opts.error_size = opts.error_size or "full"
        opts.no_models = True
    opts.repeat = opts.repeat or 5
    if opts.repeat < 1 or opts.reference_repeat < 1:
        parser.error("--repeat and --reference-repeat must be at least 1")
    error_text = opts.error_size or "640x360"
    try:
        opts.error_size = None if error_text == "full" else parse_size(error_text)
    except argparse.ArgumentTypeError as e:
        parser.error(f"--error-size: {e}")
    if opts.models_filter:
        try:
            re.compile(opts.models_filter)
        except re.error as e:
            parser.error(f"--models-filter: {e}")
    opts.covrast = os.path.abspath(opts.covrast)
    if not os.access(opts.covrast, os.X_OK):
        parser.error(f"{opts.covrast}: not an executable (build covrast first, or pass --covrast)")
    opts.scenegen = os.path.abspath(
        opts.scenegen or os.path.join(os.path.dirname(opts.covrast), "covrast-scenegen"))
    opts.models = os.path.abspath(opts.models)
    if opts.scenes:
        names = opts.scenes.split(",")
        unknown = [n for n in names if n not in {s[0] for s in SCENES}]
        if unknown:
            parser.error("--scenes: unknown " + ", ".join(unknown))
    return opts


def bundled_scenes(opts):
    """The bundled benchmark scenes of this run (all, the quick pair, or --scenes), as scene
    dicts."""
    wanted = [s for s in SCENES if s[0] in QUICK_SCENES] if opts.quick else list(SCENES)
    if opts.scenes:
        names = opts.scenes.split(",")
        wanted = [s for s in SCENES if s[0] in names]
    return [{"name": name, "path": os.path.join(REPO, path), "size": None,
             "what": f"`{path}` ({what})"} for name, path, what in wanted]


def plotting_interpreter(opts, notes):
    """A Python interpreter that can import matplotlib (installing python3-matplotlib for the
    full report when none can), or None with a note saying why there are no plots."""
    interp = interpreter_with_matplotlib()
    if interp is None and not opts.quick:
        message = install_matplotlib()
        interp = interpreter_with_matplotlib()
        if interp is None:
            notes.append("No plots: matplotlib could not be imported. " + message)
    elif interp is None:
        notes.append("No plots: matplotlib (Debian's python3-matplotlib) is not installed, and "
                     "--quick does not install it.")
    if interp is None:
        log("plots skipped: matplotlib cannot be imported")
    return interp


def plot_scene(interp, opts, result, images_dir, tmp):
    """Draws the error-versus-time plot of one scene with interp; returns its file name in
    images_dir, or None (logged) when there is nothing to draw or drawing failed."""
    name = result["name"]
    points = [{"mode": m, "ms": row["ms"], "rmse": row["rmse"]}
              for m, row in result["rows"].items()
              if ok(row) and row["rmse"] > 0 and row["ms"] > 0]
    file = f"bench-{name}-error-vs-time.png"
    sz = lambda s: f"{s[0]}x{s[1]}"  # noqa: E731
    spec = {"points": points, "out": os.path.join(images_dir, file),
            "title": f"{name}: error versus time", "repeat": opts.repeat,
            "time_size": sz(result["time_size"]), "error_size": sz(result["error_size"])}
    spec_path = os.path.join(tmp, f"plot-{name}.json")
    write_json(spec_path, spec)
    proc = subprocess.run([interp, os.path.abspath(__file__), "--plot-spec", spec_path],
                          capture_output=True, text=True)
    if proc.returncode == 0 and points:
        return file
    why = (proc.stderr.strip().splitlines() or ["no points"])[-1]
    log(f"plot for {name} failed: {why}")
    return None


def main():
    """Measures every scene, writes the report and checks it; returns the exit status."""
    started = time.monotonic()
    opts = parse_options()
    if opts.plot_spec:
        draw_plot(opts.plot_spec)
        return 0
    out_dir = os.path.abspath(opts.out or os.path.join(REPO, "docs"))
    images_dir = os.path.join(out_dir, "images")
    os.makedirs(images_dir, exist_ok=True)

    notes = []
    if opts.quick:
        notes.append("Quick mode (`--quick`): a smoke test at 96x54 with one frame and two scenes "
                     "and no sample models; the numbers mean little.")
    elif opts.repeat < 5:
        notes.append(f"K = {opts.repeat} instead of the default 5, to keep the run short on a "
                     "shared machine.")
    interp = plotting_interpreter(opts, notes)

    results, plots, crops = [], {}, {}
    with tempfile.TemporaryDirectory(prefix="covrast-report-") as tmp:
        scenes, set_notes = bundled_scenes(opts), []
        if opts.no_real:
            set_notes.append("Generated real-content scenes: left out (`--no-real`).")
        else:
            scenes += real_scenes(opts, tmp, set_notes)
        if opts.no_models:
            set_notes.append("Sample models: left out (" +
                             ("`--quick`" if opts.quick else "`--no-models`") + ").")
        else:
            scenes += model_scenes(opts, tmp, set_notes)
        for scene in scenes:
            name = scene["name"]
            try:
                result = measure_scene(opts, scene, tmp)
            except Failure as e:
                log(f"== {name}: FAILED: {e}")
                result = empty_result(scene)
                result["rows"] = {m: {"mode": m, "samples": samples_text(m), "error": str(e)}
                                  for m in MODES}
            results.append(result)
            try:
                crops[name] = make_crops(result, images_dir, opts.quick)
            except (Failure, OSError, zlib.error) as e:
                crops[name] = ([], None, f"crops failed: {e}")
            if interp:
                plots[name] = plot_scene(interp, opts, result, images_dir, tmp)

    seconds = time.monotonic() - started
    took = f"{seconds / 60:.1f} minutes" if seconds >= 120 else f"{seconds:.0f} s"
    notes.append(f"This run took {took} ({len(results)} scenes).")
    md_path = os.path.join(out_dir, "benchmarks.md")
    write_report(opts, results, plots, crops, set_notes, notes, md_path)
    log(f"wrote {md_path} in {took}")
    problems = check_report(md_path, results)
    for p in problems:
        log(f"report: {p}")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
