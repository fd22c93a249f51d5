#!/usr/bin/env python3
"""Checks that the module layering the build states is the one the code follows (docs/ARCHITECTURE.md).

Usage: scripts/check_includes.py [REPO_ROOT]   (default: the repository this script is in)

Two checks, each violation printed as `file:line: message`, exit 1 if any:
1. Every `#include "X/..."` in a library folder names X = the folder itself or a module below it in GRAPH
   (the transitive closure: sampling may include core because sampling -> volume -> core). `X/detail/` headers
   are private: only X itself, tests/ and bench/ include them.
2. Each `raysift_module(NAME DEPS ... PRIVATE_DEPS ...)` in the top CMakeLists.txt lists exactly the raysift_*
   modules GRAPH gives NAME, so CMake links what the code includes and nothing the layering forbids.
Folders not in GRAPH that hold code (apps, bench, tests, and future python/, server/, mpi/) may include anything.
"""
import re
import sys
from pathlib import Path

# The one statement of the direction: each library module and the modules it may use directly.
GRAPH = {
    "core": [],
    "volume": ["core"],
    "mesh": ["core"],
    "isosurface": ["volume", "mesh"],
    "features": ["mesh"],
    "sampling": ["features", "volume", "isosurface"],
    "nrr": ["core", "mesh"],
}
# Top-level folders that may include every module (everything <- apps, bench, tests, and the apps to come).
TOP_USERS = {"apps", "bench", "tests", "python", "server", "mpi", "examples"}
SOURCE_SUFFIXES = {".h", ".hpp", ".cpp", ".cc"}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([A-Za-z0-9_]+)/([^"]*)"')
MODULE_CALL = re.compile(r"^\s*raysift_module\(\s*([A-Za-z0-9_]+)([^)]*)\)", re.MULTILINE)


def closure(module):
    seen, todo = set(), list(GRAPH[module])
    while todo:
        m = todo.pop()
        if m not in seen:
            seen.add(m)
            todo.extend(GRAPH[m])
    return seen


def include_violations(root):
    for path in sorted(root.rglob("*")):
        rel = path.relative_to(root)
        if path.suffix not in SOURCE_SUFFIXES or not path.is_file() or rel.parts[0] in {"build", ".git"}:
            continue
        owner = rel.parts[0] if len(rel.parts) > 1 else None
        for n, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
            m = INCLUDE.match(line)
            if not m or m.group(1) not in GRAPH:
                continue
            target, rest = m.group(1), m.group(2)
            where = f"{rel}:{n}"
            if rest.startswith("detail/") and owner != target and owner not in {"tests", "bench"}:
                yield f"{where}: includes {target}/detail/ (private to {target}/)"
            elif owner in GRAPH and target != owner and target not in closure(owner):
                allowed = ", ".join(sorted(closure(owner))) or "nothing"
                yield f"{where}: {owner}/ may not include {target}/ (allowed: {allowed})"
            elif owner not in GRAPH and owner not in TOP_USERS:
                yield f"{where}: folder '{owner}' is neither a module in GRAPH nor an app folder; add it to one"


def cmake_violations(root):
    cmake = root / "CMakeLists.txt"
    text = cmake.read_text()
    stated = {}
    for m in MODULE_CALL.finditer(text):
        line = text.count("\n", 0, m.start()) + 1
        stated[m.group(1)] = (line, set(re.findall(r"\braysift_([A-Za-z0-9_]+)", m.group(2))))
    for module, deps in GRAPH.items():
        if module not in stated:
            yield f"CMakeLists.txt: no raysift_module({module} ...) call"
            continue
        line, cmake_deps = stated[module]
        if cmake_deps != set(deps):
            yield (f"CMakeLists.txt:{line}: raysift_{module} links {sorted(cmake_deps)} but the layering says "
                   f"{sorted(deps)} (scripts/check_includes.py GRAPH)")
    for module, (line, _) in stated.items():
        if module not in GRAPH:
            yield f"CMakeLists.txt:{line}: module '{module}' is not in scripts/check_includes.py GRAPH"


def main(argv):
    root = Path(argv[1] if len(argv) > 1 else Path(__file__).resolve().parent.parent).resolve()
    if not (root / "CMakeLists.txt").is_file():
        print(f"check_includes: error: {root} has no CMakeLists.txt; pass the repository root", file=sys.stderr)
        return 2
    problems = list(include_violations(root)) + list(cmake_violations(root))
    for p in problems:
        print(p, file=sys.stderr)
    if problems:
        print(f"check_includes: {len(problems)} layering violation(s)", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
