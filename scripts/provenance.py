"""provenance.py: what a results/ script records about where it ran.

git_revision(): short hash of this repository's HEAD ("unknown" outside git).
machine(): "<system> <release>, <n> cores (<cpu model>)".
utc_now(): "YYYY-MM-DD HH:MM" in UTC.
"""
import datetime
import os
import platform
import subprocess


def git_revision():
    try:
        return subprocess.check_output(["git", "-C", os.path.dirname(os.path.abspath(__file__)), "rev-parse",
                                        "--short", "HEAD"], text=True, stderr=subprocess.DEVNULL).strip()
    except Exception:
        return "unknown"


def machine():
    cpu = "unknown"
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    # The BLAS Debian's alternatives select (as machine_summary() in
    # core/io/src/provenance.cpp): the last digits of the FEM and of the
    # tensor-mass models depend on it.
    blas = ""
    for lib in ("/usr/lib/x86_64-linux-gnu/libblas.so.3", "/usr/lib/aarch64-linux-gnu/libblas.so.3"):
        if os.path.exists(lib):
            folder = os.path.basename(os.path.dirname(os.path.realpath(lib)))
            blas = ", reference BLAS" if folder == "blas" else f", {folder}"
            break
    return f"{platform.system()} {platform.release()}, {os.cpu_count()} cores ({cpu}){blas}"


def utc_now():
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M")
