#!/usr/bin/env python3
"""Mutation testing of the tangent and derivative code (docs/testing.md, "Mutation score").

Driven by scripts/mutate.sh. Lists every single-token mutant of the functions that compute
tangents, Jacobians and derivatives in blocks/, engine/ and the generator's differentiation and
emission (symbolic/), draws a seeded sample, and for each mutant in turn: edits the file (the
original kept in memory and in a backup file, restored on exit, on an error and on SIGINT/SIGTERM),
rebuilds only the test executables that cover the file (release build, ninja), runs them with a
time limit, records killed/survived, restores the file.

Operators (one token each):
  sign   a binary + becomes -, or - becomes +; += becomes -=, or -= becomes +=
  factor the term after =, +=, -=, return or a binary + or - multiplied by 2.0
  index  a subscript a[i] becomes a[i + 1]
  drop   a term dropped: `+ t` or `- t` removed, or the right-hand side of += / -= made 0.0

A mutant that does not compile is "stillborn" and left out of the score; a test that fails,
crashes or exceeds its time limit kills the mutant.
"""
import argparse
import json
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))

# ------------------------------------------------------------------------------ what is mutated

TANGENT_NAME = re.compile(r"tangent|jacobian|derivative", re.IGNORECASE)

# file -> (function-name filter: None = every function of the file, test executables)
BLOCK_TANGENT = ["blocks_registry_tangent_test"]


def block_tests(stem):
    extra = {
        "damper_cdc": ["blocks_damper_cdc_test", "blocks_damper_valve_law_test"],
        "hydraulics": ["blocks_damper_cdc_test", "blocks_damper_valve_law_test"],
        "mass_spring_damper": ["engine_msd_sensitivity_test"],
        "multibody": ["mbs_sensor_tangents_test", "blocks_direction_plan_test"],
        "objectives": ["engine_msd_sensitivity_test"],
        "objective_window": ["engine_msd_sensitivity_test", "blocks_vehicle_objectives_test"],
    }.get(stem, [])
    own = "blocks_%s_test" % stem
    own = [own] if os.path.exists(os.path.join(ROOT, "tests/blocks/%s_test.cpp" % stem)) else []
    return BLOCK_TANGENT + own + extra


ENGINE_EVALUATION = ["engine_msd_sensitivity_test", "engine_feedthrough_test", "engine_jacobian_colouring_test",
                     "engine_evaluator_cache_test", "engine_stiff_test"]
ENGINE_INTEGRATORS = ["engine_msd_sensitivity_test", "engine_stiff_test", "engine_rosenbrock_test",
                      "engine_error_control_test", "engine_substep_test", "engine_rosenbrock_local_stage_test"]
ENGINE_LINEAR = ["engine_quarter_car_modes_test", "engine_sedan_linear_test"]
# fastest first: the first failing executable ends a mutant's run (emit_cpp_test compiles the
# emitted code: about a minute)
SYMBOLIC = ["symbolic_differentiate_test", "symbolic_grouped_tangent_test", "symbolic_emit_cpp_test"]


def scope():
    files = {}
    for name in sorted(os.listdir(os.path.join(ROOT, "blocks"))):
        if name.endswith(".cpp"):
            files["blocks/" + name] = (TANGENT_NAME, block_tests(name[:-4]))
    for f in ["engine/evaluation/evaluator.cpp", "engine/evaluation/jacobian_colouring.cpp"]:
        files[f] = (TANGENT_NAME, ENGINE_EVALUATION)
    for f in ["engine/analysis/cvodes_solver.cpp", "engine/analysis/rk4_solver.cpp", "engine/analysis/sdirk_solver.cpp",
              "engine/analysis/rosenbrock_solver.cpp", "engine/analysis/local_stages.cpp"]:
        files[f] = (TANGENT_NAME, ENGINE_INTEGRATORS)
    for f in ["engine/linear/linearization.cpp", "engine/linear/equilibrium.cpp", "engine/linear/frequency_response.cpp"]:
        files[f] = (TANGENT_NAME, ENGINE_LINEAR)
    files["symbolic/differentiate.cpp"] = (None, SYMBOLIC)
    files["symbolic/grouped_tangent.cpp"] = (None, SYMBOLIC)
    files["symbolic/emit_cpp_tangent.cpp"] = (TANGENT_NAME, SYMBOLIC)
    return files


# ------------------------------------------------------------------------------ tokens

TOKEN = re.compile(r"""
    (?P<comment>//[^\n]*|/\*.*?\*/)
  | (?P<string>R"(?P<delim>[^(\s]*)\(.*?\)(?P=delim)"|"(?:\\.|[^"\\\n])*"|'(?:\\.|[^'\\\n])*')
  | (?P<number>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?[a-zA-Z]*)
  | (?P<ident>[A-Za-z_]\w*)
  | (?P<op>->\*|<<=|>>=|\.\.\.|->|\+\+|--|<<|>>|<=|>=|==|!=|&&|\|\||\+=|-=|\*=|/=|%=|&=|\|=|\^=|::|[^\s\w])
  | (?P<space>\s+)
""", re.VERBOSE | re.DOTALL)

KEYWORDS = {"return", "case", "if", "else", "while", "for", "do", "switch", "throw", "new", "delete", "sizeof",
            "const", "static_cast", "operator", "co_return", "and", "or", "not"}
QUALIFIERS = {"const", "override", "noexcept", "final", "mutable", "volatile", "&", "&&"}


def tokenize(text):
    out = []  # (kind, text, start, end)
    pos = 0
    while pos < len(text):
        m = TOKEN.match(text, pos)
        if not m:
            raise ValueError("cannot tokenize at %d" % pos)
        kind = m.lastgroup if m.lastgroup != "delim" else "string"
        if kind == "string" and m.group("string") is not None:
            kind = "string"
        if kind not in ("comment", "space"):
            out.append((kind, m.group(0), m.start(), m.end()))
        pos = m.end()
    return out


def matching(tokens, i, open_, close):
    depth = 0
    for j in range(i, len(tokens)):
        if tokens[j][1] == open_:
            depth += 1
        elif tokens[j][1] == close:
            depth -= 1
            if depth == 0:
                return j
    return -1


def function_bodies(tokens, name_filter):
    """(first, last) token indices of the bodies of the function definitions whose name matches."""
    bodies = []
    for i in range(len(tokens) - 1):
        kind, text = tokens[i][0], tokens[i][1]
        if kind != "ident" or tokens[i + 1][1] != "(" or text in KEYWORDS:
            continue
        if name_filter is not None and not name_filter.search(text):
            continue
        if i > 0 and tokens[i - 1][1] in (".", "->"):
            continue  # a call
        close = matching(tokens, i + 1, "(", ")")
        if close < 0:
            continue
        j = close + 1
        while j < len(tokens) and tokens[j][1] in QUALIFIERS:
            j += 1
        if j < len(tokens) and tokens[j][1] == "->":  # trailing return type
            while j < len(tokens) and tokens[j][1] not in ("{", ";"):
                j += 1
        if j < len(tokens) and tokens[j][1] == "{":
            end = matching(tokens, j, "{", "}")
            if end > 0:
                bodies.append((j + 1, end))
    # nested definitions (a lambda named like a tangent inside a tangent function): the outer one
    bodies.sort()
    merged = []
    for b in bodies:
        if merged and b[0] <= merged[-1][1]:
            continue
        merged.append(b)
    return merged


def is_operand_end(tok):
    kind, text = tok[0], tok[1]
    return (kind in ("ident", "number") and text not in KEYWORDS) or text in (")", "]")


def starts_operand(tok):
    return tok[0] in ("ident", "number") or tok[1] in ("(", "-", "!")


TERM_END = {";", ",", ")", "]", "}", "?", ":", "<", ">", "<=", ">=", "==", "!=", "&&", "||", "<<", ">>", "=", "+=",
            "-=", "*=", "/=", "{"}


def term_end(tokens, i, stop):
    """Index one past the term that starts at token i (within a body ending at stop)."""
    depth = 0
    j = i
    while j < stop:
        t = tokens[j][1]
        if depth == 0:
            if j > i and t in ("+", "-") and is_operand_end(tokens[j - 1]):
                return j
            if t in TERM_END:
                return j
        if t in ("(", "[", "{"):
            depth += 1
        elif t in (")", "]", "}"):
            depth -= 1
        j += 1
    return j


def mutants_of(path, text, name_filter):
    tokens = tokenize(text)
    out = []

    def add(op, first, last, replacement, what):
        """Replace text[tokens[first].start : tokens[last].end] (last inclusive)."""
        start, end = tokens[first][2], tokens[last][3]
        line = text.count("\n", 0, start) + 1
        out.append({"file": path, "op": op, "start": start, "end": end, "replacement": replacement,
                    "line": line, "what": what})

    for first, stop in function_bodies(tokens, name_filter):
        for i in range(first, stop):
            kind, t = tokens[i][0], tokens[i][1]
            prev = tokens[i - 1] if i > 0 else ("", "", 0, 0)
            nxt = tokens[i + 1] if i + 1 < len(tokens) else ("", "", 0, 0)
            binary = t in ("+", "-") and is_operand_end(prev)
            if binary:
                flipped = "-" if t == "+" else "+"
                add("sign", i, i, flipped, "%s -> %s" % (t, flipped))
            if t in ("+=", "-="):
                flipped = "-=" if t == "+=" else "+="
                add("sign", i, i, flipped, "%s -> %s" % (t, flipped))
            # factor 2 on the term that follows an assignment, a return or a binary +/-
            if (binary or t in ("=", "+=", "-=", "return")) and i + 1 < stop and starts_operand(nxt):
                integer_literal = nxt[0] == "number" and re.fullmatch(r"\d+[uUlL]*", nxt[1])
                if not integer_literal and nxt[1] not in ("default", "delete", "nullptr", "true", "false", "{"):
                    add("factor", i, i, t + " 2.0 *", "%s t -> %s 2.0 * t" % (t, t))
            # index off by one
            if t == "[" and is_operand_end(prev) and prev[1] not in KEYWORDS and nxt[1] not in ("]", "["):
                close = matching(tokens, i, "[", "]")
                if 0 < close < stop:
                    add("index", close, close, " + 1]", "[%s] -> [%s + 1]" % (
                        text[tokens[i + 1][2]:tokens[close - 1][3]], text[tokens[i + 1][2]:tokens[close - 1][3]]))
            # a dropped term
            if binary:
                end = term_end(tokens, i + 1, stop)
                if end > i + 1:
                    add("drop", i, end - 1, "", "dropped `%s`" % text[tokens[i][2]:tokens[end - 1][3]])
            if t in ("+=", "-="):
                end = term_end(tokens, i + 1, stop)
                if end > i + 1 and end < stop and tokens[end][1] == ";":
                    add("drop", i, end - 1, t + " 0.0", "dropped `%s`" % text[tokens[i][2]:tokens[end - 1][3]])
    for m in out:
        m["what"] = re.sub(r"\s+", " ", m["what"])
        if len(m["what"]) > 120:
            m["what"] = m["what"][:117] + "..."
    return out


def all_mutants():
    mutants = []
    for path, (name_filter, tests) in scope().items():
        full = os.path.join(ROOT, path)
        if not os.path.exists(full):
            continue
        with open(full) as f:
            text = f.read()
        for m in mutants_of(path, text, name_filter):
            m["tests"] = tests
            mutants.append(m)
    for k, m in enumerate(mutants):
        m["id"] = "%s:%d:%s:%d" % (m["file"], m["line"], m["op"], m["start"])
    return mutants


# ------------------------------------------------------------------------------ running

class Restorer:
    """Keeps the original of the file being mutated; puts it back on exit, error or signal."""

    def __init__(self, backup_dir):
        self.backup_dir = backup_dir
        self.path = None
        self.original = None

    def mutate(self, path, new_text, original):
        self.path, self.original = path, original
        shutil.copyfile(path, os.path.join(self.backup_dir, "original.src"))
        with open(os.path.join(self.backup_dir, "original"), "w") as f:
            json.dump({"path": path}, f)
        with open(path, "w") as f:
            f.write(new_text)

    def restore(self):
        if self.path is not None:
            with open(self.path, "w") as f:
                f.write(self.original)
            os.remove(os.path.join(self.backup_dir, "original"))
            self.path = None


def run(cmd, timeout, log):
    start = time.time()
    try:
        p = subprocess.run(cmd, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=timeout,
                           start_new_session=True)
        code = p.returncode
        output = p.stdout.decode(errors="replace")
    except subprocess.TimeoutExpired as e:
        code = "timeout"
        output = (e.stdout or b"").decode(errors="replace")
    log.write("$ %s\n%s\n[%s, %.1f s]\n" % (" ".join(cmd), output[-4000:], code, time.time() - start))
    log.flush()
    return code, time.time() - start


def executable(build, name):
    for sub in ("tests/blocks", "tests/engine", "tests/symbolic", "tests/symbolic/mbs", "tests/apps"):
        p = os.path.join(build, sub, name)
        if os.path.exists(p):
            return p
    return None


def summarise(results_path):
    rows = {}
    with open(results_path) as f:
        for line in f:
            r = json.loads(line)
            rows[r["id"]] = r  # the last run of each mutant
    counts = {}
    for r in rows.values():
        counts[r["status"]] = counts.get(r["status"], 0) + 1
    killed, survived = counts.get("killed", 0), counts.get("survived", 0)
    print("\nmutants run: %d; killed %d, survived %d, stillborn (do not compile) %d" % (
        len(rows), killed, survived, counts.get("stillborn", 0)))
    if killed + survived:
        print("score: %d / %d = %.1f %% killed" % (killed, killed + survived, 100.0 * killed / (killed + survived)))
    for r in rows.values():
        if r["status"] == "survived":
            print("survived: %s  %s" % (r["id"], r["what"]))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--count", type=int, default=100)
    ap.add_argument("--seed", type=int, default=44)
    ap.add_argument("--build", default=os.path.join(ROOT, "build/release"))
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--test-timeout", type=int, default=120, help="per test executable [s]")
    ap.add_argument("--build-timeout", type=int, default=900)
    ap.add_argument("--out", default=os.path.join(ROOT, "build/mutate"))
    ap.add_argument("--list", action="store_true", help="print the sample and exit")
    ap.add_argument("--only", help="run only the mutants with these ids (comma separated)")
    ap.add_argument("--skip", type=int, default=0, help="skip the first K mutants of the sample (resume)")
    ap.add_argument("--summary", action="store_true", help="summarise the results recorded in OUT and exit")
    args = ap.parse_args()

    if args.summary:
        summarise(os.path.join(args.out, "results.jsonl"))
        return 0
    mutants = all_mutants()
    rng = random.Random(args.seed)
    sample = rng.sample(mutants, min(args.count, len(mutants)))
    if args.only:
        wanted = set(args.only.split(","))
        sample = [m for m in mutants if m["id"] in wanted]
    os.makedirs(args.out, exist_ok=True)
    if args.list:
        print("%d mutants in scope; sample of %d (seed %d)" % (len(mutants), len(sample), args.seed))
        for m in sample:
            print("%-60s %s" % (m["id"], m["what"]))
        return 0

    backup_dir = os.path.join(args.out, "backup")
    os.makedirs(backup_dir, exist_ok=True)
    restorer = Restorer(backup_dir)

    def on_signal(signum, frame):
        restorer.restore()
        sys.exit(128 + signum)

    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)

    results_path = os.path.join(args.out, "results.jsonl")
    log = open(os.path.join(args.out, "mutate.log"), "a")
    results = open(results_path, "a")
    print("%d mutants in scope; running %d of a sample of %d (seed %d); log in %s" % (
        len(mutants), len(sample) - args.skip, len(sample), args.seed, log.name), flush=True)
    touched = set()
    try:
        for k, m in enumerate(sample):
            if k < args.skip:
                continue
            path = os.path.join(ROOT, m["file"])
            with open(path) as f:
                original = f.read()
            mutated = original[:m["start"]] + m["replacement"] + original[m["end"]:]
            t0 = time.time()
            restorer.mutate(path, mutated, original)
            touched.add(tuple(m["tests"]))
            log.write("\n==== %d %s %s\n" % (k, m["id"], m["what"]))
            code, build_s = run(["ninja", "-C", args.build, "-j", str(args.jobs)] + m["tests"], args.build_timeout, log)
            status, killer = None, None
            if code != 0:
                status = "stillborn"
            else:
                for test in m["tests"]:
                    exe = executable(args.build, test)
                    if exe is None:
                        continue
                    code, _ = run([exe, "--gtest_brief=1"], args.test_timeout, log)
                    if code != 0:
                        status, killer = "killed", "%s (%s)" % (test, "time limit" if code == "timeout" else "exit %s" % code)
                        break
                status = status or "survived"
            restorer.restore()
            r = dict(m, status=status, killer=killer, build_seconds=round(build_s, 1),
                     seconds=round(time.time() - t0, 1))
            r.pop("replacement", None)
            results.write(json.dumps(r) + "\n")
            results.flush()
            print("%3d %-9s %5.0f s  %s  %s%s" % (k, status, r["seconds"], m["id"], m["what"],
                                                  "  <- " + killer if killer else ""), flush=True)
        summarise(results_path)
    finally:
        restorer.restore()
        # The build as the sources are: the executables the mutants rebuilt, from the originals.
        for tests in touched:
            subprocess.run(["ninja", "-C", args.build, "-j", str(args.jobs)] + list(tests), cwd=ROOT,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return 0


if __name__ == "__main__":
    sys.exit(main())
