#!/usr/bin/env python3
"""Quality-versus-cost report for covrast (issue 5, sections 4-5): writes docs/benchmarks.md.

Renders every benchmark scene in every anti-aliasing mode with the covrast command line, and
for each mode records
  - the median `render_ms` of `covrast render SCENE --stats --repeat K` at the scene's own size,
  - the error against the `reference` mode (64 x 64 samples per pixel, double precision) from
    `covrast compare --json`: RMSE in linear light and the largest channel error in 8-bit sRGB.
The reference is slow (seconds per 640x360 frame), so the error figures are measured at a
smaller size (`--error-size`, default 640x360: every mode is rendered a second time at the
scene's size scaled down to fit that box). The report holds a table per scene, an
error-versus-time log-log plot per scene (matplotlib, when available), enlarged crops of one
edge region, and a headline paragraph computed from the numbers.

Python standard library only, plus Debian's python3-matplotlib for the plots: the full report
installs it with apt-get when it is missing; `--quick` never installs anything and skips the
plots when matplotlib cannot be imported. Crops are cut and enlarged here (PNG read and written
with zlib), so ImageMagick is not needed.

  benchmarks/report.py                          # full report into docs/ (takes many minutes)
  benchmarks/report.py --quick --out /tmp/r     # 96x54, 1 frame, two scenes: a few seconds

Exit status: 0 when every scene has a row for every mode and every render and comparison
succeeded; 1 otherwise (the report is still written, with the failures in it); 2 on bad usage.
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
import zlib

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

MODES = [
    "aliased",
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
CROP_MODES = ["aliased", "coverage", "coverage-blend", "msaa:4", "ssaa:4", "ssaa:16", "reference"]
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
    if kind == "reference":
        return f"{REFERENCE_SAMPLES} (64x64)"
    return "exact area"


def model_scenes(covrast, models_dir, tmp):
    """A framed scene JSON per OBJ in models_dir: camera on +z looking at the centre of the
    bounding box (from `covrast info --json`), far enough for the bounding sphere (radius r,
    half the box diagonal) to fit the vertical field of view: distance = 1.05 r / sin(fovy/2).
    Same framing as benchmarks/bench_frame.cpp."""
    scenes = []
    if not os.path.isdir(models_dir):
        return scenes
    for name in sorted(os.listdir(models_dir)):
        if not name.endswith(".obj"):
            continue
        obj = os.path.abspath(os.path.join(models_dir, name))
        stem = name[: -len(".obj")]
        path = os.path.join(tmp, f"model-{stem}.json")
        scene = {
            "width": 1920,
            "height": 1080,
            "background": [0.02, 0.02, 0.02],
            "camera": {"eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0], "fovy_deg": 40,
                       "near": 0.1, "far": 100},
            "meshes": [{"obj": obj, "color": "per_triangle"}],
        }
        with open(path, "w") as f:
            json.dump(scene, f)
        try:
            info = scene_info(covrast, path)
        except Failure as e:
            log(f"model {name}: skipped ({e})")
            continue
        if not info.get("bounds"):
            log(f"model {name}: skipped (no geometry)")
            continue
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
        with open(path, "w") as f:
            json.dump(scene, f)
        what = f"sample model {name}, per-triangle colours"
        scenes.append((f"model-{stem}", path, what))
    return scenes


def measure_scene(opts, name, path, what, tmp):
    """Renders one scene in every mode. Returns a dict with sizes, rows and failures."""
    covrast = opts.covrast
    info = scene_info(covrast, path)
    native = (info["width"], info["height"])
    time_size = opts.size or native
    error_size = time_size if opts.error_size is None else fit_size(time_size, opts.error_size)
    same = error_size == time_size
    work = os.path.join(tmp, name)
    os.makedirs(work, exist_ok=True)
    result = {"name": name, "path": path, "what": what, "triangles": info["triangles"],
              "time_size": time_size, "error_size": error_size, "rows": {}, "images": {},
              "threads": None}
    sz = lambda s: f"{s[0]}x{s[1]}"  # noqa: E731
    log(f"== {name}: timing at {sz(time_size)}, error at {sz(error_size)}")

    # The reference image first: every comparison needs it.
    ordered = ["reference"] + [m for m in MODES if m != "reference"]
    for mode in ordered:
        tag = mode.replace(":", "")
        row = {"mode": mode, "samples": samples_text(mode)}
        result["rows"][mode] = row
        try:
            repeat = opts.reference_repeat if mode == "reference" and not same else opts.repeat
            timed_png = os.path.join(work, f"time-{tag}.png")
            stats = render(covrast, path, timed_png, mode, time_size, repeat, opts.threads)
            row["ms"], row["frames"] = stats["render_ms"], stats["frames"]
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


def headline(results):
    """Sentences computed from the numbers: coverage against the cheapest ssaa:N that matches
    its RMSE, per scene, then a count over scenes."""
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
            text += (f"; no ssaa mode up to {best['mode']} matches it ({best['mode']}: RMSE "
                     f"{fmt_rmse(best['rmse'])}, {best['rmse'] / max(cov['rmse'], 1e-300):.1f}x "
                     f"coverage's, in {fmt_ms(best['ms'])} ms)")
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
    return " ".join(sentences)


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


def write_report(opts, results, plots, crops, notes, md_path):
    model, cpus = machine_info()
    load = " ".join(f"{x:.1f}" for x in os.getloadavg())
    threads = next((r["threads"] for r in results if r["threads"] is not None), "?")
    sz = lambda s: f"{s[0]}x{s[1]}"  # noqa: E731
    now = datetime.datetime.now(datetime.timezone.utc)
    all_threads = ", all hardware threads" if opts.threads == 0 else ""
    cmd = "benchmarks/report.py" + (" --quick" if opts.quick else "")
    if opts.repeat != (1 if opts.quick else 5):
        cmd += f" --repeat {opts.repeat}"
    lines = [
        "# Benchmarks: quality versus cost",
        "",
        f"Generated by `{cmd}`; do not edit by hand, rerun the script.",
        "Every mode of every scene is timed with `covrast render SCENE --stats --repeat K` and",
        "compared with the `reference` mode (64x64 stratified samples per pixel in double",
        "precision) with `covrast compare --json`.",
        "",
        "## Headline",
        "",
        headline(results),
        "",
        "## Method",
        "",
        f"- Machine: {model}, {cpus} CPUs (lscpu); load average when the report finished: {load}.",
        "  The machine is shared with other work, so times vary between runs, by up to 2x.",
        f"- Commit: {git_commit()}; date: {now:%Y-%m-%d %H:%M UTC}.",
        f"- Threads: {threads} (`--threads {opts.threads}`{all_threads}); tile 64.",
        f"- Time (ms): the median `render_ms` of K = {opts.repeat} frames at the size in the",
        "  scene's heading (the whole frame, without loading or PNG encoding).",
    ]
    if any(r["error_size"] != r["time_size"] for r in results):
        lines += [
            f"  The reference is timed on {opts.reference_repeat} frame(s) only: it is slow.",
            "- Error: the reference at the scenes' own sizes would dominate the run, so every mode",
            "  is rendered a second time at the error size (`--error-size "
            f"{sz(opts.error_size)}`: the scene's",
            "  size scaled down to fit that box) and compared there. The error figures therefore",
            "  describe the same scene at a lower resolution than the times, where a larger share",
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
        "  pixel; `coverage` and `coverage-blend` use no samples (exact area per pixel).",
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
        inside = r["path"].startswith(REPO + os.sep)
        shown = os.path.relpath(r["path"], REPO) if inside else os.path.basename(r["path"])
        lines += [
            f"## {name}",
            "",
            f"`{shown}` ({r['what']}; {r['triangles']:,} triangles). Time at "
            f"{sz(r['time_size'])}, error at {sz(r['error_size'])}.",
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
    """Every scene section must have a table row for every mode; returns the problems."""
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
    return problems


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--covrast", default=os.path.join(REPO, "build", "release", "covrast"),
                        help="the covrast executable (default build/release/covrast)")
    parser.add_argument("--out", help="output directory for benchmarks.md and images/ "
                        "(default docs/; required with --quick)")
    parser.add_argument("--quick", action="store_true",
                        help="96x54 for everything, 1 frame, two scenes, no models: a smoke test")
    parser.add_argument("--repeat", type=int, help="frames per timing (default 5, quick 1)")
    parser.add_argument("--reference-repeat", type=int, default=1,
                        help="frames when timing the reference at a size other than the error size")
    parser.add_argument("--size", type=parse_size, help="render every scene at WxH")
    parser.add_argument("--error-size", default=None,
                        help="WxH box for the error images, or 'full' "
                        "(default 640x360; quick: full)")
    parser.add_argument("--threads", type=int, default=0, help="covrast --threads (0 = all)")
    parser.add_argument("--models", default=os.path.join(os.path.dirname(REPO), "shared", "models"),
                        help="folder of OBJ models to add as scenes (default ../shared/models)")
    parser.add_argument("--no-models", action="store_true", help="do not add the OBJ models")
    parser.add_argument("--scenes", help="comma-separated subset of " +
                        ",".join(s[0] for s in SCENES))
    parser.add_argument("--plot-spec", help=argparse.SUPPRESS)
    opts = parser.parse_args()

    if opts.plot_spec:
        draw_plot(opts.plot_spec)
        return 0

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
    opts.covrast = os.path.abspath(opts.covrast)
    if not os.access(opts.covrast, os.X_OK):
        parser.error(f"{opts.covrast}: not an executable (build covrast first, or pass --covrast)")
    out_dir = os.path.abspath(opts.out or os.path.join(REPO, "docs"))
    images_dir = os.path.join(out_dir, "images")
    os.makedirs(images_dir, exist_ok=True)

    wanted = [s for s in SCENES if s[0] in QUICK_SCENES] if opts.quick else list(SCENES)
    if opts.scenes:
        names = opts.scenes.split(",")
        unknown = [n for n in names if n not in {s[0] for s in SCENES}]
        if unknown:
            parser.error("--scenes: unknown " + ", ".join(unknown))
        wanted = [s for s in SCENES if s[0] in names]

    notes = []
    if opts.quick:
        notes.append("Quick mode (`--quick`): a smoke test at 96x54 with one frame and two scenes; "
                     "the numbers mean little.")
    elif opts.repeat < 5:
        notes.append(f"K = {opts.repeat} instead of the default 5, to keep the run short on a "
                     "shared machine.")

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

    results, plots, crops = [], {}, {}
    with tempfile.TemporaryDirectory(prefix="covrast-report-") as tmp:
        scenes = [(n, os.path.join(REPO, p), w) for n, p, w in wanted]
        if not opts.no_models:
            models = model_scenes(opts.covrast, opts.models, tmp)
            if models:
                scenes += models
            else:
                notes.append(f"No OBJ models in {opts.models}: the model scenes are left out.")
                log(f"no models in {opts.models}, skipped")
        for name, path, what in scenes:
            try:
                result = measure_scene(opts, name, path, what, tmp)
            except Failure as e:
                log(f"== {name}: FAILED: {e}")
                result = {"name": name, "path": path, "what": what, "triangles": 0,
                          "time_size": (0, 0), "error_size": (0, 0), "threads": None,
                          "images": {}, "rows": {m: {"mode": m, "samples": samples_text(m),
                                                      "error": str(e)} for m in MODES}}
            results.append(result)
            try:
                crops[name] = make_crops(result, images_dir, opts.quick)
            except (Failure, OSError, zlib.error) as e:
                crops[name] = ([], None, f"crops failed: {e}")
            if interp:
                points = [{"mode": m, "ms": row["ms"], "rmse": row["rmse"]}
                          for m, row in result["rows"].items()
                          if ok(row) and row["rmse"] > 0 and row["ms"] > 0]
                file = f"bench-{name}-error-vs-time.png"
                sz = lambda s: f"{s[0]}x{s[1]}"  # noqa: E731
                spec = {"points": points, "out": os.path.join(images_dir, file),
                        "title": f"{name}: error versus time", "repeat": opts.repeat,
                        "time_size": sz(result["time_size"]),
                        "error_size": sz(result["error_size"])}
                spec_path = os.path.join(tmp, f"plot-{name}.json")
                with open(spec_path, "w") as f:
                    json.dump(spec, f)
                proc = subprocess.run([interp, os.path.abspath(__file__), "--plot-spec", spec_path],
                                      capture_output=True, text=True)
                if proc.returncode == 0 and points:
                    plots[name] = file
                else:
                    why = (proc.stderr.strip().splitlines() or ["no points"])[-1]
                    log(f"plot for {name} failed: {why}")

    md_path = os.path.join(out_dir, "benchmarks.md")
    write_report(opts, results, plots, crops, notes, md_path)
    log(f"wrote {md_path}")
    problems = check_report(md_path, results)
    for p in problems:
        log(f"report: {p}")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
