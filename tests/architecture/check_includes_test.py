#!/usr/bin/env python3
"""check_includes.py on small trees: a clean one passes, each wrong-way include is reported."""
import os
import subprocess
import sys
import tempfile

CHECK = os.path.join(os.path.dirname(os.path.abspath(__file__)), "check_includes.py")


def tree(files):
    root = tempfile.mkdtemp()
    for path, text in files.items():
        os.makedirs(os.path.dirname(os.path.join(root, path)), exist_ok=True)
        with open(os.path.join(root, path), "w") as f:
            f.write(text)
    return root


def check(root):
    p = subprocess.run([sys.executable, CHECK, root], capture_output=True, text=True)
    return p.returncode, p.stdout


clean = {
    "engine/framework/block.hpp": "#pragma once\n#include <vector>\n",
    "engine/analysis/run_result.hpp": '#include "engine/framework/block.hpp"\n',
    "engine/analysis/solver.cpp": '#include "engine/analysis/run_result.hpp"\n',
    "io/csv.cpp": '#include "engine/framework/block.hpp"\n#include "engine/analysis/run_result.hpp"\n',
    "apps/main.cpp": '#include "io/csv.hpp"\n#include "engine/analysis/solver.hpp"\n',
}
code, out = check(tree(clean))
assert code == 0, out

cases = {
    "engine/framework/block.hpp": ('#include "engine/analysis/run_result.hpp"\n', "engine/framework/block.hpp:1"),
    "engine/analysis/solver.cpp": ('#include "engine/studies/sweep.hpp"\n', "engine/analysis/solver.cpp:1"),
    "io/csv.cpp": ('\n#include "engine/analysis/solver.hpp"\n', "io/csv.cpp:2"),
    "engine/scene/loader.cpp": ('#include "engine/evaluation/evaluator.hpp"\n', "engine/scene/loader.cpp:1"),
    "blocks/damper.cpp": ('#include "engine/analysis/run_result.hpp"\n', "blocks/damper.cpp:1"),
    "symbolic/expr.cpp": ('#include "engine/framework/block.hpp"\n', "symbolic/expr.cpp:1"),
}
for path, (text, where) in cases.items():
    files = dict(clean)
    files[path] = text
    code, out = check(tree(files))
    assert code == 1, (path, out)
    assert where in out, (where, out)
print("check_includes: the clean tree passes and", len(cases), "wrong-way includes are each reported")
