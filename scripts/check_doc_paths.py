#!/usr/bin/env python3
"""Every repository path that docs/ and code comments name exists (issue 34).

A path is a word starting with one of the repository's top-level folders (`sim/src/cpu_water.cpp`,
`docs/scenario.md`, `tests/sim/`). It counts as existing when it is a file or folder of the
checkout; when it is a public header named the way code includes it (`sim/params.hpp` for
`sim/include/strata/sim/params.hpp`); when it names a build product (its last part is a CMake
target, `bench/strata_bench_sim`); when it ends in `_` and some file starts with it
(`sim/src/cpu_` for the CPU backend's files); or when it lists sibling extensions
(`render/shaders/overlay.vert/.frag`). In code, only comments are read (after `//` or `#`),
not string literals: a test may name files that are not in the checkout.

Usage: check_doc_paths.py [ROOT]   (exit 1 and one line per stale path when any is missing)
"""
import os
import re
import subprocess
import sys

CODE = (".cpp", ".hpp", ".h", ".glsl", ".comp", ".vert", ".frag")
HASH = (".py", ".sh", ".cmake", ".toml", ".txt")


def comment_text(path, line):
    """The part of a line that is prose: all of it in Markdown, the comment in code."""
    if path.endswith(".md"):
        return line
    if path.endswith(CODE):
        at = line.find("//")
        return line[at + 2:] if at >= 0 else ""
    if path.endswith(HASH) or os.path.basename(path) == "CMakeLists.txt":
        at = line.find("#")
        return line[at + 1:] if at >= 0 and not line.lstrip().startswith("#!") else ""
    return ""


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), ".."))
    files = subprocess.run(["git", "ls-files"], cwd=root, capture_output=True, text=True, check=True).stdout.split()
    tops = sorted({f.split("/")[0] for f in files if "/" in f})
    targets = set()
    target_re = re.compile(r"(?:add_executable|add_library|strata_add_test|strata_add_library)\(\s*([\w-]+)")
    for f in files:
        if os.path.basename(f) == "CMakeLists.txt" or f.endswith(".cmake"):
            targets.update(target_re.findall(open(os.path.join(root, f), errors="replace").read()))
    word = re.compile(r"(?<![\w./-])((?:" + "|".join(map(re.escape, tops)) + r")/[\w./-]*[\w/])")

    def exists(p):
        if os.path.exists(os.path.join(root, p)):
            return True
        head, _, rest = p.partition("/")
        if os.path.exists(os.path.join(root, head, "include", "strata", head, rest)):
            return True
        if os.path.basename(p.rstrip("/")) in targets:
            return True
        if p.endswith("_") and any(f.startswith(p) for f in files):
            return True
        if "/." in p:  # overlay.vert/.frag: siblings by extension
            base, *exts = p.split("/.")
            stem = base.rsplit(".", 1)[0]
            return exists(base) and all(exists(stem + "." + e) for e in exts)
        return False

    stale = []
    for f in files:
        if not f.endswith(".md") and not f.endswith(CODE + HASH) and os.path.basename(f) != "CMakeLists.txt":
            continue
        with open(os.path.join(root, f), errors="replace") as text:
            for n, line in enumerate(text, 1):
                for m in word.finditer(comment_text(f, line)):
                    p = m.group(1).rstrip(".")
                    if not exists(p):
                        stale.append(f"{f}:{n}: names {p}, which is not in the repository")
    for s in stale:
        print(s)
    print(f"check_doc_paths: {len(stale)} stale path(s) in docs and comments", file=sys.stderr)
    return 1 if stale else 0


if __name__ == "__main__":
    sys.exit(main())
