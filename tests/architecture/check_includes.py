#!/usr/bin/env python3
"""Fails on an #include that points the wrong way between dydp's folders.

The layers are those of docs/architecture.md: each folder of the source tree may include the
folders listed for it (and its own), nothing else. Headers of other libraries (<...>) are not
checked. Usage: check_includes.py SOURCE_ROOT; exit 1 with one line per wrong include.
"""
import os
import re
import sys

# folder -> the folders it may include (besides itself and its own subfolders)
ALLOWED = {
    "symbolic": [],
    "generated_models": ["symbolic"],
    "engine/framework": [],
    "engine/scene": ["engine/framework"],
    "engine/evaluation": ["engine/framework"],
    "engine/analysis": ["engine/framework", "engine/evaluation"],
    "engine/linear": ["engine/framework", "engine/evaluation", "engine/analysis"],
    "io": ["engine/framework", "engine/analysis/run_result.hpp"],
    "engine/studies": ["engine/framework", "engine/scene", "engine/evaluation", "engine/analysis", "engine/linear", "io"],
    "blocks": ["engine/framework", "io", "generated_models", "symbolic"],
    "python": ["engine", "io", "blocks"],
    "gui": ["engine", "io", "blocks"],
    "fmi": ["engine", "io", "blocks"],
    "apps": ["engine", "io", "blocks", "symbolic", "generated_models", "fmi"],
}
# tests/ and bench/ may include anything: they look at every layer from outside.
UNCHECKED = ("tests", "bench", "build", ".git", "scripts", "docs", "scenarios")
SOURCE = (".cpp", ".hpp", ".h")
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def folder_of(path):
    """The most specific key of ALLOWED that path lies in, or None."""
    best = None
    for key in ALLOWED:
        if path == key or path.startswith(key + "/"):
            if best is None or len(key) > len(best):
                best = key
    return best


def allowed(source_folder, target):
    if target.startswith(source_folder + "/"):
        return True
    return any(target == a or target.startswith(a + "/") for a in ALLOWED[source_folder])


def main(root):
    wrong = []
    for dirpath, dirnames, filenames in os.walk(root):
        rel_dir = os.path.relpath(dirpath, root)
        if rel_dir.split(os.sep)[0] in UNCHECKED:
            dirnames[:] = []
            continue
        for name in filenames:
            if not name.endswith(SOURCE):
                continue
            rel = os.path.normpath(os.path.join(rel_dir, name)).replace(os.sep, "/")
            folder = folder_of(rel)
            if folder is None:
                continue
            with open(os.path.join(dirpath, name), encoding="utf-8", errors="replace") as f:
                for number, line in enumerate(f, 1):
                    m = INCLUDE.match(line)
                    if not m:
                        continue
                    target = m.group(1)
                    if "/" not in target:  # a file next to this one (generated code, Qt's ui headers)
                        continue
                    if folder_of(target) is None and not os.path.exists(os.path.join(root, target)):
                        continue  # a generated header of the build tree
                    if not allowed(folder, target):
                        wrong.append(f"{rel}:{number}: includes {target}, which {folder}/ may not "
                                     f"(it may include: {', '.join(ALLOWED[folder]) or 'nothing outside itself'})")
    for w in wrong:
        print(w)
    if wrong:
        print(f"{len(wrong)} include(s) point the wrong way (docs/architecture.md)")
        return 1
    print("includes: every folder includes only the layers below it")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "."))
