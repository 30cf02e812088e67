"""Tests of scripts/fem_source_digest.py (which FEM sources a result was computed from).

- The digest of every FEM source equals the program's own (`puncture --version`, computed by
  CMake in validation/fem_cache/CMakeLists.txt): the Python mirror hashes the same files the
  same way. The program is argv[1] or $PUNCTURE_PROGRAM (skipped by neither: the test fails).
- The split per geometry is sound: no axisymmetric-only file names a type of the 3D solver or
  run, no 3D-only file names one of the axisymmetric solver or run, the 3D-only sources define
  at namespace level only members of FiniteStrainSolver and SlabInsertionRun (or functions local
  to their file), and each geometry's own files exist.
- A file of one geometry changes that geometry's digest only; a shared file changes both.
- Recorded moves of code (SAME_RUNS) make two digests of one geometry the same runs, no others.

Runs under pytest and on its own without pytest (ctest scripts.fem_source_digest).
"""
import os
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))
import fem_source_digest as fsd  # noqa: E402

TYPES_3D = ("FiniteStrainSolver", "SlabInsertionRun", "SolverSettings", "NewtonReport", "DofPoint", "CellFields",
            "VolumetricFormulation")
TYPES_AXISYMMETRIC = ("AxisymmetricSolver", "AxisymmetricInsertionRun", "AxisymmetricSlabMesh",
                      "AxisymmetricSettings", "AxisymmetricNewtonReport")


def program():
    if len(sys.argv) > 1 and not sys.argv[1].startswith("-"):
        return sys.argv[1]
    return os.environ.get("PUNCTURE_PROGRAM", str(ROOT / "build" / "apps" / "puncture"))


def code_of(path):
    """The file's text without comments and string literals."""
    text = (ROOT / path).read_text()
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    text = re.sub(r"//[^\n]*", " ", text)
    return re.sub(r'"(\\.|[^"\\\n])*"', '""', text)


def own_files(geometry):
    return [f for f in fsd.source_files() if fsd.ONLY[geometry].match(f)]


def test_the_digest_of_every_source_is_the_programs():
    _, program_digest = fsd.program_version(program())
    assert fsd.digest() == program_digest, "the Python mirror of the FEM digest differs from the program's"


def test_each_geometrys_own_files_exist_and_are_disjoint():
    three_d, axisymmetric = set(own_files("3d")), set(own_files("axisymmetric"))
    assert "reference_fem/src/finite_strain_solver.cc" in three_d
    assert "reference_fem/src/axisymmetric_newton.cc" in axisymmetric
    assert not three_d & axisymmetric


def test_no_file_of_one_geometry_names_a_type_of_the_other():
    for geometry, foreign in (("axisymmetric", TYPES_3D), ("3d", TYPES_AXISYMMETRIC)):
        for f in own_files(geometry):
            code = code_of(f)
            for name in foreign:
                assert not re.search(r"\b" + name + r"\b", code), f"{f} ({geometry} only) names {name}"


def namespace_level_definitions(code):
    """(line, class or None) of each function defined at namespace level outside an anonymous namespace
    (the project does not indent namespace contents: such a definition starts at column 0)."""
    depth, anonymous, found = 0, [], []
    for line in code.splitlines():
        if re.match(r"namespace\s*\{", line):
            anonymous.append(depth)
        head = line.split("(")[0]
        if ("(" in line and re.match(r"[A-Za-z][\w:<>,\s*&~]*$", head) and not anonymous
                and not re.match(r"(namespace|using|return|static_assert|template)\b", line)):
            owner = re.search(r"(\w+)::~?\w+$", head)
            found.append((line.strip(), owner.group(1) if owner else None))
        depth += line.count("{") - line.count("}")
        while anonymous and depth <= anonymous[-1]:
            anonymous.pop()
    return found


def test_the_3d_sources_define_only_the_3d_solver_and_run():
    checked = 0
    for f in own_files("3d"):
        if f.endswith(".cc"):
            for line, owner in namespace_level_definitions(code_of(f)):
                # the solver, the run and the run's path (slab_insertion_run.hpp)
                assert owner in ("FiniteStrainSolver", "SlabInsertionRun", "NeedlePath"), f"{f}: defines {line}"
                checked += 1
    assert checked > 20  # the check saw the solver's members
    # and it would see a free function or another class's member:
    code = "namespace puncture::fem {\nnamespace {\nint local(int a) {\n  return a;\n}\n}  // namespace\n" \
           "double shared_helper(double x) {\n  return x;\n}\nvoid AxisymmetricSolver::solve() {}\n}\n"
    assert [o for _, o in namespace_level_definitions(code)] == [None, "AxisymmetricSolver"]


def test_a_geometrys_own_file_changes_its_digest_only():
    files = ["meshing/src/graded_divisions.cpp", "reference_fem/src/axisymmetric_newton.cc",
             "reference_fem/src/finite_strain_solver.cc"]
    assert fsd.geometry_files(files, "all") == files
    assert fsd.geometry_files(files, "axisymmetric") == files[:2]
    assert fsd.geometry_files(files, "3d") == [files[0], files[2]]
    try:
        fsd.geometry_files(files, "2d")
    except ValueError as e:
        assert "unknown geometry '2d'" in str(e)
    else:
        raise AssertionError("an unknown geometry must raise")


def test_same_runs_follows_the_recorded_moves_of_code_only():
    for (geometry, newer), older in fsd.SAME_RUNS.items():
        assert geometry in fsd.GEOMETRIES and newer != older
        assert fsd.same_runs(geometry, newer, older) and fsd.same_runs(geometry, older, newer)
        other = next(g for g in fsd.GEOMETRIES if g != geometry)
        assert not fsd.same_runs(other, newer, older), "a move recorded for one geometry says nothing of the other"
    assert fsd.same_runs("3d", "0123456789abcdef", "0123456789abcdef")
    assert not fsd.same_runs("3d", "0123456789abcdef", "fedcba9876543210")
    assert not fsd.same_runs("3d", None, None)
    saved = dict(fsd.SAME_RUNS)
    try:  # a chain of moves is followed back; a cycle ends
        fsd.SAME_RUNS.clear()
        fsd.SAME_RUNS.update({("3d", "c"): "b", ("3d", "b"): "a", ("axisymmetric", "x"): "y", ("axisymmetric", "y"): "x"})
        assert fsd.same_runs("3d", "c", "a") and not fsd.same_runs("3d", "c", "d")
        assert fsd.oldest_same("axisymmetric", "x") in ("x", "y")
    finally:
        fsd.SAME_RUNS.clear()
        fsd.SAME_RUNS.update(saved)


def test_scene_geometry_follows_the_tip_for_auto():
    assert fsd.scene_geometry({"needle": {"tip": "blunt"}}) == "3d"
    assert fsd.scene_geometry({"needle": {"tip": "bevel"}}) == "axisymmetric"
    assert fsd.scene_geometry({"needle": {"tip": "blunt"}, "fem": {"geometry": "axisymmetric"}}) == "axisymmetric"


if __name__ == "__main__":
    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
    import selftest  # tests/scripts/, beside this file
    sys.exit(selftest.run(globals()))
