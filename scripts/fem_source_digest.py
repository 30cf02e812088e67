#!/usr/bin/env python3
"""fem_source_digest.py: which FEM sources a result was computed from.

The program's FEM cache key holds a digest of every source of reference_fem/
and meshing/ and of the two core headers the FEM compiles in (scene.hpp,
puncture_force.hpp; validation/fem_cache/CMakeLists.txt: SHA-256 over the sorted
files' SHA-256 hex digests, line comments left out, 16 hex digits; `puncture --version` shows it).
This module computes the same digest from the working tree or from any git
revision, and a digest per FEM geometry: the sources one geometry's run can
execute, leaving out the files only the other geometry runs, so that a change
to the 3D solver does not count as a change of the axisymmetric reference
(and the other way round). A study of many FEM runs keys each run on its
geometry's digest (scripts/fem_robustness_study.py).

Which files belong to one geometry only (tests/scripts/test_fem_source_digest.py
checks the rule that makes this sound):
  3d only:           the 3D solver and run: the files that define only
                     FiniteStrainSolver, SlabInsertionRun and the types of their
                     interface; only the 3D branch of run_needle_insertion
                     constructs them, and no axisymmetric file names them
  axisymmetric only: the axisymmetric solver, run and mesh, which the 3D run
                     never names
Everything else (scene, materials, cohesive law, the dispatcher, the output
helpers, the meshes' shared parts) is in both digests.

A change that only moves code between files (changing a shared file's text, so both digests),
or that only makes a run faster with the same floating-point operations in the same order, can
be recorded in SAME_RUNS once its runs are shown identical bit for bit; a study then keeps the
runs of the older sources (same_runs).

  python3 scripts/fem_source_digest.py [--rev REV] [--geometry all|3d|axisymmetric]
"""
import argparse
import functools
import hashlib
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SOURCE_DIRS = ("reference_fem/src", "reference_fem/include", "meshing/src", "meshing/include")
# The two headers of core/ that the FEM compiles into its code (the Scene, the layer states).
CORE_HEADERS = ("core/include/puncture/scene.hpp", "core/include/puncture/puncture_force.hpp")
# The tetrahedral mesh and mesher of the comparison models are no FEM source
# (the same filter as validation/fem_cache/CMakeLists.txt).
NOT_FEM = re.compile(r"tet_slab_mesh|tet_mesh")
ONLY = {
    "3d": re.compile(r"^(reference_fem/(src/(finite_strain_solver\.cc|finite_strain_assembly\.cc|energy_line_search\.hpp|"
                     r"slab_insertion_output\.cc|slab_insertion_run\.(cc|hpp))|"
                     r"include/puncture/fem/finite_strain_solver\.hpp)|"
                     r"meshing/(src|include/puncture/meshing)/inclined_path_mesh\.(cpp|hpp))$"),
    "axisymmetric": re.compile(r"^(reference_fem/src/axisymmetric_[a-z_]+\.(cc|hpp)|"
                               r"reference_fem/include/puncture/fem/axisymmetric_solver\.hpp|"
                               r"meshing/(src|include/puncture/meshing)/axisymmetric_slab_mesh\.(cpp|hpp))$"),
}
GEOMETRIES = tuple(ONLY)
# Changes of the FEM sources that moved code between files, or made a run faster, without
# changing what a geometry's run computes, each shown by rerunning references of that geometry
# with both programs and comparing every output bit for bit (the commit that made the change
# says which runs): (geometry, newer digest) -> older digest. A run of the older sources is then
# a run of the newer.
SAME_RUNS = {
    # The 3D run moved out of needle_insertion.cc into slab_insertion_run.cc: the default slab's
    # axisymmetric reference at 10 and 1 mm/s identical (CSV, profiles, Newton log, VTU, summary).
    ("axisymmetric", "83368e3c30ca85b3"): "e6276a660c7f6a06",
    # The axisymmetric assembly reads each cell's undeformed geometry computed once in cell order,
    # evaluates cells without heap allocations, and takes the line search's accepted full step
    # (assembled with its tangent) as the next iterate's assembly; outer and symmetric products on
    # the 6 x 6 independent components (bit for bit deal.II's: test_materials_and_solver). Its runs
    # are the older sources' runs on one assembly thread, which is how this study runs them
    # (robustness_full_016: every figure of the committed record to its last digit, the largest
    # residual share 0.0009171073838068277; the default slab's reference, on 2 threads, identical
    # too). On 2 threads the older sources' FEValues reused a cell's mapping data across each
    # thread's range and could differ in the last bits (the held-out references at 3 mm/s, 25 mm,
    # and the other slab: force columns within 2.1e-7 N, the CSV's last digit).
    ("axisymmetric", "de965b7f081a1c20"): "83368e3c30ca85b3",
    ("3d", "79a4af8dc278806a"): "4813f8d0b107e213",
    # symmetric_product reads deal.II's own index maps instead of a copy of them: the default
    # slab's reference (2 threads), robustness_full_016's first 0.6 mm (1 thread) and the 3D run
    # of robustness_full_028 identical.
    ("axisymmetric", "187515ec1bc52882"): "de965b7f081a1c20",
    ("3d", "1011df14b56786f1"): "79a4af8dc278806a",
    # The Scene's insertion gained its azimuth (read by the real-time model only) and meshing/ the
    # inclined path's map (not yet called by the 3D solver): the 3D run of robustness_full_028
    # (1 thread) identical in every CSV, the Newton log (less its timings) and the summary (less
    # its wall times); the default slab's reference (2 threads) identical in its force-depth and
    # recovery CSVs.
    ("axisymmetric", "212d3200a23d2605"): "187515ec1bc52882",
    ("3d", "b6dce00b76196741"): "1011df14b56786f1",
    # The 3D punch moves along the scene's (possibly inclined) path: along the sample axis every
    # quantity is computed with the same floating-point operations (path coordinate, held
    # displacements across the needle, reactions, distances from the path): the 3D run of
    # robustness_full_028 (1 thread) identical in every CSV and the Newton log (less its
    # timings); the default slab's axisymmetric reference (1 thread) identical in its force-depth
    # and recovery CSVs (the shared sources changed a message and the mesh call).
    ("axisymmetric", "641eaa216fd8c8de"): "212d3200a23d2605",
    ("3d", "444f7039ee057ce5"): "b6dce00b76196741",
    # A puncture's rows record the force across the needle too (an inclined run's CSV): the 3D run
    # of robustness_full_028 identical in every CSV and the Newton log (less its timings).
    ("3d", "96fb5d8e8afa74db"): "444f7039ee057ce5",
    # One resolution of fem.geometry "auto" (resolved_geometry) and the 3D path's direction from
    # the mesh's (meshing::path_direction): the 3D run of robustness_full_028 (and the same scene
    # at 30 deg) identical, the default slab's reference identical in its CSVs.
    ("axisymmetric", "b0c330198cd37219"): "641eaa216fd8c8de",
    ("3d", "84b12ebdef9e7c41"): "96fb5d8e8afa74db",
    # The 3D solver takes Prony layers (nothing evaluated or allocated without them; a layer's
    # long-term law and series shared with the axisymmetric run in insertion_common.hpp): the 3D
    # run of robustness_full_028 at 0 and 30 deg identical in every CSV and the Newton log (less
    # its timings), the default slab's reference identical in its CSVs and Newton log.
    ("axisymmetric", "ef8439a7838f334d"): "b0c330198cd37219",
    ("3d", "af25b517f5c56145"): "84b12ebdef9e7c41",
    # The run's Prony series per layer from one function beside its laws (layer_prony_terms),
    # the solver's unused time_step() getter dropped: robustness_full_028's 3D run identical in
    # every CSV and the Newton log (less its timings).
    ("3d", "c040470bc2b6ba86"): "af25b517f5c56145",
}


def source_files(rev=None):
    """The FEM source files (paths relative to the repository) of the working tree, or of git revision REV."""
    if rev is None:
        files = [os.path.relpath(os.path.join(d, f), ROOT)
                 for top in SOURCE_DIRS for d, _, names in os.walk(os.path.join(ROOT, top)) for f in names]
    else:
        files = subprocess.check_output(["git", "-C", ROOT, "ls-tree", "-r", "--name-only", rev, *SOURCE_DIRS],
                                        text=True).split()
    return sorted([f for f in files if not NOT_FEM.search(f)] + list(CORE_HEADERS))


def file_bytes(path, rev=None):
    """The content of PATH in the working tree or at revision REV, without its line comments
    (from // to the end of the line, as CMake's digest: an edited comment changes no digest)."""
    if rev is None:
        with open(os.path.join(ROOT, path), "rb") as f:
            content = f.read()
    else:
        content = subprocess.check_output(["git", "-C", ROOT, "show", f"{rev}:{path}"])
    return re.sub(rb"//[^\n]*", b"", content)


def geometry_files(files, geometry):
    """FILES less those that belong only to the other geometries (geometry 'all': every file)."""
    if geometry == "all":
        return list(files)
    if geometry not in ONLY:
        raise ValueError(f"fem_source_digest: unknown geometry '{geometry}' (all, {', '.join(GEOMETRIES)})")
    others = [ONLY[g] for g in GEOMETRIES if g != geometry]
    return [f for f in files if not any(p.match(f) for p in others)]


def digest(rev=None, geometry="all"):
    """16 hex digits: SHA-256 over the SHA-256 hex digests of the geometry's FEM sources in path order
    (geometry 'all' is the program's own digest, `puncture --version`). A revision's digests are
    computed once per process (a study reads many records of the same revision)."""
    return _digest_of(None, geometry) if rev is None else _revision_digest(rev, geometry)


@functools.lru_cache(maxsize=None)
def _revision_digest(rev, geometry):
    return _digest_of(rev, geometry)


def _digest_of(rev, geometry):
    hexes = "".join(hashlib.sha256(file_bytes(f, rev)).hexdigest()
                    for f in geometry_files(source_files(rev), geometry))
    return hashlib.sha256(hexes.encode()).hexdigest()[:16]


def oldest_same(geometry, d):
    """The oldest digest whose runs compute what runs of sources D compute (SAME_RUNS followed back)."""
    seen = set()
    while (geometry, d) in SAME_RUNS and d not in seen:
        seen.add(d)
        d = SAME_RUNS[(geometry, d)]
    return d


def same_runs(geometry, a, b):
    """True when a run of the geometry's FEM sources with digest A computes what one with digest B
    does: the same digest, or digests SAME_RUNS records as computing the same."""
    return a is not None and b is not None and oldest_same(geometry, a) == oldest_same(geometry, b)


def program_version(binary):
    """(git revision, FEM source digest) that `BINARY --version` names; the revision may end in -dirty."""
    out = subprocess.check_output([binary, "--version"], text=True)
    m = re.search(r"\(git ([0-9a-f]+(?:-dirty)?|unknown), FEM sources ([0-9a-f]{16})\)", out)
    if not m:
        raise RuntimeError(f"fem_source_digest: cannot read the git revision and FEM digest from "
                           f"'{binary} --version': {out.strip()}")
    return m.group(1), m.group(2)


def scene_geometry(scene):
    """The FEM geometry a scene (dict) runs with: its fem.geometry, or by the tip for 'auto'."""
    geometry = scene.get("fem", {}).get("geometry", "auto")
    if geometry == "auto":
        geometry = "3d" if scene["needle"]["tip"] == "blunt" else "axisymmetric"
    return geometry


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rev", default=None, help="a git revision (default: the working tree)")
    ap.add_argument("--geometry", default="all", choices=("all",) + GEOMETRIES)
    args = ap.parse_args()
    print(digest(args.rev, args.geometry))
    return 0


if __name__ == "__main__":
    sys.exit(main())
