"""Self-test of scripts/check_core_layering.py (the real-time core includes and links the standard
library, Eigen and itself only): on a small tree written here, a clean core passes; a core header
including SUNDIALS, a core source including a comparison model's header and a core target linking
CHOLMOD are each named; the comparison models' own folder (core/models) may include SUNDIALS.
Then the project's own tree passes.

Runs under pytest and on its own without pytest (ctest scripts.core_layering).
"""
import pathlib
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "scripts" / "check_core_layering.py"


def write(root, rel, text):
    path = root / rel
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)


def clean_tree(root):
    write(root, "core/include/puncture/force_mesh.hpp", "#pragma once\n#include <vector>\n#include <Eigen/Core>\n")
    write(root, "core/include/puncture/sh/real_sh.hpp", "#pragma once\n#include <cmath>\n")
    write(root, "core/src/force_mesh.cpp", '#include "puncture/force_mesh.hpp"\n#include "puncture/sh/real_sh.hpp"\n')
    write(root, "core/models/src/volumetric.cpp", "#include <sundials/sundials_types.h>\n")
    write(root, "core/CMakeLists.txt", "target_link_libraries(puncture_core PUBLIC Eigen3::Eigen puncture_sh)\n")


def check(root):
    return subprocess.run([sys.executable, str(SCRIPT), "--root", str(root)], capture_output=True, text=True)


def test_a_clean_core_passes_and_each_violation_is_named():
    with tempfile.TemporaryDirectory() as tmp:
        root = pathlib.Path(tmp)
        clean_tree(root)
        assert check(root).returncode == 0, check(root).stdout
        write(root, "core/include/puncture/integrator.hpp", "#pragma once\n#include <cvode/cvode.h>\n")
        write(root, "core/src/tick.cpp", '#include <vector>\n#include "puncture/comparison/comparison_model.hpp"\n')
        write(root, "core/CMakeLists.txt", "target_link_libraries(puncture_model PUBLIC puncture_core ${CHOLMOD_LIBRARY})\n")
        r = check(root)
        assert r.returncode == 1
        assert "core/include/puncture/integrator.hpp:2: includes cvode/cvode.h" in r.stdout
        assert "core/src/tick.cpp:2: includes puncture/comparison/comparison_model.hpp" in r.stdout
        assert "puncture_model links ${CHOLMOD_LIBRARY}" in r.stdout
        assert "core/models" not in r.stdout


def test_the_projects_core_passes():
    r = check(ROOT)
    assert r.returncode == 0, r.stdout + r.stderr


if __name__ == "__main__":
    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
    import selftest  # tests/scripts/, beside this file
    sys.exit(selftest.run(globals()))
