#!/usr/bin/env python3
"""Runs the examples of README.md and docs/*.md as a reader would, on a fresh copy of the
repository: every fenced ```sh / ```bash block and every ```json scene or manifest.

Each Markdown file gets its own copy of the source tree (without .git, build/ and out/) in a
temporary directory, and its blocks run there in order, in one shell each (bash -e -o pipefail),
so a block may use what an earlier block of the same file made. `covrast` is the executable
given by --covrast (first on PATH) and so is `build/release/covrast`; HOME is an empty folder
of the temporary directory. ../shared (the sample models) is beside the copy when it is beside
the repository, and absent with --no-shared.

JSON blocks: a manifest (an object with "cases") is run with `covrast test`; anything else is a
scene, or scene keys without the braces (merged into scenes/default.json), rendered at 64x36
with --strict. Either is written into the copy's scenes/ (a manifest into tests/) unless a
`file:` marker names the repository file it shows, which must then hold the same JSON.

Markers, HTML comments on the lines right above a fence (invisible in the rendered page):
  <!-- needs-shared -->      needs ../shared: skipped, with the reason, when it is absent
  <!-- not-run: REASON -->   not run (installation, long steps, fragments): REASON is printed
  <!-- exit-code: N -->      the block's expected exit code (default 0)
  <!-- file: PATH -->        a JSON block is the repository's file PATH

Exit status: 0 when every example ran as expected, 1 otherwise.
Each block has 120 s (CHECK_DOCS_TIMEOUT=SECONDS to change it); on a timeout its process group
is killed.
Usage: scripts/check-docs.py --covrast EXE [--no-shared] [--keep] [FILE.md ...]
"""

import argparse
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

FENCE = re.compile(r"^```([A-Za-z0-9_+-]*)\s*$")
MARKER = re.compile(r"^<!--\s*([a-z-]+)(?::\s*(.*?))?\s*-->$")
RUN_LANGS = {"sh", "bash", "json"}
TIMEOUT_S = int(os.environ.get("CHECK_DOCS_TIMEOUT", "120"))


class Block:
    def __init__(self, path, line, lang, text, markers):
        self.path, self.line, self.lang, self.text, self.markers = path, line, lang, text, markers

    def where(self):
        return f"{self.path}:{self.line} {self.lang}"


def blocks_of(md_path, shown_path):
    """The fenced blocks of a Markdown file with the markers right above each."""
    lines = md_path.read_text(encoding="utf-8").split("\n")
    blocks, i = [], 0
    while i < len(lines):
        m = FENCE.match(lines[i].strip())
        if not m or not m.group(1):
            i += 1
            continue
        markers, k = {}, i - 1
        while k >= 0 and MARKER.match(lines[k].strip()):
            mk = MARKER.match(lines[k].strip())
            markers[mk.group(1)] = mk.group(2) or ""
            k -= 1
        j = i + 1
        while j < len(lines) and lines[j].strip() != "```":
            j += 1
        blocks.append(Block(shown_path, i + 1, m.group(1), "\n".join(lines[i + 1:j]) + "\n",
                            markers))
        i = j + 1
    return blocks


def fresh_copy(source, work):
    """A copy of the source tree in work/covrast, as a clone would have it (no build output)."""
    dest = work / "covrast"
    shutil.copytree(source, dest, symlinks=True,
                    ignore=shutil.ignore_patterns(".git", "build", "out", "__pycache__"))
    return dest


def run(cmd, cwd, env, input_text=None):
    """Runs cmd in a process group of its own: on a timeout the whole group is killed."""
    start = time.monotonic()
    proc = subprocess.Popen(cmd, cwd=cwd, env=env, text=True, stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            start_new_session=True)
    try:
        output, _ = proc.communicate(input_text, timeout=TIMEOUT_S)
        code = proc.returncode
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        output, _ = proc.communicate()
        code = f"timeout after {TIMEOUT_S} s"
    return code, output, time.monotonic() - start


def json_command(block, tree, covrast):
    """What to run for a JSON block: (command, None) or (None, error)."""
    text = block.text
    fragment = False
    try:
        data = json.loads(text)
    except json.JSONDecodeError:
        try:
            data = json.loads("{" + text + "}")
            fragment = True
        except json.JSONDecodeError as e:
            return None, f"neither JSON nor JSON keys ({e}); mark a fragment with not-run"
    if not isinstance(data, dict):
        return None, "not a JSON object; mark it with not-run"
    manifest = "cases" in data
    if "file" in block.markers:
        target = tree / block.markers["file"]
        if not target.is_file():
            return None, f"file: {block.markers['file']} is not in the repository"
        if json.loads(target.read_text(encoding="utf-8")) != data:
            return None, f"differs from the repository's {block.markers['file']}"
    else:
        if fragment and not manifest:
            base = json.loads((tree / "scenes/default.json").read_text(encoding="utf-8"))
            base.update(data)
            data = base
        folder = tree / ("tests" if manifest else "scenes")
        target = folder / f"docs-example-{Path(block.path).stem}-{block.line}.json"
        target.write_text(json.dumps(data, indent=1) + "\n", encoding="utf-8")
    if manifest:
        return [covrast, "test", str(target), "--quiet"], None
    out = tree / "out"
    out.mkdir(exist_ok=True)
    return [covrast, "render", str(target), "-o", str(out / f"docs-example-{block.line}.png"),
            "--size", "64x36", "--strict", "--quiet"], None


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--covrast", required=True, help="the covrast executable to run")
    parser.add_argument("--source", default=str(Path(__file__).resolve().parent.parent),
                        help="the repository (default: this script's)")
    parser.add_argument("--no-shared", action="store_true",
                        help="run as if ../shared were absent")
    parser.add_argument("--keep", action="store_true", help="keep the temporary directory")
    parser.add_argument("files", nargs="*", help="Markdown files (default: README.md docs/*.md)")
    args = parser.parse_args()

    source = Path(args.source).resolve()
    covrast = str(Path(args.covrast).resolve())
    shared = source.parent / "shared"
    have_shared = shared.is_dir() and not args.no_shared
    files = [Path(f).resolve() for f in args.files] or \
        [source / "README.md"] + sorted((source / "docs").glob("*.md"))

    work_root = Path(tempfile.mkdtemp(prefix="covrast-docs-"))
    counts = {"ok": 0, "skipped": 0, "failed": 0}
    started = time.monotonic()
    try:
        for md in files:
            shown = str(md.relative_to(source)) if md.is_relative_to(source) else str(md)
            blocks = [b for b in blocks_of(md, shown) if b.lang in RUN_LANGS]
            if not blocks:
                continue
            work = work_root / re.sub(r"[^A-Za-z0-9_.-]", "_", shown)
            work.mkdir()
            tree = fresh_copy(source, work)
            if have_shared:
                (work / "shared").symlink_to(shared)
            (work / "home").mkdir()
            (work / "bin").mkdir()
            (work / "bin/covrast").symlink_to(covrast)
            (tree / "build/release").mkdir(parents=True)
            (tree / "build/release/covrast").symlink_to(covrast)
            env = dict(os.environ, HOME=str(work / "home"),
                       PATH=f"{work / 'bin'}{os.pathsep}{os.environ.get('PATH', '')}")
            for block in blocks:
                if "not-run" in block.markers:
                    print(f"skip {block.where()}: {block.markers['not-run'] or 'not run'}")
                    counts["skipped"] += 1
                    continue
                if "needs-shared" in block.markers and not have_shared:
                    print(f"skip {block.where()}: needs ../shared (the sample models), absent")
                    counts["skipped"] += 1
                    continue
                expected = int(block.markers.get("exit-code") or 0)
                if block.lang == "json":
                    command, error = json_command(block, tree, covrast)
                    if error:
                        print(f"FAIL {block.where()}: {error}")
                        counts["failed"] += 1
                        continue
                    code, output, seconds = run(command, tree, env)
                else:
                    code, output, seconds = run(["bash", "-e", "-o", "pipefail", "-s"], tree, env,
                                                block.text)
                if code == expected:
                    print(f"ok   {block.where()} ({seconds:.1f} s)")
                    counts["ok"] += 1
                else:
                    print(f"FAIL {block.where()}: exit {code}, expected {expected}")
                    print("  " + "\n  ".join(block.text.rstrip("\n").split("\n")))
                    print("  output:\n    " + "\n    ".join(output.rstrip("\n").split("\n")[-20:]))
                    counts["failed"] += 1
    finally:
        if args.keep:
            print(f"kept {work_root}")
        else:
            shutil.rmtree(work_root, ignore_errors=True)
    print(f"check-docs: {counts['ok']} ran as documented, {counts['skipped']} skipped, "
          f"{counts['failed']} failed ({time.monotonic() - started:.1f} s)")
    return 1 if counts["failed"] else 0


if __name__ == "__main__":
    sys.exit(main())
