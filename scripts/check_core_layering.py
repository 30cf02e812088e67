#!/usr/bin/env python3
"""check_core_layering.py: the real-time core compiles with Eigen only.

The libraries puncture_sh, puncture_core and puncture_model (core/src,
core/src/sh, core/src/model and their headers in core/include/puncture) may
include the C++ standard library, Eigen and their own headers: no SUNDIALS,
CHOLMOD, OpenMP, deal.II, VTK or CGAL, and none of the comparison models
(core/models), the meshing, the validation harness or the apps. Their CMake
targets may link Eigen and each other only.

  python3 scripts/check_core_layering.py [--root DIR]

Exit 0 when every include and link is allowed; 1 with one line per violation
(file:line and what it includes or links).
"""
import argparse
import os
import re
import sys

CORE_SOURCES = ["core/src", "core/include/puncture"]
# Folders of core/ that are libraries of their own (not the real-time core).
NOT_CORE = ["core/models", "core/io", "core/scene_io"]
STANDARD = {
    "algorithm", "array", "atomic", "cassert", "chrono", "cmath", "complex", "cstddef", "cstdint", "cstdio", "cstdlib",
    "cstring", "deque", "filesystem", "functional", "initializer_list", "iomanip", "iosfwd", "iostream", "iterator",
    "limits", "map", "memory", "mutex", "numeric", "optional", "ostream", "random", "set", "span", "sstream",
    "stdexcept", "string", "string_view", "thread", "tuple", "type_traits", "unordered_map", "unordered_set",
    "utility", "variant", "vector",
}
# Headers of the core libraries themselves, under core/include/puncture.
OWN_PREFIXES = ("puncture/sh/", "puncture/model/")
INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]')
LINK = re.compile(r"target_link_libraries\((puncture_sh|puncture_core|puncture_model)\s+(.*?)\)", re.S)
ALLOWED_LINKS = {"PUBLIC", "PRIVATE", "INTERFACE", "Eigen3::Eigen", "puncture_sh", "puncture_core", "puncture_model"}


def own_header(root, name):
    """A header of the core libraries: core/include/<name> exists and is not a folder of another library."""
    if not name.startswith("puncture/"):
        return False
    top_level = "/" not in name[len("puncture/"):]
    return (top_level or name.startswith(OWN_PREFIXES)) and os.path.isfile(os.path.join(root, "core", "include", name))


def include_violations(root):
    out = []
    for top in CORE_SOURCES:
        for folder, _, files in os.walk(os.path.join(root, top)):
            rel_folder = os.path.relpath(folder, root)
            if any(rel_folder == n or rel_folder.startswith(n + "/") for n in NOT_CORE):
                continue
            for f in sorted(files):
                if not f.endswith((".cpp", ".hpp", ".h")):
                    continue
                path = os.path.join(folder, f)
                with open(path, encoding="utf-8") as text:
                    for number, line in enumerate(text, 1):
                        m = INCLUDE.match(line)
                        if not m:
                            continue
                        bracket, name = m.groups()
                        ok = (bracket == "<" and (name in STANDARD or name.startswith("Eigen/"))) or \
                             own_header(root, name) or \
                             (bracket == '"' and os.path.isfile(os.path.join(folder, name)))
                        if not ok:
                            out.append(f"{os.path.relpath(path, root)}:{number}: includes {name}")
    return out


def link_violations(root):
    out = []
    path = os.path.join(root, "core", "CMakeLists.txt")
    with open(path, encoding="utf-8") as f:
        text = f.read()
    for m in LINK.finditer(text):
        for item in m.group(2).split():
            if item not in ALLOWED_LINKS:
                out.append(f"core/CMakeLists.txt: {m.group(1)} links {item}")
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--root", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    args = ap.parse_args()
    problems = include_violations(args.root) + link_violations(args.root)
    for p in problems:
        print(p)
    if problems:
        print(f"check_core_layering: {len(problems)} include(s) or link(s) outside the standard library, Eigen and "
              "the core's own headers", file=sys.stderr)
        return 1
    print("check_core_layering: the real-time core (puncture_sh, puncture_core, puncture_model) includes and links "
          "the standard library, Eigen and itself only")
    return 0


if __name__ == "__main__":
    sys.exit(main())
