"""selftest.py: runs a test module's test_* functions without pytest (how ctest runs the
scripts' self-tests; under pytest this file is not used). A function that takes `tmp_path`
gets a fresh temporary folder. Every failing test is reported, then the exit status is 1.

    if __name__ == "__main__":
        sys.exit(selftest.run(globals()))
"""
import inspect
import pathlib
import tempfile


def run(namespace):
    passed = failed = 0
    for name, fn in sorted(namespace.items()):
        if not (name.startswith("test_") and callable(fn)):
            continue
        try:
            if "tmp_path" in inspect.signature(fn).parameters:
                with tempfile.TemporaryDirectory() as d:
                    fn(pathlib.Path(d))
            else:
                fn()
            passed += 1
        except Exception as e:   # report every failing test, then fail
            failed += 1
            print(f"FAILED {name}: {type(e).__name__}: {e}")
    print(f"{passed} passed, {failed} failed")
    return 1 if failed else 0
